//! Soft bodies against rapier colliders: a cube dropped on the ground comes to rest on it, and
//! a block on a slope sticks or slides as Coulomb's law says.

use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, ColliderSet, RigidBodySet, SharedShape};

const GRAVITY: DVec3 = DVec3::new(0.0, -9.81, 0.0);

/// A plane through the origin with normal `normal`, as a rapier triangle mesh of two large
/// triangles, friction `friction`.
fn ground_mesh(normal: DVec3, friction: f64) -> ColliderSet {
    let normal = normal.normalize();
    let u = normal.cross(DVec3::Z).normalize() * 10.0;
    let w = normal.cross(u).normalize() * 10.0;
    let vertices = [-u - w, u - w, u + w, -u + w].map(|v| v.as_vec3()).to_vec();
    // Counter-clockwise seen from the normal's side.
    let triangles = if (u.cross(w)).dot(normal) > 0.0 {
        vec![[0, 1, 2], [0, 2, 3]]
    } else {
        vec![[0, 2, 1], [0, 3, 2]]
    };
    let mut colliders = ColliderSet::new();
    colliders.insert(
        ColliderBuilder::trimesh(vertices, triangles)
            .unwrap()
            .friction(friction as f32)
            .build(),
    );
    colliders
}

/// A ground half-space through the origin with outward normal `normal` and friction `friction`.
fn ground(normal: DVec3, friction: f64) -> ColliderSet {
    let mut colliders = ColliderSet::new();
    colliders.insert(
        ColliderBuilder::new(SharedShape::halfspace(normal.normalize().as_vec3()))
            .friction(friction as f32)
            .build(),
    );
    colliders
}

/// A 10 cm rubber cube (E = 1e5 Pa, ν = 0.3, 1000 kg/m³, 4 x 4 x 4 cells, damped) whose centre
/// is at `centre`.
fn rubber_cube(centre: DVec3, rotation: DVec3) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::splat(0.05), [4, 4, 4]).unwrap();
    DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
        .translation(centre)
        .rotation(rotation)
        .build()
        .unwrap()
}

fn lowest(body: &DeformableBody) -> f64 {
    body.positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min)
}

fn fastest(body: &DeformableBody) -> f64 {
    body.velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max)
}

#[test]
fn a_dropped_cube_comes_to_rest_on_the_ground() {
    // Dropped from 0.5 m, frames of 1/60 s for 2 s. The bound on penetration is the
    // contact margin plus 1 mm; the body must end at rest, its centre about half a side up.
    let colliders = ground(DVec3::Y, 0.5);
    let settings = ContactSettings::default();
    for force in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let mut body = rubber_cube(DVec3::new(0.0, 0.55, 0.0), DVec3::ZERO);
        let integrator = AutomaticIntegrator {
            force,
            ..AutomaticIntegrator::default()
        };
        let mut deepest = f64::INFINITY;
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for _ in 0..120 {
            constraints
                .detect_contacts(
                    &body,
                    &colliders,
                    &RigidBodySet::new(),
                    1.0 / 60.0,
                    GRAVITY,
                    &settings,
                )
                .unwrap();
            integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    GRAVITY,
                )
                .unwrap();
            deepest = deepest.min(lowest(&body));
        }
        let centre = body.center_of_mass().y;
        println!(
            "{force:?}: deepest {:.3} mm, centre {:.2} mm, fastest node {:.2e} m/s after 2 s",
            deepest * 1e3,
            centre * 1e3,
            fastest(&body)
        );
        assert!(deepest >= -(settings.margin + 1e-3), "{force:?}: {deepest}");
        assert!(fastest(&body) < 1e-2, "{force:?} still moving");
        // The rubber sags under its weight by ρ g L²/(2E) ≈ 0.5 mm at the centre.
        assert!(
            (centre - 0.05).abs() < 2e-3,
            "{force:?}: centre at {centre}"
        );
    }
}

#[test]
fn a_block_on_a_slope_sticks_or_slides_as_coulomb_says() {
    // A 20° slope (a half-space, and a two-triangle mesh): tan 20° = 0.364. With μ = 0.6 the
    // block holds; with μ = 0.2 it slides with
    // acceleration g (sin θ - μ cos θ) = 1.513 m/s², checked over 0.5 s to 5 % (the block
    // settles onto the slope in the first frames, and rubber rocks a little as it slides).
    // Both integrators: explicit friction is exact Coulomb; implicit friction lets a stuck block
    // creep at most at the stiction speed (1e-4 m/s) times 0.61 of its limit, 3e-5 m in 0.5 s,
    // within the same 1e-4 m bound.
    let angle = 20f64.to_radians();
    let normal = DVec3::new(-angle.sin(), angle.cos(), 0.0);
    let downhill = DVec3::new(angle.cos(), angle.sin(), 0.0) * -1.0;
    let settings = ContactSettings::default();
    let sliding = 9.81 * (angle.sin() - 0.2 * angle.cos());
    // The slope as a half-space and as a triangle mesh.
    for (shape, friction, expected, implicit) in [
        ("half-space", 0.6, 0.0, false),
        ("half-space", 0.2, sliding, false),
        ("triangle mesh", 0.2, sliding, false),
        ("half-space", 0.6, 0.0, true),
        ("half-space", 0.2, sliding, true),
    ] {
        let colliders = match shape {
            "half-space" => ground(normal, friction),
            _ => ground_mesh(normal, friction),
        };
        // The cube resting on the slope, tilted with it.
        let mut body = rubber_cube(normal * 0.0505, DVec3::new(0.0, 0.0, angle));
        body.friction = friction;
        let frame = 1.0 / 240.0;
        let mut history = Vec::new();
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for _ in 0..240 {
            constraints
                .detect_contacts(
                    &body,
                    &colliders,
                    &RigidBodySet::new(),
                    frame,
                    GRAVITY,
                    &settings,
                )
                .unwrap();
            if implicit {
                ImplicitIntegrator::default()
                    .step(&mut body, &mut constraints, &mut workspace, frame, GRAVITY)
                    .unwrap();
            } else {
                SymplecticEuler::default()
                    .step(&mut body, &mut constraints, &mut workspace, frame, GRAVITY)
                    .unwrap();
            }
            history.push(body.center_of_mass().dot(downhill));
        }
        // Acceleration from the distance travelled between 0.5 s and 1 s: s = v0 t + a t²/2 fits
        // with v0 from the first half.
        let (s0, s1, s2) = (history[119], history[179], history[239]);
        let t = 60.0 * frame;
        let acceleration = (s2 - 2.0 * s1 + s0) / (t * t);
        println!(
            "{shape}, μ = {friction}, implicit {implicit}: slid {:.2} mm in 1 s, acceleration {acceleration:.3} m/s² (expected {expected:.3})",
            (s2 - history[0]) * 1e3
        );
        if expected == 0.0 {
            // It slips about a millimetre while it lands, then holds.
            assert!((s2 - s0).abs() < 1e-4, "the block crept {}", s2 - s0);
        } else {
            assert!(
                (acceleration / expected - 1.0).abs() < 0.05,
                "{acceleration}"
            );
        }
    }
}

#[test]
fn collision_groups_decide_which_colliders_a_soft_body_touches() {
    // The ground is in group 2. A cube whose filter excludes group 2 falls through it (free fall:
    // g t²/2 = 0.196 m after 0.2 s, less the 5 cm it started above); one whose filter includes
    // it lands. The same test rapier applies to two colliders (`InteractionGroups::test`).
    use rapier3d::prelude::{Group, InteractionGroups, InteractionTestMode};
    let mut colliders = ColliderSet::new();
    colliders.insert(
        ColliderBuilder::new(SharedShape::halfspace(rapier_fvm::glamx::Vec3::Y))
            .collision_groups(InteractionGroups::new(
                Group::GROUP_2,
                Group::ALL,
                InteractionTestMode::And,
            ))
            .build(),
    );
    for (filter, lands) in [
        (Group::GROUP_1, false),
        (Group::GROUP_1 | Group::GROUP_2, true),
    ] {
        let mut body = rubber_cube(DVec3::new(0.0, 0.1, 0.0), DVec3::ZERO);
        body.collision_groups =
            InteractionGroups::new(Group::GROUP_1, filter, InteractionTestMode::And);
        let integrator = SymplecticEuler::default();
        let frame = 1.0 / 60.0;
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for _ in 0..12 {
            constraints
                .detect_contacts(
                    &body,
                    &colliders,
                    &RigidBodySet::new(),
                    frame,
                    GRAVITY,
                    &ContactSettings::default(),
                )
                .unwrap();
            integrator
                .step(&mut body, &mut constraints, &mut workspace, frame, GRAVITY)
                .unwrap();
        }
        println!(
            "filter {filter:?}: lowest node at {:.1} mm",
            lowest(&body) * 1e3
        );
        if lands {
            assert!(lowest(&body) > -2e-3, "the ground should hold it");
        } else {
            assert!(lowest(&body) < -0.1, "it should have fallen through");
        }
    }
}

#[test]
fn an_elastic_bar_striking_a_wall_end_on_rebounds_at_its_impact_speed() {
    // Saint-Venant's bar: an undamped elastic bar (0.5 m, E = 1e6 Pa, ν = 0, 1000 kg/m³, so
    // c = sqrt(E/ρ) = 31.6 m/s) moving end-on at 1 m/s into a rigid frictionless wall, in zero
    // gravity, with the default inelastic contacts. A compression wave runs to the far end and
    // back; after 2L/c = 31.6 ms the bar leaves the wall at its impact speed, all its energy
    // elastic in between. Tolerance 5 % on the rebound speed and the contact time: the lumped
    // masses and the explicit step disperse the wave front over a few cells.
    let mut colliders = ColliderSet::new();
    let wall = colliders.insert(
        ColliderBuilder::new(SharedShape::halfspace(rapier_fvm::glamx::Vec3::X))
            .friction(0.0)
            .build(),
    );
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.0, 1000.0).unwrap();
    let length = 0.5;
    let mesh = mesh::cuboid(DVec3::new(length / 2.0, 0.025, 0.025), [20, 2, 2]).unwrap();
    let mut bar = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(length / 2.0 + 1e-3, 0.0, 0.0))
        .linvel(DVec3::new(-1.0, 0.0, 0.0))
        .friction(0.0)
        .build()
        .unwrap();
    let integrator = SymplecticEuler::default();
    let (dt, mut time) = (1e-3, 0.0);
    let (mut first_touch, mut last_touch) = (None, None);
    let bodies = RigidBodySet::new();
    let settings = ContactSettings::default();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    while time < 0.1 {
        constraints
            .detect_contacts(&bar, &colliders, &bodies, dt, DVec3::ZERO, &settings)
            .unwrap();
        integrator
            .step(&mut bar, &mut constraints, &mut workspace, dt, DVec3::ZERO)
            .unwrap();
        time += dt;
        let (force, _) = constraints.contact_force_on(&bar, wall, dt).unwrap();
        if force.x.abs() > 0.0 {
            first_touch.get_or_insert(time - dt);
            last_touch = Some(time);
        }
    }
    let speed = bar.linear_momentum().x / bar.total_mass();
    let contact_time = last_touch.unwrap() - first_touch.unwrap();
    let expected_time = 2.0 * length / (1e6f64 / 1000.0).sqrt();
    println!(
        "rebound {speed:.4} m/s for 1 m/s in ({:+.2} %); contact {:.2} ms vs 2L/c = {:.2} ms",
        100.0 * (speed - 1.0),
        contact_time * 1e3,
        expected_time * 1e3
    );
    assert!((speed - 1.0).abs() < 0.05);
    assert!((contact_time / expected_time - 1.0).abs() < 0.05);
}

/// The contacts `detect_contacts` finds for `body` (its frame 1/60 s, default settings) among
/// `colliders` and `bodies`, split into those with `ground` and the rest.
fn contacts_with(
    body: &DeformableBody,
    (colliders, bodies): (&ColliderSet, &RigidBodySet),
    ground: rapier3d::prelude::ColliderHandle,
) -> (usize, usize) {
    let mut constraints = BodyConstraints::new();
    let settings = ContactSettings::default();
    let found =
        (constraints.detect_contacts(body, colliders, bodies, 1.0 / 60.0, GRAVITY, &settings))
            .unwrap();
    let on_ground = (found.iter())
        .filter(|c| c.target == ContactTarget::Collider(ground))
        .count();
    (on_ground, found.len() - on_ground)
}

/// A fixed rigid body holding a ground half-space (as scenes make the ground), and its collider.
fn fixed_ground() -> (ColliderSet, RigidBodySet, rapier3d::prelude::ColliderHandle) {
    use rapier3d::prelude::RigidBodyBuilder;
    let (mut colliders, mut bodies) = (ColliderSet::new(), RigidBodySet::new());
    let fixed = bodies.insert(RigidBodyBuilder::fixed());
    let shape = ColliderBuilder::new(SharedShape::halfspace(rapier_fvm::glamx::Vec3::Y));
    let ground = colliders.insert_with_parent(shape, fixed, &mut bodies);
    (colliders, bodies, ground)
}

#[test]
fn a_body_resting_on_a_fixed_half_space_touches_it_only_within_reach() {
    // Reach at rest over a 1/60 s frame: the 1 mm margin plus 2 |g| dt² = 5.45 mm. The cube's
    // bottom face (5 x 5 nodes) is 0.5 mm above the ground, its next layer 25.5 mm: 25 contacts.
    // A half-space's bounds are infinite; its fixed body, not turning, must not make every
    // surface node within a metre a contact (it did: 0 x infinity made the reach NaN, which
    // `f64::min` turned into the largest collider reach, 1 m).
    let (colliders, bodies, ground) = fixed_ground();
    let cube = rubber_cube(DVec3::new(0.0, 0.0505, 0.0), DVec3::ZERO);
    assert_eq!(contacts_with(&cube, (&colliders, &bodies), ground), (25, 0));
}

#[test]
fn a_collider_about_to_strike_a_body_widens_its_reach_to_the_ground() {
    // The cube's bottom is 10 mm above the ground, beyond its own reach at rest (6.45 mm): no
    // contact. A box 2 mm above its top falling at 3 m/s can drive it down within the frame,
    // so the ground's reach grows by the box's travel (2 x 3 m/s x 1/60 s = 0.1 m, to 106.5 mm):
    // the bottom face's 25 nodes and the 16 surface nodes of each layer 35, 60 and 85 mm up
    // touch it, not the top face at 110 mm.
    use rapier3d::prelude::RigidBodyBuilder;
    let (mut colliders, mut bodies, ground) = fixed_ground();
    let cube = rubber_cube(DVec3::new(0.0, 0.06, 0.0), DVec3::ZERO);
    assert_eq!(contacts_with(&cube, (&colliders, &bodies), ground), (0, 0));
    let falling = RigidBodyBuilder::dynamic()
        .translation(rapier_fvm::glamx::Vec3::new(0.0, 0.127, 0.0))
        .linvel(rapier_fvm::glamx::Vec3::new(0.0, -3.0, 0.0));
    let falling = bodies.insert(falling);
    let shape = ColliderBuilder::cuboid(0.015, 0.015, 0.015);
    colliders.insert_with_parent(shape, falling, &mut bodies);
    let (on_ground, on_box) = contacts_with(&cube, (&colliders, &bodies), ground);
    assert_eq!(on_ground, 25 + 3 * 16);
    assert!(on_box > 0, "the box's own contacts with the top face");
}

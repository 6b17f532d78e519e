//! Dynamic rigid bodies touching or glued to soft bodies, under every integrator: the coupled
//! system's energy never rises (rigid bodies included), a strike without restitution never
//! rebounds faster than it came, a ball faster than its own size per coupling substep meets the
//! soft nodes in its path, and light and heavy partners (mass ratios 1e-6 to 1e6) stay where the
//! statics puts them.
//!
//! The energy of the whole system is the soft bodies' kinetic, elastic and gravitational energy
//! plus the rigid bodies' kinetic energy and their gravitational energy at the position half a
//! (coupling sub)step back along their velocity, which rapier's symplectic Euler step keeps
//! exactly in free flight (so that the check sees only what the coupling adds).

mod common;

use rapier_fvm::coupling::{Audit, FrameAudit};
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle, SharedShape};

const GRAVITY: DVec3 = DVec3::new(0.0, -9.81, 0.0);

/// The energy (J) of `world`: every soft body's kinetic, elastic and gravitational energy, and
/// every dynamic rigid body's kinetic and (half a frame back) gravitational energy.
fn coupled_energy(world: &FvmWorld) -> f64 {
    let soft: f64 = world
        .soft_bodies
        .iter()
        .map(|(_, b)| b.kinetic_energy() + b.elastic_energy() + b.gravity_potential_energy(GRAVITY))
        .sum();
    // rapier steps the rigid bodies in coupling substeps of `h`.
    let h = f64::from(world.physics.integration_parameters.dt) / f64::from(world.coupling.substeps);
    let rigid: f64 = world
        .physics
        .bodies
        .iter()
        .filter(|(_, b)| b.is_dynamic())
        .map(|(_, b)| {
            let mass = f64::from(b.mass());
            let v = b.linvel().as_dvec3();
            let w = b.angvel().as_dvec3();
            let inertia = b.mass_properties().effective_world_inv_inertia;
            let spin = if w == DVec3::ZERO {
                0.0
            } else {
                // ½ ωᵀ I ω with I the inverse of the world inverse inertia.
                let i = inertia;
                let m = DMat3::from_cols_array(
                    &[
                        i.m11, i.m12, i.m13, i.m12, i.m22, i.m23, i.m13, i.m23, i.m33,
                    ]
                    .map(f64::from),
                );
                0.5 * w.dot(m.inverse() * w)
            };
            let com = b.center_of_mass().as_dvec3() - v * (h / 2.0);
            0.5 * mass * v.length_squared() + spin - mass * GRAVITY.dot(com)
        })
        .sum();
    soft + rigid
}

fn soft_block(half: f64, cells: usize, centre: DVec3, young: f64, density: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, density).unwrap();
    let mut body = DeformableBodyBuilder::new(
        mesh::cuboid(DVec3::splat(half), [cells; 3]).unwrap(),
        material,
    )
    .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
    .translation(centre)
    .build()
    .unwrap();
    body.friction = 0.8;
    body
}

/// What a run did: the largest rise of the coupled energy above its start (J), and per frame
/// whether every soft body's step was refused for needing too many explicit substeps.
struct Run {
    energy_rise: f64,
    refused_frames: usize,
    frames: usize,
}

impl Run {
    /// Whether every frame was refused with [`Error::TooManySubsteps`] (a scene too stiff for
    /// the forced explicit integrator): a clear error rather than a wrong motion.
    fn all_refused(&self) -> bool {
        self.refused_frames == self.frames
    }
}

/// Steps `world` for `frames`, calling `each` after every frame; a step that fails with anything
/// but [`Error::TooManySubsteps`] fails the test.
fn run(world: &mut FvmWorld, frames: usize, mut each: impl FnMut(&FvmWorld)) -> Run {
    let start = coupled_energy(world);
    let mut run = Run {
        energy_rise: 0.0,
        refused_frames: 0,
        frames,
    };
    for _ in 0..frames {
        let mut refused = false;
        for (handle, outcome) in world.step() {
            match outcome {
                Ok(_) => {}
                Err(Error::TooManySubsteps { .. }) => refused = true,
                Err(error) => panic!("{handle:?}: {error}"),
            }
        }
        run.refused_frames += usize::from(refused);
        run.energy_rise = run.energy_rise.max(coupled_energy(world) - start);
        each(world);
    }
    run
}

/// The tolerance (J) on the coupled energy's rise in a world whose bodies weigh `weight` (N)
/// and span `height` (m), carrying kinetic energy `kinetic` (J): rapier keeps the rigid bodies'
/// state in f32, whose relative rounding (6e-8) over the frames' handful of operations leaves
/// the energy exact to about 1e-6 of its scale. Everything the coupling could add is far above.
fn energy_tolerance(weight: f64, height: f64, kinetic: f64) -> f64 {
    1e-6 * (weight * height + kinetic)
}

/// The integrators every case runs under: the automatic choice, forced implicit, forced
/// explicit.
const INTEGRATORS: [Option<IntegratorKind>; 3] = [
    None,
    Some(IntegratorKind::Implicit),
    Some(IntegratorKind::Explicit),
];

fn box_on_block(
    integrator: Option<IntegratorKind>,
    box_mass: f64,
    young: f64,
) -> (FvmWorld, RigidBodyHandle) {
    let mut world = common::world_with_ground(integrator);
    world.soft_bodies.insert(soft_block(
        0.05,
        4,
        DVec3::new(0.0, 0.05, 0.0),
        young,
        1000.0,
    ));
    let rigid = place_box(&mut world, box_mass, 0.1);
    (world, rigid)
}

/// A dynamic 4 cm box of `mass` (kg, friction 0.8) placed 0.5 mm above the height `top` (m), 1 cm
/// off the vertical axis.
fn place_box(world: &mut FvmWorld, mass: f64, top: f32) -> RigidBodyHandle {
    let half = 0.02f32;
    let density = mass as f32 / (8.0 * half * half * half);
    let (rigid, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.01, top + half + 5e-4, 0.0)),
        ColliderBuilder::cuboid(half, half, half)
            .density(density)
            .friction(0.8),
    );
    rigid
}

/// Runs `world` 2 s with its box `rigid` placed on soft bodies; `label` names the case, and the
/// system weighs `weight` (N) over `height` (m). The box must settle: never rise more than 1 mm
/// above where it was placed, end within 5 mm of it and within 1 mm sideways, the whole
/// system's energy never above its start (f32 rounding, see `energy_tolerance`); or, if
/// `refused`, every frame must be refused (a scene too stiff for the forced explicit
/// integrator).
fn settle_box(
    (world, rigid): (&mut FvmWorld, RigidBodyHandle),
    label: &str,
    (weight, height): (f64, f64),
    refused: bool,
) {
    let start = world.physics.bodies[rigid].translation().as_dvec3();
    let mut highest = f64::NEG_INFINITY;
    let run = run(world, 120, |w| {
        highest = highest.max(f64::from(w.physics.bodies[rigid].translation().y));
    });
    let end = world.physics.bodies[rigid].translation().as_dvec3();
    let tolerance = energy_tolerance(weight, height, 0.0);
    println!(
        "{label}: energy rise {:.2e} J (tolerance {tolerance:.1e}), refused {}/{}, highest {:+.3} mm, end {:+.3?} mm",
        run.energy_rise,
        run.refused_frames,
        run.frames,
        (highest - start.y) * 1e3,
        (end - start) * 1e3
    );
    if refused {
        assert!(run.all_refused(), "{label}");
        return;
    }
    assert_eq!(run.refused_frames, 0, "{label}");
    assert!(run.energy_rise <= tolerance, "{label}");
    assert!(highest - start.y < 1e-3, "{label}");
    assert!((end.y - start.y).abs() < 5e-3, "{label}");
    assert!(
        DVec3::new(end.x - start.x, 0.0, end.z - start.z).length() < 1e-3,
        "{label}"
    );
}

/// A ball of `ball_mass` (kg, radius 2 cm) flying at 3 m/s into a free 10 cm soft cube (1 kg,
/// E = `young`) without gravity, restitution 0; returns the run, the ball's speed away from the
/// cube's centre of mass at the end (m/s).
fn strike(integrator: Option<IntegratorKind>, ball_mass: f64, young: f64) -> (Run, f64) {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.gravity = Vec3::ZERO;
    let cube = world
        .soft_bodies
        .insert(soft_block(0.05, 4, DVec3::ZERO, young, 1000.0));
    let radius = 0.02f32;
    let density = ball_mass as f32 / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3));
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vec3::new(-0.1, 0.01, 0.0))
            .linvel(Vec3::new(3.0, 0.0, 0.0)),
        ColliderBuilder::ball(radius)
            .density(density)
            .restitution(0.0),
    );
    let run = run(&mut world, 40, |_| {});
    let away = {
        let soft = &world.soft_bodies[cube];
        let velocity = soft.linear_momentum() / soft.total_mass();
        let ball = &world.physics.bodies[ball];
        let direction = (ball.translation().as_dvec3() - soft.center_of_mass()).normalize();
        (ball.linvel().as_dvec3() - velocity).dot(direction)
    };
    (run, away)
}

/// A 2 cm ball of 100 g (restitution 0) falling at 30 m/s from 1 mm above a 10 cm soft block
/// (E = 1e6 Pa, 1 kg) on the ground, in frames of `dt` (s) of rapier's four coupling substeps;
/// returns the world, the ball and the block's top centre node, which the ball strikes head-on.
fn fast_ball(integrator: Option<IntegratorKind>, dt: f64) -> (FvmWorld, RigidBodyHandle, usize) {
    let mut world = common::world_with_ground(integrator);
    world.physics.integration_parameters.dt = dt as f32;
    let block = soft_block(0.05, 4, DVec3::new(0.0, 0.05, 0.0), 1e6, 1000.0);
    let top = DVec3::new(0.0, 0.1, 0.0);
    let struck = (0..block.positions().len())
        .min_by(|&a, &b| {
            let distance = |n: usize| (block.positions()[n] - top).length();
            distance(a).total_cmp(&distance(b))
        })
        .unwrap();
    world.soft_bodies.insert(block);
    let radius = 0.01f32;
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vec3::new(0.0, 0.1 + radius + 1e-3, 0.0))
            .linvel(Vec3::new(0.0, -30.0, 0.0)),
        ColliderBuilder::ball(radius)
            .density(0.1 / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3)))
            .restitution(0.0),
    );
    (world, ball, struck)
}

/// The first thing `found` (the audit of frame `frame`) flags, if anything.
fn audit_finding(found: &FrameAudit, frame: usize) -> Option<String> {
    (!found.is_clean()).then(|| format!("frame {frame}: {found:?}"))
}

/// A 20 cm soft rope (1 x 1 cm, 20 g, clamped at the top) with a ball of `ratio` times its mass
/// glued below its end, hanging at rest in a world of frame step `dt` (s), its Young's modulus
/// chosen so that the static stretch is 1 % of its length; returns the world, the ball and
/// where it was placed (m).
fn rope_and_ball(
    integrator: Option<IntegratorKind>,
    ratio: f64,
    dt: f64,
) -> (FvmWorld, RigidBodyHandle, DVec3) {
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = integrator;
    world.physics.integration_parameters.dt = dt as f32;
    let (length, side) = (ROPE_LENGTH, 0.01);
    let rope_mass = 0.02;
    let density = rope_mass / (length * side * side);
    let ball_mass = ratio * rope_mass;
    let load = (ball_mass + rope_mass / 2.0) * 9.81;
    let young = load / (0.01 * side * side);
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, density).unwrap();
    let mesh = mesh::cuboid(DVec3::new(side / 2.0, length / 2.0, side / 2.0), [2, 20, 2]).unwrap();
    let top = mesh.nodes_where(|p| p.y >= length / 2.0 - 1e-9);
    let bottom = mesh.nodes_where(|p| p.y <= -length / 2.0 + 1e-9);
    let rope = DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
        .translation(DVec3::new(0.0, -length / 2.0, 0.0))
        .pinned_nodes(top)
        .build()
        .unwrap();
    let radius = 0.01f64;
    let ball_density = ball_mass / (4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
    let centre = DVec3::new(0.0, -(length + radius + 1e-3), 0.0);
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(centre.as_vec3()),
        ColliderBuilder::ball(radius as f32).density(ball_density as f32),
    );
    let rope = world.soft_bodies.insert(rope);
    world.attach(rope, bottom, ball).unwrap();
    (world, ball, centre)
}

/// The rope's length (m).
const ROPE_LENGTH: f64 = 0.2;

/// [`rope_and_ball`] at 1/60 s frames run 1 s; returns the run and the ball's drop below the
/// unstretched end (m) at the end, with the expected static stretch (m).
fn hanging(integrator: Option<IntegratorKind>, ratio: f64) -> (Run, f64, f64) {
    let (mut world, ball, centre) = rope_and_ball(integrator, ratio, 1.0 / 60.0);
    let run = run(&mut world, 60, |_| {});
    let drop = centre.y - f64::from(world.physics.bodies[ball].translation().y);
    (run, drop, 0.01 * ROPE_LENGTH)
}

/// Steps `world` `frames` frames under a per-frame audit with its default tolerances; returns
/// every frame the audit did not find clean, with what it found.
fn unclean_frames(world: &mut FvmWorld, frames: usize) -> Vec<(usize, FrameAudit)> {
    let mut audit = Audit::default();
    audit.restart_world(world);
    (1..=frames)
        .filter_map(|frame| {
            let results = world.step();
            let found = audit.check_world(world, &results);
            (!found.is_clean()).then_some((frame, found))
        })
        .collect()
}

#[test]
fn boxes_light_and_heavy_rest_on_a_soft_block_under_every_integrator() {
    // A 4 cm rigid box of 1 g to 10 kg placed 0.5 mm above a 10 cm soft block (E = 1e6 or 1e9
    // Pa, 1 kg) on the ground, 2 s. It must settle on the block: never rise more than 1 mm
    // above where it was placed (it was thrown up to 777 m when an implicit step froze it), end
    // within 5 mm of it (the block's compression under 10 kg is about 1.5 mm) and within 1 mm
    // sideways, with the whole system's energy never above its start (tolerance: f32 rounding,
    // see `energy_tolerance`). The explicit integrator cannot step the 1e9 Pa block at 1/60 s:
    // it must refuse every frame.
    for integrator in INTEGRATORS {
        for (mass, young) in [
            (1e-3, 1e9),
            (1e-2, 1e9),
            (0.1, 1e9),
            (0.1, 1e6),
            (2.0, 1e6),
            (10.0, 1e6),
        ] {
            let (mut world, rigid) = box_on_block(integrator, mass, young);
            let label = format!("{integrator:?}, {mass} kg on E = {young:e}");
            let refused = integrator == Some(IntegratorKind::Explicit) && young >= 1e9;
            let scale = ((mass + 1.0) * 9.81, 0.15);
            settle_box((&mut world, rigid), &label, scale, refused);
        }
    }
}

#[test]
fn a_box_landing_on_a_soft_block_in_one_coupling_substep_comes_to_rest_and_gains_nothing() {
    // A 4 cm box of 0.5 kg dropped 5 cm onto a 10 cm soft block (E = 5e5 Pa, 1 kg) on the
    // ground, forced implicit steps, one coupling substep per 1/60 s frame (rapier's default
    // four solver iterations in it), 2 s. The implicit step carries the box by h v; rapier's
    // step, integrating in four parts, carried it (n − 1)/(2n) |g| h² = 1.0 mm less far down,
    // so the box resting on the block ended every frame moving down at (n − 1)/(2n) |g| h =
    // 61 mm/s, and the audit saw the coupled system gain energy as the box settled. At rest the
    // box must be still (10⁻³ of that speed: f32 rounding and the block's creep are far below)
    // and no frame may show a gain, penetration or anything else the audit flags.
    let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
    world.coupling.substeps = 1;
    let block = soft_block(0.05, 3, DVec3::new(0.0, 0.05, 0.0), 5e5, 1000.0);
    world.soft_bodies.insert(block);
    let rigid = place_box(&mut world, 0.5, 0.15);
    let unclean = unclean_frames(&mut world, 120);
    let body = &world.physics.bodies[rigid];
    let (v, w) = (body.linvel().as_dvec3(), body.angvel().as_dvec3());
    let ghost = 3.0 / 8.0 * 9.81 / 60.0;
    println!(
        "unclean frames {}, final speed {:.2e} m/s (ghost {ghost:.3} m/s), spin {:.2e} rad/s",
        unclean.len(),
        v.length(),
        w.length()
    );
    assert!(unclean.is_empty(), "{:?}", unclean.first());
    assert!(v.length() < 1e-3 * ghost, "{v:?}");
    assert!(w.length() < 1e-3, "{w:?}");
}

#[test]
fn a_box_rests_on_a_stack_of_two_soft_blocks_under_every_integrator() {
    // The boxes of the test above, 0.1 and 2 kg, on a stack of two 10 cm soft blocks (E = 1e6
    // Pa, 1 kg each) on the ground, 2 s: the blocks touch each other and step together (one
    // implicit system under forced implicit steps, the box a rigid partner of the top block).
    // The same bounds: never more than 1 mm above where it was placed, at the end within 5 mm
    // of it (the stack's compression under 2 kg is about 0.6 mm) and within 1 mm sideways, the
    // whole system's energy never above its start (f32 rounding, see `energy_tolerance`).
    for integrator in INTEGRATORS {
        for mass in [0.1, 2.0] {
            let mut world = common::world_with_ground(integrator);
            for centre in [0.05, 0.1505] {
                world.soft_bodies.insert(soft_block(
                    0.05,
                    4,
                    DVec3::new(0.0, centre, 0.0),
                    1e6,
                    1000.0,
                ));
            }
            let rigid = place_box(&mut world, mass, 0.2005);
            let label = format!("{integrator:?}, {mass} kg on two blocks");
            let scale = ((mass + 2.0) * 9.81, 0.25);
            settle_box((&mut world, rigid), &label, scale, false);
        }
    }
}

#[test]
fn a_ball_striking_a_soft_cube_without_restitution_never_leaves_faster_than_it_came() {
    // A 2 cm ball of 1 g to 1 t at 3 m/s into a free 10 cm soft cube (1 kg) without gravity,
    // restitution 0, 40 frames. Its speed away from the cube's centre of mass afterwards is at
    // most its approach speed (the cube's elasticity may push it back, the contact adds nothing;
    // an implicit step with the ball frozen sent it off at up to 99 m/s), and the system's
    // energy never rises above its start (tolerance: f32 rounding). The explicit integrator must
    // refuse the 1e9 Pa cube.
    for integrator in INTEGRATORS {
        for (mass, young) in [(1e-3, 1e6), (1.0, 1e6), (1e3, 1e6), (1e-3, 1e9), (1.0, 1e9)] {
            let (run, away) = strike(integrator, mass, young);
            let tolerance = energy_tolerance(0.0, 0.0, 0.5 * mass * 9.0);
            println!(
                "{integrator:?}, {mass} kg into E = {young:e}: energy rise {:.2e} J (tolerance {tolerance:.1e}), refused {}/{}, leaving at {away:.3} m/s",
                run.energy_rise, run.refused_frames, run.frames
            );
            if integrator == Some(IntegratorKind::Explicit) && young >= 1e9 {
                assert!(run.all_refused());
                continue;
            }
            assert_eq!(run.refused_frames, 0);
            assert!(run.energy_rise <= tolerance);
            assert!(away <= 3.0);
        }
    }
}

#[test]
fn a_ball_hanging_from_a_soft_rope_stretches_it_as_the_statics_says_at_every_mass_ratio() {
    // A ball of 1e-6 to 1e6 times a 20 g rope's mass, glued to its end, released at rest; the
    // rope's modulus is set so that the static stretch, (M + m/2) g L / (E A), is 2 mm. After
    // 1 s the ball's drop must be that stretch within 3 % (the Neo-Hookean law at 1 % strain
    // and the rope's lateral contraction differ from the linear estimate by about 1 %; an
    // implicit step with the ball frozen dropped an 80 t ball 2.17 m), and the system's energy
    // never rises above its start (tolerance: f32 rounding). The explicit integrator cannot step
    // the stiff ropes the heavy balls need at 1/60 s: it must refuse them every frame.
    for integrator in INTEGRATORS {
        for ratio in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
            let (run, drop, expected) = hanging(integrator, ratio);
            let weight = (ratio + 1.0) * 0.02 * 9.81;
            let tolerance = energy_tolerance(weight, 0.25, 0.0);
            println!(
                "{integrator:?}, ratio {ratio:e}: energy rise {:.2e} J (tolerance {tolerance:.1e}), refused {}/{}, drop {:.4} mm vs {:.4} mm",
                run.energy_rise,
                run.refused_frames,
                run.frames,
                drop * 1e3,
                expected * 1e3
            );
            if run.all_refused() && integrator == Some(IntegratorKind::Explicit) {
                assert!(ratio >= 1e3, "only the stiff ropes are refused");
                continue;
            }
            assert_eq!(run.refused_frames, 0);
            assert!(run.energy_rise <= tolerance);
            assert!((drop / expected - 1.0).abs() < 0.03);
        }
    }
}

#[test]
fn a_heavy_ball_on_a_rope_gains_no_energy_in_any_long_implicit_frame() {
    // The 20 kg ball (1000 times the 20 g rope) of the test above, forced implicit at 1/60 and
    // 1/30 s frames, 2 s. The per-frame audit, with its default tolerances (an energy rise of
    // 0.1 % of the kinetic and elastic energy, Newton's tolerance, plus rapier's f32 rounding
    // of the ball's state), finds nothing in any frame: no energy gained by the coupled system,
    // no failed Newton solve; and the ball ends at the static stretch within 3 %. The implicit
    // step solves the ball's motion with the rope's as one backward Euler step, whose energy
    // `m v²/2 − m g·x` plus the rope's cannot rise: measured with the ball's height half a
    // substep back along its velocity (exact for rapier alone in free flight), the coupled
    // energy rose by 4.2e-3 J in frame 4 at 1/30 s (tolerance 2.8e-4 J) and by 2.3e-3 J in
    // frame 6 at 1/60 s as the backward Euler step slowed the rising ball.
    for dt in [1.0 / 60.0, 1.0 / 30.0] {
        let (mut world, ball, centre) = rope_and_ball(Some(IntegratorKind::Implicit), 1e3, dt);
        let unclean = unclean_frames(&mut world, (2.0 / dt).round() as usize);
        let drop = centre.y - f64::from(world.physics.bodies[ball].translation().y);
        let expected = 0.01 * ROPE_LENGTH;
        println!(
            "dt {dt:.4}: {} unclean frames, first {:?}; drop {:.4} mm vs {:.4} mm",
            unclean.len(),
            unclean.first(),
            drop * 1e3,
            expected * 1e3
        );
        assert!(unclean.is_empty(), "dt {dt}: {:?}", unclean.first());
        assert!((drop / expected - 1.0).abs() < 0.03, "dt {dt}");
    }
}

#[test]
fn a_ball_at_30_m_per_s_meets_the_soft_nodes_in_its_path_and_gains_no_energy() {
    // A 2 cm ball of 100 g at 30 m/s into a 10 cm soft block (E = 1e6 Pa) on the ground, 20
    // frames of 1/240, 1/60 and 1/30 s, automatic and forced explicit integrators (both step it
    // explicitly). rapier moves the ball 3 to 25 cm per coupling substep, more than its
    // diameter: a soft step that saw the ball frozen where the substep began let it jump past
    // the node it strikes, which ended on its far side. The node it strikes head-on must stay
    // below the ball's centre, and every frame must pass the audit (`coupling::Audit`, default
    // tolerances): no node through the ball or deeper in it than the penetration tolerance, and
    // neither the whole system's energy nor the block's with the bodies it exchanged energy
    // with over the frame risen by more than 0.1 % of their kinetic and elastic energy plus the
    // allowances for f32 rounding and symplectic Euler's oscillation (the strike itself loses
    // about 40 of the ball's 45 J).
    for integrator in [None, Some(IntegratorKind::Explicit)] {
        for dt in [1.0 / 240.0, 1.0 / 60.0, 1.0 / 30.0] {
            let (mut world, ball, struck) = fast_ball(integrator, dt);
            let block = world.soft_bodies.iter().next().unwrap().0;
            let label = format!("{integrator:?} at dt {dt:.2e} s");
            let mut audit = Audit::default();
            audit.restart_world(&world);
            for frame in 1..=20 {
                let results = world.step();
                for (_, outcome) in &results {
                    assert!(outcome.is_ok(), "{label}: {outcome:?}");
                }
                let found = audit.check_world(&world, &results);
                let node = world.soft_bodies[block].positions()[struck];
                let centre = world.physics.bodies[ball].translation().as_dvec3();
                assert!(node.y < centre.y, "{label}, frame {frame}: {node} {centre}");
                assert!(audit_finding(&found, frame).is_none(), "{label}: {found:?}");
            }
        }
    }
}

#[test]
fn a_fast_ball_into_a_soft_block_is_solved_in_every_short_implicit_frame() {
    // A 2 cm ball of 100 g at 30 m/s into a 10 cm soft block (E = 1e6 Pa, 1 kg, friction 0.8)
    // resting on the ground (friction 0.5), forced implicit at 1/240 s frames, 20 frames
    // (rapier's four coupling substeps a frame). Every Newton solve meets its tolerance and the
    // audit finds nothing (default tolerances, see the test above). The strike spreads the
    // block's base on the ground, where interior nodes must stick: Newton's model, flat along a
    // sliding node's slip, carried them past their stick zone of `stiction_speed h`, and the
    // halving line search left them short of it from one iteration to the next, so that the
    // third coupling substep of frame 1 stopped at 20 iterations with its residual cycling
    // between 0.15 and 0.39; the search now lands on the lowest energy up to the rejected step.
    let mut world = FvmWorld::default();
    world.coupling.integrator.force = Some(IntegratorKind::Implicit);
    world.physics.integration_parameters.dt = 1.0 / 240.0;
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    world
        .soft_bodies
        .insert(soft_block(0.05, 4, DVec3::new(0.0, 0.05, 0.0), 1e6, 1000.0));
    let radius = 0.01f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vec3::new(0.0, 0.1 + radius + 1e-3, 0.0))
            .linvel(Vec3::new(0.0, -30.0, 0.0)),
        ColliderBuilder::ball(radius)
            .density(0.1 / (4.0 / 3.0 * std::f32::consts::PI * radius.powi(3)))
            .restitution(0.0),
    );
    let unclean = unclean_frames(&mut world, 20);
    println!(
        "{} unclean frames, first {:?}",
        unclean.len(),
        unclean.first()
    );
    assert!(unclean.is_empty(), "{:?}", unclean.first());
}

#[test]
fn a_1_g_box_on_a_stiff_block_stepped_explicitly_does_not_bounce_off() {
    // A 4 cm box of 1 g placed 0.5 mm above a 10 cm block of E = 1e9 Pa, stepped explicitly in
    // frames of 1/240 s (65 383 substeps each, 16 346 per coupling substep), 8 frames: it lands
    // in the third. rapier's step leaves a corner of the spinning box micrometres inside the
    // block; pushed out within one explicit substep at the depenetration speed (0.1 m/s), it
    // kicked the box up at 6 cm/s and gained 3.5e-6 J. Every frame must pass the audit (default
    // tolerances: the energy may rise by 0.1 % of the kinetic and elastic energy plus the
    // allowances, 1.5e-7 J here) and the box must never rise faster than 1 cm/s, a tenth of
    // the speed it lands at (restitution 0: the stiff block's spring-back alone may lift it).
    let (mut world, rigid) = box_on_block(Some(IntegratorKind::Explicit), 1e-3, 1e9);
    world.physics.integration_parameters.dt = 1.0 / 240.0;
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let started = std::time::Instant::now();
    for frame in 1..=8 {
        let results = world.step();
        for (_, outcome) in &results {
            assert!(outcome.is_ok(), "{outcome:?}");
        }
        let found = audit.check_world(&world, &results);
        let rising = world.physics.bodies[rigid].linvel().y;
        println!(
            "frame {frame}: box rising at {rising:+.2e} m/s, system energy {:?}",
            found.system
        );
        assert!(audit_finding(&found, frame).is_none(), "{found:?}");
        assert!(rising < 1e-2, "frame {frame}: {rising} m/s");
    }
    println!(
        "{:.0} ms per frame",
        started.elapsed().as_secs_f64() * 1e3 / 8.0
    );
}

#[test]
fn a_heavy_box_crushing_a_foam_block_under_implicit_steps_is_never_thrown_up() {
    // A 10 cm rigid box of 10 kg or 1000 kg released at rest 1 mm above a foam block (E = 10
    // kPa, 20 x 10 x 20 cm, 100 kg/m³) on the ground, implicit steps at 1/60 s for a third of a
    // second. The foam cannot carry either box (10 kg presses 9.8 kPa, about its modulus):
    // elements under the box's edges are crushed and frames refused with a typed error (the
    // state before them kept), or the box sinks. Released at rest with nothing to give it
    // energy, it can never rise above where it was released (1 mm: the contacts' speculative
    // margin). The rigid bodies' response in each step, a Newton solve whose backtracking line
    // search crept toward the point where the contacts come in by a fraction of the step per
    // iteration, was left unsolved, and the 10 kg box was thrown up from frame 9 (0.57 m after
    // 20 frames, 0.67 m at its highest).
    for mass in [10.0, 1000.0] {
        let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
        common::insert_foam_block(&mut world, MaterialModel::StableNeoHookean);
        let (rigid, _) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.151, 0.0)),
            ColliderBuilder::cuboid(0.05, 0.05, 0.05).density((mass / 1e-3) as f32),
        );
        let released = f64::from(world.physics.bodies[rigid].translation().y);
        let (mut highest, mut refused) = (f64::NEG_INFINITY, 0);
        for _ in 0..20 {
            for (_, outcome) in world.step() {
                refused += usize::from(outcome.is_err());
            }
            let y = f64::from(world.physics.bodies[rigid].translation().y);
            highest = highest.max(y);
        }
        println!(
            "{mass} kg: highest {:+.3} mm above its release, refused {refused}/20 frames",
            (highest - released) * 1e3
        );
        assert!(highest - released < 1e-3, "{mass} kg");
    }
}

#[test]
fn a_box_crushing_a_soft_block_in_long_implicit_frames_stays_on_it_or_slides_off_as_explicit_steps_do()
 {
    // A 100 kg, 4 cm box on the 10 cm, 1 kg block of E = 1e6 Pa (its weight, 0.6 MPa on the
    // box's face, is more than the block can carry), at 1/30 s frames: the extremes sweep's
    // heaviest box. Released 1 cm off centre, it tilts into the crushed block and slides off its
    // edge. While the box's footprint overlaps the block's top (|x| < 5 cm + 2 cm), every frame
    // taken forced implicit must leave its centre above the top face less half the box's side
    // (it may sink into the crushed block, not pass through it), and its sideways slide must
    // follow forced explicit substeps' within 2 mm (measured: 0.9 mm; the heights differ by up
    // to 5 mm, the implicit bounce being damped). A frame the implicit step cannot take is
    // refused with a typed error, and the run ends there. Before a frame redone in more
    // substeps put the rigid corners back where they were with the rest of the state, the box
    // passed through the block's top triangles (its centre 6.8 cm up at frame 12 with the top
    // face at 9.4 cm); with the box's mass counted in the contacts' penalties, the step was
    // refused at frame 5 (Newton wandering between contacts switching on and off).
    let path = |kind| {
        let (mut world, rigid) = box_on_block(Some(kind), 100.0, 1e6);
        world.physics.integration_parameters.dt = 1.0 / 30.0;
        let block = world.soft_bodies.iter().next().unwrap().0;
        let mut frames = Vec::new();
        for frame in 0..30 {
            let refused = world
                .step()
                .into_iter()
                .find_map(|(_, result)| result.err());
            if let Some(error) = refused {
                println!("{kind:?}, frame {frame}: refused: {error}");
                break;
            }
            let at = world.physics.bodies[rigid].translation();
            let face = common::mean_height_of_nodes_above(&world.soft_bodies[block], 0.05 - 1e-9);
            frames.push((f64::from(at.x), f64::from(at.y), face));
        }
        frames
    };
    let explicit = path(IntegratorKind::Explicit);
    let implicit = path(IntegratorKind::Implicit);
    for (frame, (&(x, centre, face), &(reference, ..))) in
        implicit.iter().zip(&explicit).enumerate()
    {
        println!(
            "frame {frame}: box at x {x:.4} m (explicit {reference:.4}), centre {centre:.4} m, \
             top face {face:.4} m"
        );
        if x.abs() < 0.05 + 0.02 {
            assert!(
                centre > face - 0.02,
                "frame {frame}: box centre {centre:.4} m, block's top face {face:.4} m"
            );
            assert!(
                (x - reference).abs() < 2e-3,
                "frame {frame}: x {x} m, explicit {reference} m"
            );
        }
    }
}

/// Steps `world` (one soft body) `frames` times; the soft body's positions at the end, and the
/// factorizations and reused iterations of each frame's last implicit substep, summed.
fn implicit_work(world: &mut FvmWorld, frames: usize) -> (Vec<DVec3>, usize, usize) {
    let (mut factorizations, mut reused) = (0, 0);
    for _ in 0..frames {
        for (handle, outcome) in world.step() {
            let report = outcome.unwrap_or_else(|e| panic!("{handle:?}: {e}"));
            let implicit = report.implicit.expect("forced implicit");
            assert!(implicit.converged, "{implicit:?}");
            factorizations += implicit.factorizations;
            reused += implicit.reused_factorizations;
        }
    }
    let (_, body) = world.soft_bodies.iter().next().unwrap();
    (body.positions().to_vec(), factorizations, reused)
}

#[test]
fn a_block_under_a_resting_box_reuses_its_factorization_and_meets_the_same_tolerance() {
    // A 30 g, 4 cm box placed on a 10 cm soft block (E = 1e6 Pa, 1 kg) on the ground, forced
    // implicit, never asleep, 1 s: Newton reusing earlier factorizations (the chord) against
    // Newton with the exact tangent at every iteration, both to the default tolerance 1e-6 of
    // the force scale. Each run stops within that of the same minimum at every substep, so the
    // block's nodes agree to about 1e-6 of its motion per substep; 1e-4 of the motion is
    // allowed after 240 substeps. The box, light against the penalties that hold it, follows
    // the block's top: the Newton matrix is the held tangent less nearly all of its contact
    // stiffness, taken in by the box's response. A reused iteration that took that response in
    // with the current coupling on an earlier tangent missed the few percent the contacts'
    // pieces had changed by, and the chord gave reuse up at almost every substep (55
    // factorizations against the exact run's 60 in the frames' last substeps, measured with
    // this test before the change); with the coupling kept with its factorization, the reused
    // matrix is the earlier exact one (1 against 60; at most a quarter allowed).
    let settled = |reuse: bool| {
        let (mut world, _) = box_on_block(Some(IntegratorKind::Implicit), 0.03, 1e6);
        world.coupling.integrator.implicit.reuse_factorization = reuse;
        world.coupling.sleep = SleepSettings::never();
        let start = world
            .soft_bodies
            .iter()
            .next()
            .unwrap()
            .1
            .positions()
            .to_vec();
        (start, implicit_work(&mut world, 60))
    };
    let (start, (chord, chord_factorizations, reused)) = settled(true);
    let (_, (exact, exact_factorizations, none)) = settled(false);
    assert_eq!(none, 0);
    let gap = (chord.iter().zip(&exact))
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    let motion = (exact.iter().zip(&start))
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    println!(
        "gap {gap:.3e} m of {motion:.3e} m of motion; chord {chord_factorizations} factorizations \
         and {reused} reuses, exact Newton {exact_factorizations} factorizations"
    );
    assert!(gap < 1e-4 * motion, "gap {gap} m");
    assert!(reused > 0);
    assert!(4 * chord_factorizations <= exact_factorizations);
}

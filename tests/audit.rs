//! The per-frame audit (`coupling::Audit`): each check raised on a state built to fail it, and
//! none raised on a body at rest on the ground or falling freely.
//!
//! Tolerances are the audit's defaults (`AuditSettings::default()`): an energy rise of 0.1 % of
//! the kinetic and elastic energy plus 1e-9 J, plus f32 rounding of rigid bodies and, after
//! explicit steps, `(h / h_crit)(K + Ψ)` for symplectic Euler's oscillation, a penetration of
//! the larger of the contact margin (1 mm) and a quarter of the smallest rest altitude (for the
//! 10 cm cubes of 4 cells here, about 3 mm), a collapse below 1 % of the rest volume. The
//! constructed failures are far beyond them (a node 20 mm deep, a cube moved 20 cm through a
//! 2 mm wall or a 4 mm soft sheet, volumes at 0.5 %, a 1 m/s kick); the clean cases are checked
//! with the same tolerances, and the free fall against its closed-form energy loss.

mod common;

use rapier_fvm::coupling::{Audit, AuditSettings, BodyAudit, FrameAudit, PenetrationTarget};
use rapier_fvm::glamx::{Quat, Vec3};
use rapier_fvm::prelude::*;
use rapier3d::math::Pose;
use rapier3d::parry::query::{Ray, RayCast};
use rapier3d::parry::shape::Cuboid;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};

/// A 10 cm cube (4 x 4 x 4 cells, E = 1e6 Pa, ν = 0.3, 1000 kg/m³, lightly damped) with its
/// bottom at `bottom` (m).
fn cube(bottom: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
        .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
        .translation(DVec3::new(0.0, bottom + 0.05, 0.0))
        .build()
        .unwrap()
}

/// Steps `world` `frames` frames under `audit`, returning each frame's findings.
fn audited(world: &mut FvmWorld, audit: &mut Audit, frames: usize) -> Vec<FrameAudit> {
    (0..frames)
        .map(|_| {
            let results = world.step();
            audit.check_world(world, &results)
        })
        .collect()
}

/// The integrators every clean case runs under.
const INTEGRATORS: [Option<IntegratorKind>; 3] = [
    None,
    Some(IntegratorKind::Explicit),
    Some(IntegratorKind::Implicit),
];

#[test]
fn a_cube_resting_on_the_ground_raises_nothing_under_every_integrator() {
    for integrator in INTEGRATORS {
        let mut world = common::world_with_ground(integrator);
        let handle = world.soft_bodies.insert(cube(0.0));
        let mut audit = Audit::default();
        audit.restart_world(&world);
        let frames = audited(&mut world, &mut audit, 60);
        for (frame, found) in frames.iter().enumerate() {
            let body = found.body(handle).unwrap();
            assert!(
                found.is_clean(),
                "{integrator:?}, frame {frame}: {found:#?}"
            );
            assert!(body.energy.is_some() && found.system.is_some());
        }
    }
}

#[test]
fn a_free_fall_loses_exactly_the_energy_symplectic_euler_loses_and_raises_nothing() {
    // Symplectic Euler (and backward Euler, the same update for a uniform acceleration) changes
    // `K - M g·x` by exactly `-M |g|² h² / 2` per step of `h` in free fall; the body stays
    // undeformed, so the elastic energy stays zero.
    for integrator in [
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let mut world = FvmWorld::default();
        world.coupling.integrator.force = integrator;
        let handle = world.soft_bodies.insert(cube(10.0));
        let mass = world.soft_bodies[handle].total_mass();
        let mut audit = Audit::default();
        audit.restart_world(&world);
        for _ in 0..30 {
            let results = world.step();
            let report = *results[0].1.as_ref().unwrap();
            // A free body needs no coupling: it steps once per frame, in the substeps its
            // report tells.
            let (steps, h) = (report.explicit.map(|e| (e.substeps, e.substep_dt)))
                .or(report.implicit.map(|i| (i.substeps, i.substep_dt)))
                .expect("a stepped body reports its substeps");
            let frame = f64::from(world.physics.integration_parameters.dt);
            assert!((f64::from(steps) * h - frame).abs() < 1e-12 * frame);
            let steps = f64::from(steps);
            let expected = -steps * 0.5 * mass * 9.81f64.powi(2) * h * h;
            let found = audit.check_world(&world, &results);
            assert!(found.is_clean(), "{integrator:?}: {found:#?}");
            let gain = found.body(handle).unwrap().energy.unwrap().gain;
            // f32 gravity (9.81 is not exact in f32) and the sums' rounding near 1e3 J of
            // potential energy: 1e-6 relative and 1e-9 J.
            assert!(
                (gain - expected).abs() < 1e-6 * expected.abs() + 1e-9,
                "{integrator:?}: gain {gain:e} J, expected {expected:e} J"
            );
        }
    }
}

#[test]
fn a_node_set_deep_inside_the_ground_is_a_penetration() {
    let mut world = common::world_with_ground(None);
    let handle = world.soft_bodies.insert(cube(0.0));
    let mut audit = Audit::default();
    let results = world.step();
    assert!(audit.check_world(&world, &results).is_clean());
    let body = &mut world.soft_bodies[handle];
    let corner = body.mesh().nearest_node(DVec3::new(0.05, 0.0, 0.05)) as usize;
    let mut at = body.positions()[corner];
    at.y = -0.02;
    body.set_node_position(corner, at).unwrap();
    let found = audit.check_world(&world, &Vec::new());
    let body = found.body(handle).unwrap();
    assert_eq!(body.penetrations.points, 1);
    assert!((body.penetrations.deepest - 0.02).abs() < 1e-6);
    assert!(matches!(
        body.penetrations.deepest_in,
        Some(PenetrationTarget::Collider(_))
    ));
    assert!(body.penetrates() && !body.is_clean() && !found.is_clean());
}

#[test]
fn a_cube_moved_through_a_thin_wall_has_crossed_it() {
    // A 2 mm wall at x = 0; the cube starts left of it and is set 20 cm to the right.
    let mut world = FvmWorld::default();
    world.physics.gravity = Vec3::ZERO;
    world
        .physics
        .insert_collider(ColliderBuilder::cuboid(0.001, 0.5, 0.5), None);
    let handle = world.soft_bodies.insert(cube(-0.05));
    let shift = DVec3::new(-0.1, 0.0, 0.0);
    let start: Vec<DVec3> = world.soft_bodies[handle]
        .positions()
        .iter()
        .map(|x| *x + shift)
        .collect();
    world.soft_bodies[handle].set_positions(&start).unwrap();
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let through: Vec<DVec3> = start.iter().map(|x| *x - 2.0 * shift).collect();
    world.soft_bodies[handle].set_positions(&through).unwrap();
    let found = audit.check_world(&world, &Vec::new());
    let body = found.body(handle).unwrap();
    // Every boundary node passed through the wall: 4 x 4 x 4 cells have 98 boundary nodes.
    assert_eq!(body.penetrations.crossed, 98);
    assert!(body.crossed() && !body.penetrates());
}

/// The audit of a still 10 cm cube (centred at the origin, no gravity) after a collider without
/// a body, `shape` at `then`, is set by hand at `now`, as one frame.
fn audit_after_setting_collider(shape: ColliderBuilder, then: Pose, now: Pose) -> BodyAudit {
    let mut world = FvmWorld::default();
    world.physics.gravity = Vec3::ZERO;
    let collider = world.physics.insert_collider(shape.position(then), None);
    let handle = world.soft_bodies.insert(cube(-0.05));
    let mut audit = Audit::default();
    audit.restart_world(&world);
    world.physics.colliders[collider].set_position(now);
    let found = audit.check_world(&world, &Vec::new());
    found.body(handle).unwrap().clone()
}

#[test]
fn a_still_cube_beside_a_box_turning_fast_has_not_crossed_it() {
    // A 3 cm box centred 28 mm beyond the middle of the cube's +x face, turned 2.2 rad about
    // its own vertical axis (z) over the frame, from 27° (0.471 rad). In the box's frame the
    // face's middle node moves on a circle of 28 mm about that axis, outside the box (whose
    // corners are 21.2 mm from it); the nodes off the middle are farther, or beyond the box's
    // half height of 15 mm. The straight chord of that arc runs along the box's x axis,
    // 28 cos(1.1) = 12.7 mm from it, through the box from its -x face to its +x face: checked
    // below, so that the audit would have found a crossing had it followed the chord.
    let centre = Vec3::new(0.078, 0.0, 0.0);
    let (from, turn) = (0.471, 2.2);
    let then = Pose::from_parts(centre, Quat::from_rotation_z(from));
    let now = Pose::from_parts(centre, Quat::from_rotation_z(from + turn));
    let node = Vec3::new(0.05, 0.0, 0.0);
    let (start, end) = (
        then.inverse_transform_point(node),
        now.inverse_transform_point(node),
    );
    let shape = Cuboid::new(Vec3::splat(0.015));
    let hit =
        |a: Vec3, b: Vec3| shape.cast_local_ray_and_get_normal(&Ray::new(a, b - a), 1.0, false);
    let (entry, exit) = (hit(start, end).unwrap(), hit(end, start).unwrap());
    assert!(entry.time_of_impact + exit.time_of_impact < 1.0);
    assert!(entry.normal.dot(exit.normal) < 0.0);
    let body =
        audit_after_setting_collider(ColliderBuilder::cuboid(0.015, 0.015, 0.015), then, now);
    assert!(!body.crossed() && !body.penetrates(), "{body:#?}");
}

#[test]
fn a_cube_a_thin_wall_turns_through_has_crossed_it() {
    // A 2 mm wall (1 m square) across x = 0.1 m, turned 0.4 rad about a vertical axis at
    // x = 0.1 m, z = -0.45 m over the frame: its part beside the cube (z from -5 to 5 cm) swings
    // from x = 0.1 m to x = -0.07 m to -0.11 m, past the whole cube (x from -5 to 5 cm), whose
    // 98 boundary nodes (4 x 4 x 4 cells) all went through it, in one face and out of the other.
    let pivot = Vec3::new(0.1, 0.0, -0.45);
    let turned = Quat::from_rotation_y(-0.4);
    let then = Pose::from_parts(Vec3::new(0.1, 0.0, 0.0), Quat::IDENTITY);
    let now = Pose::from_parts(pivot + turned * (then.translation - pivot), turned);
    let body = audit_after_setting_collider(ColliderBuilder::cuboid(0.001, 0.5, 0.5), then, now);
    assert_eq!(body.penetrations.crossed, 98, "{body:#?}");
    assert!(body.crossed() && !body.penetrates());
}

/// A soft sheet 4 mm thick and 40 cm square across x = 0 (its faces at x = ±2 mm), in a world
/// without gravity, and a 10 cm cube whose right face touches the sheet's left face.
fn cube_beside_a_soft_sheet() -> (FvmWorld, DeformableBodyHandle, DeformableBodyHandle) {
    let mut world = FvmWorld::default();
    world.physics.gravity = Vec3::ZERO;
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::new(0.002, 0.2, 0.2), [1, 8, 8]).unwrap();
    let sheet = DeformableBodyBuilder::new(mesh, material).build().unwrap();
    let sheet = world.soft_bodies.insert(sheet);
    let cube = world.soft_bodies.insert(cube(-0.05));
    let beside: Vec<DVec3> = (world.soft_bodies[cube].positions().iter())
        .map(|x| DVec3::new(x.x - 0.052, x.y, x.z))
        .collect();
    world.soft_bodies[cube].set_positions(&beside).unwrap();
    (world, sheet, cube)
}

/// Moves every node of `body` in `world` by `shift` (m).
fn shift_body(world: &mut FvmWorld, body: DeformableBodyHandle, shift: DVec3) {
    let moved: Vec<DVec3> = (world.soft_bodies[body].positions().iter())
        .map(|x| *x + shift)
        .collect();
    world.soft_bodies[body].set_positions(&moved).unwrap();
}

/// The audit of the cube beside the sheet after the cube and the sheet are moved by hand by
/// `cube_shift` and `sheet_shift` (m), as one frame; with the handles of the sheet and cube.
fn audit_after_moving(
    cube_shift: DVec3,
    sheet_shift: DVec3,
) -> (FrameAudit, DeformableBodyHandle, DeformableBodyHandle) {
    let (mut world, sheet, cube) = cube_beside_a_soft_sheet();
    let mut audit = Audit::default();
    audit.restart_world(&world);
    shift_body(&mut world, cube, cube_shift);
    shift_body(&mut world, sheet, sheet_shift);
    (audit.check_world(&world, &Vec::new()), sheet, cube)
}

#[test]
fn a_cube_moved_through_a_thin_soft_sheet_has_crossed_it_and_one_slid_along_it_has_not() {
    // Set 20 cm to the right, through the sheet: every boundary node of the cube (98) went
    // through it, in one face and out of the opposite one.
    let (found, sheet, cube) = audit_after_moving(DVec3::new(0.2, 0.0, 0.0), DVec3::ZERO);
    let body = found.body(cube).unwrap();
    assert_eq!(body.penetrations.crossed, 98, "{body:#?}");
    assert_eq!(
        body.penetrations.first_crossed,
        Some(PenetrationTarget::SoftBody(sheet))
    );
    assert!(body.crossed() && !body.penetrates());
    // Slid 5 cm along the sheet's face instead: its face nodes stay on the sheet's surface, the
    // others beside it; none went through.
    let (found, _, cube) = audit_after_moving(DVec3::new(0.0, 0.05, 0.0), DVec3::ZERO);
    let body = found.body(cube).unwrap();
    assert!(!body.crossed() && !body.penetrates(), "{body:#?}");
    // The sheet carried along with the cube, both 20 cm to the right: nothing crossed.
    let both = DVec3::new(0.2, 0.0, 0.0);
    let (found, _, _) = audit_after_moving(both, both);
    assert!(found.bodies.iter().all(|(_, b)| !b.crossed()), "{found:#?}");
}

#[test]
fn a_cube_set_inside_another_soft_cube_is_a_penetration() {
    let mut world = FvmWorld::default();
    let lower = world.soft_bodies.insert(cube(0.0));
    // The upper cube's bottom 2 cm inside the lower one.
    let upper = world.soft_bodies.insert(cube(0.08));
    let found = Audit::default().check_world(&world, &Vec::new());
    let body = found.body(upper).unwrap();
    assert!(body.penetrates());
    assert_eq!(
        body.penetrations.deepest_in,
        Some(PenetrationTarget::SoftBody(lower))
    );
    // The deepest node lies 2 cm inside: its nearest boundary is the lower cube's top.
    assert!((body.penetrations.deepest - 0.02).abs() < 1e-9);
}

#[test]
fn a_ball_set_inside_a_soft_cube_is_a_penetration_and_a_glued_one_is_not() {
    // A free rigid ball of radius 1 cm centred 2 cm below the cube's top face, between its
    // nodes (none of which it touches): the rigid body went in between the contact points. Glued
    // to one of the cube's nodes instead (a bone inside flesh), the same ball is where it belongs.
    for glued in [false, true] {
        let mut world = FvmWorld::default();
        world.physics.gravity = Vec3::ZERO;
        let handle = world.soft_bodies.insert(cube(0.0));
        let (ball, collider) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.0125, 0.08, 0.0125)),
            ColliderBuilder::ball(0.01),
        );
        if glued {
            let node = world.soft_bodies[handle]
                .mesh()
                .nearest_node(DVec3::new(0.0, 0.075, 0.0));
            world.attach(handle, [node], ball).unwrap();
        }
        let found = Audit::default().check_world(&world, &Vec::new());
        let body = found.body(handle).unwrap();
        if glued {
            assert!(!body.penetrates(), "glued: {:?}", body.penetrations);
        } else {
            assert!(body.penetrates());
            assert_eq!(
                body.penetrations.deepest_in,
                Some(PenetrationTarget::Collider(collider))
            );
            // The centre lies 2 cm below the top face, its nearest boundary.
            assert!((body.penetrations.deepest - 0.02).abs() < 1e-6);
        }
    }
}

#[test]
fn mirrored_and_flattened_cubes_have_inverted_and_collapsed_elements() {
    let mut world = FvmWorld::default();
    let handle = world.soft_bodies.insert(cube(0.0));
    let tets = world.soft_bodies[handle].mesh().tet_count();
    let rest: Vec<DVec3> = world.soft_bodies[handle].positions().to_vec();
    let mut audit = Audit::default();
    let mirrored: Vec<DVec3> = rest.iter().map(|x| DVec3::new(-x.x, x.y, x.z)).collect();
    world.soft_bodies[handle].set_positions(&mirrored).unwrap();
    let found = audit.check_world(&world, &Vec::new());
    let body = found.body(handle).unwrap();
    assert_eq!((body.inverted_elements, body.collapsed_elements), (tets, 0));
    assert!((body.smallest_volume_ratio + 1.0).abs() < 1e-9);
    let flat: Vec<DVec3> = rest
        .iter()
        .map(|x| DVec3::new(x.x, 0.005 * x.y, x.z))
        .collect();
    world.soft_bodies[handle].set_positions(&flat).unwrap();
    let found = audit.check_world(&world, &Vec::new());
    let body = found.body(handle).unwrap();
    assert_eq!((body.inverted_elements, body.collapsed_elements), (0, tets));
    assert!((body.smallest_volume_ratio - 0.005).abs() < 1e-9);
    assert!(body.has_bad_elements());
}

#[test]
fn velocities_set_between_frames_are_energy_gained_until_the_audit_restarts() {
    let mut world = common::world_with_ground(None);
    let soft = world.soft_bodies.insert(cube(0.0));
    let (free_ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(1.0, 0.5, 0.0)),
        ColliderBuilder::ball(0.05),
    );
    // Resting on the cube's top face (0.1 m).
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.1 + 0.02 + 5e-4, 0.0)),
        ColliderBuilder::ball(0.02),
    );
    let mut audit = Audit::default();
    audit.restart_world(&world);
    assert!(
        audited(&mut world, &mut audit, 5)
            .iter()
            .all(FrameAudit::is_clean)
    );
    // The cube kicked at 1 m/s sideways: K = M/2 = 0.5 J, far above 0.1 % of it (no explicit
    // allowance: the check after a hand-made change has no step's report).
    let kick = vec![DVec3::new(1.0, 0.0, 0.0); world.soft_bodies[soft].node_count()];
    world.soft_bodies[soft].set_velocities(&kick).unwrap();
    let found = audit.check_world(&world, &Vec::new());
    let energy = found.body(soft).unwrap().energy.unwrap();
    assert!(
        energy.gained() && (energy.gain - 0.5).abs() < 0.01,
        "{energy:?}"
    );
    assert!(found.system.unwrap().gained());
    // After a restart the same state is the reference.
    audit.restart_world(&world);
    assert!(
        !audit
            .check_world(&world, &Vec::new())
            .system
            .unwrap()
            .gained()
    );
    // A rigid ball far from the cube thrown up by hand: rapier's alone, not the coupled
    // system's.
    world.physics.bodies[free_ball].set_linvel(Vec3::new(0.0, 30.0, 0.0), true);
    let found = audit.check_world(&world, &Vec::new());
    assert!(!found.system.unwrap().gained(), "{found:#?}");
    // The ball resting on the cube stopped, then thrown up at 30 m/s by hand between frames:
    // the coupled system gains its kinetic energy.
    world.physics.bodies[ball].set_linvel(Vec3::ZERO, true);
    audit.restart_world(&world);
    world.physics.bodies[ball].set_linvel(Vec3::new(0.0, 30.0, 0.0), true);
    let found = audit.check_world(&world, &Vec::new());
    let system = found.system.unwrap();
    let ball_mass = f64::from(world.physics.bodies[ball].mass());
    assert!(system.gained());
    // ½ m v², less the gravitational energy of the half-step look-back (m g v h/2).
    let h = f64::from(world.physics.integration_parameters.dt) / 4.0;
    let expected = 0.5 * ball_mass * 900.0 - ball_mass * 9.81 * 30.0 * h / 2.0;
    assert!(
        (system.gain - expected).abs() < 1e-6 * expected,
        "{system:?} vs {expected}"
    );
}

#[test]
fn a_box_falling_beside_a_soft_pillar_gains_nothing_at_any_coupling_substeps() {
    // A 0.43 kg box (6 cm, 2000 kg/m³) released at rest 0.5 mm beside the side of a 1 m pillar
    // (E = 1e8 Pa, settled within its first frame) standing on the ground, falling freely along
    // it for 12 frames of 1/60 s (0.2 m) without touching it: it is within the pillar's contact
    // reach, so the coupled system counts it. Its energy measured half of rapier's integration
    // step back is exactly constant in free flight (symplectic Euler), and rapier integrates
    // positions once per solver iteration: taking the coupling substep instead (1/60 s with one
    // substep and rapier's four iterations) measured a gain of 2.8 mJ in the first frame
    // (tolerance 0.77 mJ), and of 4.3 mJ every frame for the same box on its own.
    for substeps in [1, 2, 4] {
        let mut world = common::world_with_ground(Some(IntegratorKind::Explicit));
        world.coupling.substeps = substeps;
        let material = Material::new(MaterialModel::StableNeoHookean, 1e8, 0.3, 1000.0).unwrap();
        let mesh = mesh::cuboid(DVec3::new(0.05, 0.5, 0.05), [2, 10, 2]).unwrap();
        let pillar = DeformableBodyBuilder::new(mesh, material)
            .damping(RayleighDamping::stiffness_proportional(2e-3, material.lame()).unwrap())
            .translation(DVec3::new(0.0, 0.5, 0.0))
            .build()
            .unwrap();
        let pillar = world.soft_bodies.insert(pillar);
        let (_, box_collider) = world.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vec3::new(0.05 + 0.03 + 5e-4, 0.9, 0.0)),
            ColliderBuilder::cuboid(0.03, 0.03, 0.03).density(2000.0),
        );
        let mut audit = Audit::default();
        audit.restart_world(&world);
        let mut coupled_frames = 0;
        for frame in 0..12 {
            let found = audited(&mut world, &mut audit, 1).remove(0);
            assert!(
                found.is_clean(),
                "{substeps} substeps, frame {frame}: {found:#?}"
            );
            let contacts = world.coupling.constraints(pillar).unwrap().contacts();
            let target = ContactTarget::Collider(box_collider);
            coupled_frames += usize::from(contacts.iter().any(|c| c.target == target));
        }
        // The box was within the pillar's contact reach, so in the coupled system, in some.
        assert!(coupled_frames > 0, "{substeps} substeps");
    }
}

#[test]
fn a_newton_solve_that_cannot_converge_is_refused_and_the_audit_sees_it() {
    // A cube released stretched by half along x: one Newton iteration per substep cannot meet
    // 1e-12 however the frame is refined, so the frame is refused (the state kept); twenty
    // iterations meet 1e-6 in the frame's one substep.
    for (iterations, tolerance, fails) in [(1, 1e-12, true), (20, 1e-6, false)] {
        let mut world = FvmWorld::default();
        world.coupling.integrator.force = Some(IntegratorKind::Implicit);
        world.coupling.integrator.implicit.max_newton_iterations = iterations;
        world.coupling.integrator.implicit.tolerance = tolerance;
        let handle = world.soft_bodies.insert(cube(0.0));
        let stretched: Vec<DVec3> = world.soft_bodies[handle]
            .positions()
            .iter()
            .map(|x| DVec3::new(1.5 * x.x, x.y, x.z))
            .collect();
        world.soft_bodies[handle].set_positions(&stretched).unwrap();
        let mut audit = Audit::default();
        audit.restart_world(&world);
        let results = world.step();
        let found = audit.check_world(&world, &results);
        let body = found.body(handle).unwrap();
        match &results[0].1 {
            Ok(report) => {
                assert!(!fails, "{report:?}");
                let implicit = report.implicit.unwrap();
                assert!(implicit.converged, "{implicit:?}");
                assert_eq!(implicit.substeps, 1);
                assert!(body.is_clean(), "{body:?}");
            }
            Err(error) => {
                assert!(fails, "{error}");
                assert!(
                    matches!(error, Error::NewtonDidNotConverge { substeps: 64, .. }),
                    "{error}"
                );
                assert_eq!(world.soft_bodies[handle].positions(), &stretched[..]);
                assert_eq!(body.step_error.as_ref(), Some(error));
                assert!(!body.is_clean());
            }
        }
    }
}

#[test]
fn custom_tolerances_are_the_ones_applied() {
    // With a collapse ratio above 1, every element of a body at rest is collapsed: the setting
    // is read, not a constant.
    let mut world = FvmWorld::default();
    let handle = world.soft_bodies.insert(cube(0.0));
    let tets = world.soft_bodies[handle].mesh().tet_count();
    let mut audit = Audit::new(AuditSettings {
        collapse_ratio: 1.5,
        ..AuditSettings::default()
    });
    let found = audit.check_world(&world, &Vec::new());
    assert_eq!(found.body(handle).unwrap().collapsed_elements, tets);
}

#[test]
fn the_energy_of_a_body_glued_to_a_fixed_body_counts_its_implicit_springs() {
    // A 20 x 5 x 5 cm bar (E = 1e6 Pa) whose nodes along one top edge are glued to a fixed rigid
    // body, released horizontal, forced implicit (backward Euler, then BDF2) in one coupling
    // substep a frame. The implicit step pulls each glued node to its anchor with a spring
    // `k = penalty_factor m/h²` (`h` the frame's effective step, however many substeps the
    // swing cuts it into) that holds `k |x − a|²/2` at the step's end (the anchors of a fixed
    // body stay where the nodes were glued): the audit's energy of the body is its kinetic,
    // elastic and gravitational energy plus those springs', to round-off (1e-12 of the total);
    // the springs' share is checked to be well above round-off, so that leaving it out fails
    // (it was left out; and BDF2's first step, a backward Euler one, was counted with BDF2's
    // stiffness).
    for scheme in [ImplicitScheme::BackwardEuler, ImplicitScheme::Bdf2] {
        glued_springs_counted(scheme);
    }
}

/// The check of [`the_energy_of_a_body_glued_to_a_fixed_body_counts_its_implicit_springs`]
/// under `scheme`.
fn glued_springs_counted(scheme: ImplicitScheme) {
    let (builder, hinge) = common::bar_with_hinge(DVec3::new(0.0, 0.5, 0.0));
    let mut world = FvmWorld::default();
    world.coupling.substeps = 1;
    world.coupling.integrator.force = Some(IntegratorKind::Implicit);
    world.coupling.integrator.implicit.scheme = scheme;
    let gravity = world.physics.gravity.as_dvec3();
    let handle = world.soft_bodies.insert(builder.build().unwrap());
    let bar = common::glue_to_fixed_axle(&mut world, handle, &hinge, Vec3::new(-0.1, 0.525, 0.0));
    // The anchors where the world keeps them: through the fixed body's pose, in f32 as rapier's.
    let pose = *world.physics.bodies[bar].position();
    let anchors: Vec<DVec3> = (hinge.iter())
        .map(|&n| world.soft_bodies[handle].positions()[n as usize].as_vec3())
        .map(|x| (pose.transform_point(pose.inverse_transform_point(x))).as_dvec3())
        .collect();
    let mut audit = Audit::default();
    audit.restart_world(&world);
    for frame in 0..20 {
        let results = world.step();
        let found = audit.check_world(&world, &results);
        let report = results[0].1.as_ref().unwrap().implicit.unwrap();
        let body = &world.soft_bodies[handle];
        let factor = world.coupling.contact.penalty_factor;
        // The springs take the whole step's effective `m/h²`, whatever its substeps: two thirds
        // of the step for BDF2 once it has a step before it (its first is backward Euler's).
        let whole = report.substep_dt * f64::from(report.substeps);
        let h = if scheme == ImplicitScheme::Bdf2 && frame > 0 {
            2.0 * whole / 3.0
        } else {
            whole
        };
        let springs: f64 = (hinge.iter().zip(&anchors))
            .map(|(&n, a)| {
                let n = n as usize;
                0.5 * factor * body.masses()[n] / (h * h)
                    * (body.positions()[n] - *a).length_squared()
            })
            .sum();
        let moving = body.kinetic_energy() + body.elastic_energy();
        let expected = moving + body.gravity_potential_energy(gravity) + springs;
        let counted = found.body(handle).unwrap().energy.unwrap().energy;
        println!(
            "{scheme:?} frame {frame}: springs {springs:.6e} J, audit beyond the rest {:.6e} J",
            counted - (expected - springs)
        );
        assert!((counted - expected).abs() < 1e-12 * expected.abs().max(moving));
        assert!(springs > 1e-6 * expected.abs());
    }
}

#[test]
fn a_glued_body_keeps_its_place_and_energy_when_the_implicit_substeps_change() {
    // A 10 cm cube hanging from a fixed rigid body by the 25 nodes of its top face, forced
    // implicit in one coupling substep a frame, settled for 2 s; then the implicit integrator
    // is told to cut frames into 3 substeps or 1, switching back and forth over ten frames. The
    // glue's springs hold the cube's weight with a stiffness taken from the whole frame's step
    // (`penalty_factor m/h²`, `h` the frame), whatever its substeps: the equilibrium does not
    // change, so the cube must stay where it hung (every node within 1 µm: Newton's tolerance
    // alone may move it) and the audit must find no energy gained (0.1 % of the energy in
    // motion plus 1e-9 J) in any frame of the switches. With the springs' stiffness following
    // the substeps (`h` the substep), each switch stretched or relaxed them: measured, the cube
    // moved by 23 µm and the audit flagged energy gained in three of the ten frames.
    let mut world = FvmWorld::default();
    world.coupling.substeps = 1;
    world.coupling.integrator.force = Some(IntegratorKind::Implicit);
    world.coupling.sleep = SleepSettings::never();
    let handle = world.soft_bodies.insert(cube(0.4));
    let top: Vec<u32> = (world.soft_bodies[handle].positions().iter().enumerate())
        .filter(|(_, x)| x.y > 0.4999)
        .map(|(n, _)| n as u32)
        .collect();
    assert_eq!(top.len(), 25);
    common::glue_to_fixed_axle(&mut world, handle, &top, Vec3::new(0.0, 0.5, 0.0));
    for _ in 0..120 {
        world.step();
    }
    let hung = world.soft_bodies[handle].positions().to_vec();
    // The audit's first frame has the springs' energy of the frame before it to go by.
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let results = world.step();
    audit.check_world(&world, &results);
    let mut flagged = Vec::new();
    let mut farthest: f64 = 0.0;
    for (frame, substeps) in [3, 3, 3, 1, 1, 1, 3, 1, 3, 1].into_iter().enumerate() {
        world.coupling.integrator.implicit.substeps = substeps;
        let results = world.step();
        if !audit.check_world(&world, &results).is_clean() {
            flagged.push(frame);
        }
        let moved = (world.soft_bodies[handle].positions().iter().zip(&hung))
            .map(|(x, x0)| (*x - *x0).length())
            .fold(0.0, f64::max);
        farthest = farthest.max(moved);
    }
    println!("farthest node moved {farthest:.3e} m; frames flagged {flagged:?}");
    assert!(farthest < 1e-6, "{farthest} m");
    assert!(flagged.is_empty(), "{flagged:?}");
}

#[test]
fn a_box_falling_onto_a_ball_beside_a_soft_cube_hands_the_ball_energy_the_audit_counts() {
    // A 2 cm ball (1000 kg/m³, 34 g) rests on the ground 0.5 mm beside a side face of the 10 cm
    // cube, within its contact reach; a 2 cm steel box (8000 kg/m³, 64 g), 16.5 mm clear of the
    // cube, falls 9 cm onto the ball's far side and drives it against the cube. The box reaches
    // the ball through rapier's own contacts alone, so the energy the ball takes from it is no
    // gain of the coupling, and the audit counts the box with the ball (it flagged the frame of
    // the blow, a 2.7e-4 J gain, before it did). Every frame must be clean under the automatic
    // choice, and the ball's kinetic energy must rise in some frame by more than the cube's
    // energy tolerance: with the box left out, that frame reads as a gain.
    let mut world = common::world_with_ground(None);
    let cube = world.soft_bodies.insert(cube(0.0));
    let radius = 0.02;
    let ball_x = 0.05 + radius + 5e-4;
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(ball_x as f32, radius as f32, 0.0)),
        ColliderBuilder::ball(radius as f32)
            .density(1000.0)
            .friction(0.8),
    );
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(ball_x as f32 + 0.006, 0.14, 0.0)),
        ColliderBuilder::cuboid(0.01, 0.01, 0.01)
            .density(8000.0)
            .friction(0.8),
    );
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let kinetic = |world: &FvmWorld| world.physics.bodies[ball].kinetic_energy();
    let mut handed_over = false;
    for frame in 0..45 {
        let before = kinetic(&world);
        let found = audited(&mut world, &mut audit, 1).remove(0);
        assert!(found.is_clean(), "frame {frame}: {found:#?}");
        let energy = found.body(cube).unwrap().energy.unwrap();
        handed_over |= f64::from(kinetic(&world) - before) > energy.tolerance;
    }
    assert!(handed_over);
}

#[test]
fn a_check_with_no_step_since_the_last_finds_the_same_energy() {
    // A ball of 1 cm radius (1000 kg/m³, 4.2 g) falls 2 mm above the top of the implicitly
    // stepped cube, within its contact reach: the implicit steps carry it, and the audit takes
    // the change their velocity changes made to its half-step-back measure, `½ h m g·Δv`, out
    // of the frame's gain. Checked again with no step in between (and the same results, so that
    // the implicit penalties' energy counts as before), the same state must show no gain at all
    // (within 1e-12 J, the sums' round-off): the carried change belongs to the frame it was
    // made in (taken out a second time, it read as a 7.0e-6 J loss).
    let mut world = common::world_with_ground(Some(IntegratorKind::Implicit));
    let cube = world.soft_bodies.insert(cube(0.0));
    let radius = 0.01_f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.1 + radius + 2e-3, 0.0)),
        ColliderBuilder::ball(radius).density(1000.0),
    );
    let mut audit = Audit::default();
    audit.restart_world(&world);
    let results = world.step();
    let stepped = audit.check_world(&world, &results);
    assert!(stepped.is_clean(), "{stepped:#?}");
    let again = audit.check_world(&world, &results);
    let energy = again.body(cube).unwrap().energy.unwrap();
    assert!(energy.gain.abs() < 1e-12, "{energy:?}");
}

//! Steps the integrators cannot resolve are refused with a typed error and the state before them
//! kept, never taken: an impact that flattens elements (the material's answer to the load, which
//! no substep undoes), and a Newton solve that does not converge in the most substeps refinement
//! allows. A frame Newton cannot solve in one substep is redone in more, exactly as if that many
//! had been asked for; a solve on its round-off floor (a stiff, nearly incompressible beam) is
//! accepted as stalled, not refused.

mod common;

use common::{cantilever, gravity, world_with_ground};
use rapier_fvm::coupling::Audit;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::integrate::COLLAPSE_RATIO;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};

/// Speed (m/s) of a cube dropped from 0.5 m.
fn drop_speed() -> f64 {
    (2.0 * 9.81 * 0.5f64).sqrt()
}

/// A 10 cm cube (4 cells a side, stable Neo-Hookean, ν = 0.3, 1000 kg/m³) of Young's modulus
/// `young` (Pa), released 1 mm above the ground at the speed of a 0.5 m drop.
fn dropped_cube(young: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap();
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
        .translation(DVec3::new(0.0, 0.051, 0.0))
        .linvel(DVec3::new(0.0, -drop_speed(), 0.0))
        .build()
        .unwrap()
}

/// The elastic energy density (J/m³) of the stable Neo-Hookean material (`ν ≥ 0`) squeezed to
/// zero thickness with its sides held, `F = diag(1, 0, 1)`: `Ψ = μ/2 (I_C − 3) − μ (J − 1) +
/// (λ + μ)/2 (J − 1)²` at `I_C = 2`, `J = 0`, that is `μ + λ/2`. Letting the sides spread lowers
/// it, so no element can take in more than this before it is flat.
fn flattening_energy_density(young: f64) -> f64 {
    let lame = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0)
        .unwrap()
        .lame();
    lame.mu + lame.lambda / 2.0
}

/// Runs a cube of `young` (Pa) dropped on the ground for 0.25 s in frames of 1/240 s under
/// `force` (or the automatic choice); returns the first refusal, after checking that the refused
/// step was not taken (the body is left as it was before the refused coupling substep: no element
/// crushed, as the audit sees it) and that the next frame is refused too.
fn drop_until_refused(young: f64, force: Option<IntegratorKind>) -> Option<Error> {
    let mut world = world_with_ground(force);
    world.physics.integration_parameters.dt = 1.0 / 240.0;
    let cube = world.soft_bodies.insert(dropped_cube(young));
    let mut audit = Audit::default();
    audit.restart_world(&world);
    for _ in 0..60 {
        let results = world.step();
        let found = audit.check_world(&world, &results);
        let body = found.body(cube).unwrap();
        if let Err(error) = &results[0].1 {
            assert_eq!(body.inverted_elements, 0, "{force:?}: {error}");
            assert_eq!(body.collapsed_elements, 0, "{force:?}: {error}");
            assert!(body.smallest_volume_ratio >= COLLAPSE_RATIO);
            let again = world.step();
            assert!(
                again[0].1.is_err(),
                "{force:?}: the same frame passed again"
            );
            return Some(error.clone());
        }
        assert!(body.is_clean(), "{force:?}: {body:?}");
    }
    None
}

#[test]
fn a_cube_its_material_cannot_stop_is_refused_at_the_impact_and_left_as_it_was() {
    // At E = 1 kPa the drop's kinetic energy density, ρv²/2 = 4.9 kJ/m³, is 7.3 times what the
    // material holds flattened (673 J/m³): elements must flatten. Every integrator refuses the
    // frame that crushes one below 1 % of its rest volume.
    let kinetic = 0.5 * 1000.0 * drop_speed().powi(2);
    let capacity = flattening_energy_density(1e3);
    assert!(
        kinetic > 7.0 * capacity,
        "{kinetic} J/m³ vs {capacity} J/m³"
    );
    for force in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let refusal = drop_until_refused(1e3, force);
        println!("{force:?}: {refusal:?}");
        match refusal {
            Some(Error::ElementCrushed { volume_ratio, .. }) => {
                assert!(volume_ratio < COLLAPSE_RATIO, "{force:?}: {volume_ratio}");
            }
            // Refined implicit frames of the crushing impact may end on a Newton solve that
            // cannot converge instead.
            Some(Error::NewtonDidNotConverge { substeps, .. }) => {
                assert_ne!(force, Some(IntegratorKind::Explicit));
                assert_eq!(substeps, 64);
            }
            other => panic!("{force:?}: {other:?}"),
        }
    }
}

#[test]
fn a_cube_its_material_can_stop_is_not_refused() {
    // At E = 100 kPa the material holds 67 kJ/m³ flattened, 14 times the drop's 4.9 kJ/m³.
    let kinetic = 0.5 * 1000.0 * drop_speed().powi(2);
    assert!(flattening_energy_density(1e5) > 13.0 * kinetic);
    for force in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        assert_eq!(drop_until_refused(1e5, force), None, "{force:?}");
    }
}

/// A cube of 1e5 Pa released stretched by half along x without gravity, stepped by `integrator`
/// for `frames` frames of 1/60 s; returns the positions and each frame's report.
fn released_stretched(
    integrator: &ImplicitIntegrator,
    frames: usize,
) -> (Vec<DVec3>, Vec<ImplicitReport>) {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mut body =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [4; 3]).unwrap(), material)
            .build()
            .unwrap();
    let stretched: Vec<DVec3> = body
        .positions()
        .iter()
        .map(|x| DVec3::new(1.5 * x.x, x.y, x.z))
        .collect();
    body.set_positions(&stretched).unwrap();
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let reports = (0..frames)
        .map(|_| {
            integrator
                .step(
                    &mut body,
                    &mut constraints,
                    &mut workspace,
                    1.0 / 60.0,
                    DVec3::ZERO,
                )
                .unwrap()
        })
        .collect();
    (body.positions().to_vec(), reports)
}

#[test]
fn a_frame_newton_cannot_solve_in_one_substep_is_redone_in_more() {
    // Three Newton iterations cannot meet 1e-9 for the release of a cube stretched by half in
    // one substep of 1/60 s; in shorter substeps they can. The frame is redone in twice the
    // substeps until they do, and ends exactly as a frame asked for in that many substeps.
    let limited = ImplicitIntegrator {
        max_newton_iterations: 3,
        tolerance: 1e-9,
        reuse_factorization: false,
        ..ImplicitIntegrator::default()
    };
    let (refined, reports) = released_stretched(&limited, 1);
    let substeps = reports[0].substeps;
    println!("{reports:?}");
    assert!(substeps > 1 && substeps.is_power_of_two(), "{reports:?}");
    assert!(reports[0].converged, "{reports:?}");
    let asked = ImplicitIntegrator {
        substeps,
        ..limited
    };
    let (direct, direct_reports) = released_stretched(&asked, 1);
    assert_eq!(direct_reports[0].substeps, substeps);
    assert_eq!(refined, direct);
    // Later frames are refined as they need, and converge.
    let (_, reports) = released_stretched(&limited, 5);
    assert!(reports.iter().all(|r| r.converged), "{reports:?}");
}

#[test]
fn a_stiff_nearly_incompressible_beam_on_its_round_off_floor_is_accepted_as_stalled() {
    // E = 1e11 Pa, ν = 0.4999: λ = 1.7e14 Pa, so moving the coordinates (up to 1 m) by one unit
    // in the last place changes the nodal forces by about 1e-3 of the beam's weight. Newton
    // stops there, a few times 1e-4 above the 1e-6 tolerance: a stall on the round-off floor,
    // not a failure, and the frame is taken.
    let material = Material::new(MaterialModel::StableNeoHookean, 1e11, 0.4999, 1000.0).unwrap();
    let (mut beam, _) = cantilever([20, 2, 2], material);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let integrator = ImplicitIntegrator::default();
    let mut stalled = 0;
    for _ in 0..10 {
        let report = integrator
            .step(
                &mut beam,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                gravity(),
            )
            .unwrap();
        assert_eq!(report.substeps, 1, "{report:?}");
        assert!(report.relative_residual < 1e-2, "{report:?}");
        stalled += report.stalled_substeps;
    }
    assert!(stalled > 0, "no frame stopped on its round-off floor");
}

/// A foam block (E = 10 kPa, 20 x 10 x 20 cm, 100 kg/m³) on the ground whose explicit steps are
/// all refused (it needs hundreds of substeps a frame; one is allowed).
fn foam_whose_steps_are_refused(world: &mut FvmWorld) -> DeformableBodyHandle {
    world.coupling.integrator.explicit.max_substeps = 1;
    common::insert_foam_block(world, MaterialModel::Corotated)
}

/// Steps `world` for a second at 1/60 s, every frame refused for the deformable body `soft`
/// (which must not move); returns the largest distance (m) the rigid body `rigid` strayed from
/// where it started and the mean force (N) `soft` exerted on it over the last half second.
fn held_by_refused_body(
    world: &mut FvmWorld,
    soft: DeformableBodyHandle,
    rigid: RigidBodyHandle,
) -> (f64, DVec3) {
    let start = world.physics.bodies[rigid].translation().as_dvec3();
    let rest = world.soft_bodies[soft].positions().to_vec();
    let (mut strayed, mut support) = (0.0f64, DVec3::ZERO);
    for frame in 0..60 {
        let results = world.step();
        assert!(
            matches!(results[0].1, Err(Error::TooManySubsteps { .. })),
            "{:?}",
            results[0].1
        );
        assert_eq!(world.soft_bodies[soft].positions(), &rest[..]);
        let at = world.physics.bodies[rigid].translation().as_dvec3();
        strayed = strayed.max((at - start).length());
        if frame >= 30 {
            support += world.load_on(soft, rigid).0 / 30.0;
        }
    }
    (strayed, support)
}

#[test]
fn a_box_on_a_body_whose_steps_are_refused_is_held_where_it_rests() {
    // A 10 kg box resting on the refused foam: the foam stays where it was, so the box must meet
    // it as a fixed obstacle would; without the hold it fell 10 cm through the foam to the
    // ground in the first 0.15 s. Static equilibrium: the foam carries the box's weight, m g =
    // 98.1 N (1 %: rapier's solver and the hold's sweeps settle to well within it), and the box
    // stays within 1 mm of where it was put (the contacts' speculative margin and the
    // depenetration of what rapier's step pushes in).
    let mut world = world_with_ground(Some(IntegratorKind::Explicit));
    let foam = foam_whose_steps_are_refused(&mut world);
    let mass = 10.0;
    let (rigid, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.0, 0.15, 0.0)),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05).density((mass / 1e-3) as f32),
    );
    let (strayed, support) = held_by_refused_body(&mut world, foam, rigid);
    let weight = mass * 9.81;
    println!("box strayed {strayed:.2e} m, foam's support {support:?} N vs {weight} N");
    assert!(strayed < 1e-3);
    assert!((support.y / weight - 1.0).abs() < 0.01);
}

#[test]
fn a_ball_glued_to_a_body_whose_steps_are_refused_is_held_at_its_anchors() {
    // A 1 kg ball glued to the nodes of one side of the refused foam (not along a line, about
    // which it would swing), clear of the ground: the anchors hold it where it was (1 mm: the attachments' drift correction) and the foam carries its weight,
    // 9.81 N (1 %).
    let mut world = world_with_ground(Some(IntegratorKind::Explicit));
    let foam = foam_whose_steps_are_refused(&mut world);
    let side = world.soft_bodies[foam]
        .mesh()
        .nodes_where(|p| p.x >= 0.1 - 1e-9);
    let (radius, mass) = (0.03f32, 1.0);
    let density = mass / (4.0 / 3.0 * std::f64::consts::PI * f64::from(radius).powi(3));
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(0.14, 0.05, 0.0)),
        ColliderBuilder::ball(radius).density(density as f32),
    );
    world.attach(foam, side, ball).unwrap();
    let (strayed, support) = held_by_refused_body(&mut world, foam, ball);
    let weight = mass * 9.81;
    println!("ball strayed {strayed:.2e} m, foam's support {support:?} N vs {weight} N");
    assert!(strayed < 1e-3);
    assert!((support.y / weight - 1.0).abs() < 0.01);
}

/// One 10-node tetrahedron, its corners at the origin and `h` = 0.1 m along each axis (stable
/// Neo-Hookean of `young` Pa, ν = 0.3, 1000 kg/m³), the mid-edge node of edge (2, 3) moving
/// along x at `speed` (m/s).
fn sheared_quadratic_element(young: f64, speed: f64) -> DeformableBody {
    let h = 0.1;
    let corners = [DVec3::ZERO, DVec3::X * h, DVec3::Y * h, DVec3::Z * h];
    let mut positions = corners.to_vec();
    positions
        .extend(rapier_fvm::element::tet10::EDGES.map(|[i, j]| 0.5 * (corners[i] + corners[j])));
    let element = std::array::from_fn(|a| a as u32);
    let mesh = mesh::QuadraticTetMesh::new(positions, vec![element]).unwrap();
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0).unwrap();
    DeformableBodyBuilder::quadratic(mesh, material)
        .nodes_linvel([9], DVec3::new(speed, 0.0, 0.0))
        .build()
        .unwrap()
}

#[test]
fn a_quadratic_element_keeping_its_volume_is_not_crushed_when_its_subdivision_folds() {
    // Moving the mid-edge node of edge (2, 3) of the element by d along x is the displacement
    // u = (4 d y z / h², 0, 0): F = I + e_x ⊗ ∇u_x, det F = 1 at every point, for any d. Past
    // d = h/2 a tetrahedron of the element's straight-sided subdivision (which contact and
    // output use) is inverted all the same. The element is whole: a step that takes it there
    // is not refused (measured on the subdivision, it was, and the frame after it the same).
    let mut body = sheared_quadratic_element(1e5, 0.0);
    let sheared: Vec<DVec3> = (body.positions().iter().enumerate())
        .map(|(node, x)| *x + DVec3::new(if node == 9 { 0.06 } else { 0.0 }, 0.0, 0.0))
        .collect();
    body.set_positions(&sheared).unwrap();
    let ratios = body.element_volume_ratios();
    println!(
        "sheared by 0.06 m: element J {ratios:?}, subdivision inverted {}",
        body.inverted_tet_count()
    );
    assert!((ratios[0] - 1.0).abs() < 1e-12, "{ratios:?}");
    assert!(body.inverted_tet_count() >= 1);
    // The same shear reached in one frame of 1/60 s (3.6 m/s; at 1 Pa the elastic forces move
    // the node by about 1e-4 of that), by every integrator.
    for force in [IntegratorKind::Explicit, IntegratorKind::Implicit] {
        let mut body = sheared_quadratic_element(1.0, 0.06 * 60.0);
        let integrator = AutomaticIntegrator {
            force: Some(force),
            ..AutomaticIntegrator::default()
        };
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        for frame in 0..2 {
            let report = integrator.step(
                &mut body,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                DVec3::ZERO,
            );
            let ratios = body.element_volume_ratios();
            println!(
                "{force:?} frame {frame}: node 9 at x = {:.5} m, element J {ratios:?}, subdivision inverted {}",
                body.positions()[9].x,
                body.inverted_tet_count()
            );
            assert!(report.is_ok(), "{force:?}: {report:?}");
            assert!(ratios[0] > 0.99, "{force:?}: {ratios:?}");
        }
        assert!(
            body.inverted_tet_count() >= 1,
            "{force:?}: not past the fold"
        );
    }
}

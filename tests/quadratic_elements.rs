//! Quadratic (10-node) tetrahedra pass the tests linear ones pass, and are accurate in bending:
//!
//! - patch tests: a homogeneous deformation (any model) and, for linear elasticity, a quadratic
//!   displacement (linear stress) are reproduced exactly: interior forces are zero, respectively
//!   the consistent load `∫ N_a div σ dV`, to round-off;
//! - rigid motion carries no elastic or damping force;
//! - explicit and implicit steps conserve linear momentum;
//! - the cantilever's tip deflection and first frequency against beam theory.

mod common;

use common::{Lcg, MODELS, OBJECTIVE_MODELS};
use rapier_fvm::element::ElementOrder;
use rapier_fvm::element::tet10::EDGES;
use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};

const HALF: f64 = 0.2;

/// A quadratic 3 x 3 x 3-cell box whose interior corner nodes are moved randomly by up to 30 % of
/// a cell; mid-edge nodes stay at their edges' midpoints (straight-sided elements).
fn distorted_quadratic_box() -> mesh::QuadraticTetMesh {
    let regular = mesh::cuboid(DVec3::splat(HALF), [3, 3, 3]).unwrap();
    let cell = 2.0 * HALF / 3.0;
    let mut rng = Lcg(5);
    let positions = regular
        .positions()
        .iter()
        .map(|p| {
            if is_interior(*p) {
                *p + rng.vector() * (0.3 * cell)
            } else {
                *p
            }
        })
        .collect();
    let distorted = TetMesh::new(positions, regular.tets().to_vec()).unwrap();
    mesh::QuadraticTetMesh::from_linear(&distorted).unwrap()
}

fn is_interior(p: DVec3) -> bool {
    p.abs().max_element() < HALF - 1e-9
}

/// The quadratic body of `mesh` with every node placed at `map(p)` moving at `rate(p)`, and its
/// forces.
fn forces_under(
    mesh: &mesh::QuadraticTetMesh,
    model: MaterialModel,
    damping: Option<RayleighDamping>,
    map: impl Fn(DVec3) -> DVec3,
    rate: impl Fn(DVec3) -> DVec3,
) -> Vec<DVec3> {
    let material = Material::new(model, 1e7, 0.3, 1000.0).unwrap();
    let mut builder = DeformableBodyBuilder::quadratic(mesh.clone(), material);
    if let Some(damping) = damping {
        builder = builder.damping(damping);
    }
    common::forces_under(&mut builder.build().unwrap(), map, rate)
}

/// Largest interior force over largest boundary force.
fn interior_ratio(mesh: &mesh::QuadraticTetMesh, forces: &[DVec3]) -> f64 {
    let interior: Vec<bool> = mesh.positions().iter().map(|p| is_interior(*p)).collect();
    common::interior_ratio(forces, &interior)
}

/// Tolerance 1e-9 of the largest boundary force: the exact answer is zero (the four-point rule
/// integrates the constant-stress integrand exactly on straight elements) and round-off is
/// ~1e-14.
#[test]
fn every_model_passes_the_patch_test_under_a_finite_homogeneous_deformation() {
    let mesh = distorted_quadratic_box();
    let f = common::finite_homogeneous_deformation();
    let f_dot = common::homogeneous_deformation_rate();
    let damping = RayleighDamping::new(2e4, 1e4).unwrap();
    for model in MODELS {
        let elastic = forces_under(&mesh, model, None, |p| f * p + DVec3::X, |_| DVec3::ZERO);
        let ratio = interior_ratio(&mesh, &elastic);
        println!("{model:?} quadratic patch test: interior/boundary force = {ratio:.2e}");
        assert!(ratio < 1e-9, "{model:?}: {ratio:e}");
        let damped = forces_under(&mesh, model, Some(damping), |p| f * p, |p| f_dot * p);
        let ratio = interior_ratio(&mesh, &damped);
        assert!(ratio < 1e-9, "{model:?} damped: {ratio:e}");
    }
}

/// The higher-order patch test, which linear tetrahedra cannot pass: under the quadratic
/// displacement `u = (a y², b x z, c x²)`, which changes no volume (`ε_xx = ε_yy = ε_zz = 0`),
/// linear elasticity has the linear stress `σ = 2μ ε` and the constant divergence
/// `div σ = μ Δu = μ (2a, 0, 2c)`. The Galerkin force on an interior node is then exactly the
/// consistent load `div σ ∫ N_a dV`, with `∫ N = -V/20` at a corner and `V/5` at a mid-edge node
/// (the four-point rule integrates the quadratic integrand exactly). Tolerance 1e-9 of the
/// largest boundary force (round-off).
#[test]
fn quadratic_displacement_gives_the_consistent_load_on_interior_nodes() {
    let mesh = distorted_quadratic_box();
    let (a, b, c) = (2e-3, -1e-3, 1.5e-3);
    let u = |p: DVec3| DVec3::new(a * p.y * p.y, b * p.x * p.z, c * p.x * p.x);
    let material = Material::new(MaterialModel::Linear, 1e7, 0.3, 1000.0).unwrap();
    let divergence = DVec3::new(2.0 * a, 0.0, 2.0 * c) * material.lame().mu;
    let forces = forces_under(
        &mesh,
        MaterialModel::Linear,
        None,
        |p| p + u(p),
        |_| DVec3::ZERO,
    );
    let mut shape_integral = vec![0.0; mesh.node_count()];
    for element in mesh.elements() {
        let p: Vec<DVec3> = element[..4]
            .iter()
            .map(|&n| mesh.positions()[n as usize])
            .collect();
        let volume = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) / 6.0;
        for (k, &n) in element.iter().enumerate() {
            shape_integral[n as usize] += if k < 4 { -volume / 20.0 } else { volume / 5.0 };
        }
    }
    let boundary = mesh
        .positions()
        .iter()
        .zip(&forces)
        .filter(|(p, _)| !is_interior(**p))
        .map(|(_, f)| f.length())
        .fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for (n, p) in mesh.positions().iter().enumerate() {
        if is_interior(*p) {
            let expected = divergence * shape_integral[n];
            worst = worst.max((forces[n] - expected).length());
        }
    }
    println!(
        "quadratic field: worst interior force error / boundary force = {:.2e}",
        worst / boundary
    );
    assert!(worst < 1e-9 * boundary);
}

/// Rigid rotation and spin: no elastic or damping force, to 1e-10 of the force a 1 % strain
/// gives (round-off).
#[test]
fn rigid_motion_produces_no_force() {
    let mesh = distorted_quadratic_box();
    let damping = RayleighDamping::new(2e4, 1e4).unwrap();
    let rotation = DMat3::from_axis_angle(DVec3::new(-1.0, 0.5, 2.0).normalize(), 2.5);
    let spin = DVec3::new(3.0, -1.0, 2.0);
    let translation = DVec3::new(1.0, -2.0, 0.5);
    let scale = 1e7 * 0.01 * (2.0 * HALF / 3.0f64).powi(2);
    for model in OBJECTIVE_MODELS {
        let forces = forces_under(
            &mesh,
            model,
            Some(damping),
            |p| rotation * p + translation,
            |p| spin.cross(rotation * p),
        );
        let largest = forces.iter().map(|f| f.length()).fold(0.0, f64::max);
        assert!(largest < 1e-10 * scale, "{model:?}: {largest:e} N");
    }
}

/// A free, spinning and vibrating body: internal forces sum to zero, so the momentum is kept to
/// round-off (1e-12 relative) by explicit and implicit steps alike.
#[test]
fn momentum_is_conserved_by_explicit_and_implicit_steps() {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.4, 1000.0).unwrap();
    let linear = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2]).unwrap();
    let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
    for implicit in [false, true] {
        let mut body = DeformableBodyBuilder::quadratic(quadratic.clone(), material)
            .damping(RayleighDamping::new(5.0, 10.0).unwrap())
            .build()
            .unwrap();
        let (change, scale) = common::free_momentum_change(&mut body, 3, implicit);
        println!("implicit {implicit}: |Δp| = {change:.2e} of {scale:.3e} kg m/s");
        assert!(change < 1e-12 * scale);
    }
}

/// An undamped quadratic body stepped explicitly at the automatic substep keeps its energy:
/// the stable-step estimate holds for the lumped quadratic element. A 5 % bound on the drift of
/// kinetic + elastic energy over 0.5 s (symplectic Euler oscillates by O(dt) around the true
/// energy; an unstable step grows without bound).
#[test]
fn explicit_steps_of_quadratic_elements_are_stable() {
    let material = Material::new(MaterialModel::Corotated, 1e6, 0.3, 1000.0).unwrap();
    let linear = mesh::cuboid(DVec3::splat(0.1), [3, 3, 3]).unwrap();
    let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
    let mut body = DeformableBodyBuilder::quadratic(quadratic, material)
        .build()
        .unwrap();
    let (worst, _) = common::explicit_energy_change(&mut body, 9, 0.005, 30);
    println!(
        "explicit quadratic: worst energy drift {:.2}%",
        100.0 * worst
    );
    assert!(worst < 0.05);
}

/// The reference cantilever (E = 1e8, L = 1 m, 0.1 x 0.1 m) of 10 x 1 x 1 cells, clamped face
/// pinned. At ν = 0 the clamp holds back no Poisson contraction and the 3D beam is Timoshenko's:
/// quadratic tetrahedra are within 0.5 % of it (measured -0.16 %), where linear ones of the same
/// cells are 67 % too stiff. At ν = 0.3 the pinned face stiffens the 3D beam by about 1 % (the
/// converged 3D tip, 60 x 6 x 6 quadratic cells, is -0.96 % from Timoshenko): 10 x 1 x 1 cells
/// are within 3 % of Timoshenko (measured -2.84 %), 20 x 1 x 1 within 2 % (-1.89 %).
#[test]
fn quadratic_cantilever_matches_beam_theory() {
    for (nu, cells, bound) in [
        (0.0, [10, 1, 1], 0.005),
        (0.3, [10, 1, 1], 0.03),
        (0.3, [20, 1, 1], 0.02),
    ] {
        let material = Material::new(MaterialModel::Linear, 1e8, nu, common::DENSITY).unwrap();
        let half = DVec3::new(0.5, 0.05, 0.05);
        let quadratic =
            mesh::QuadraticTetMesh::from_linear(&mesh::cuboid(half, cells).unwrap()).unwrap();
        let clamped = quadratic.nodes_where(|p| p.x <= -half.x + 1e-9);
        let tip = quadratic.nodes_where(|p| p.x >= half.x - 1e-9);
        let mut body = DeformableBodyBuilder::quadratic(quadratic, material)
            .pinned_nodes(clamped)
            .build()
            .unwrap();
        assert_eq!(body.element_order(), ElementOrder::Quadratic);
        let height = |b: &DeformableBody| {
            tip.iter()
                .map(|&n| b.positions()[n as usize].y)
                .sum::<f64>()
                / tip.len() as f64
        };
        let rest = height(&body);
        let gravity = DVec3::new(0.0, -common::GRAVITY, 0.0);
        statics::solve_equilibrium(&mut body, gravity, &StaticSettings::default()).unwrap();
        let error = (rest - height(&body)) / common::timoshenko_tip_deflection(1e8, nu) - 1.0;
        println!(
            "quadratic {cells:?} nu = {nu}: tip error {:+.2}%",
            100.0 * error
        );
        assert!(error.abs() < bound, "nu = {nu}, {cells:?}: {error}");
    }
}

/// The first bending frequency of the quadratic 20 x 1 x 1 beam at ν = 0.3 within 1 % of the
/// Timoshenko beam's 5.069 Hz (shear and rotary inertia included; computed with 400 beam elements
/// in `benches/compare/common.py`); measured +0.7 %, of which about +0.5 % is the pinned face
/// (the 40 x 4 x 4 quadratic beam gives 5.095 Hz).
#[test]
fn quadratic_cantilever_first_frequency_matches_timoshenko() {
    let material = Material::new(MaterialModel::Linear, 1e8, 0.3, common::DENSITY).unwrap();
    let half = DVec3::new(0.5, 0.05, 0.05);
    let quadratic =
        mesh::QuadraticTetMesh::from_linear(&mesh::cuboid(half, [20, 1, 1]).unwrap()).unwrap();
    let clamped = quadratic.nodes_where(|p| p.x <= -half.x + 1e-9);
    let body = DeformableBodyBuilder::quadratic(quadratic, material)
        .pinned_nodes(clamped)
        .build()
        .unwrap();
    let frequency = statics::fundamental_frequency(&body).unwrap();
    let error = frequency / 5.069 - 1.0;
    println!(
        "quadratic 20x1x1 first frequency {frequency:.4} Hz ({:+.2}%)",
        100.0 * error
    );
    assert!(error.abs() < 0.01);
}

/// A quadratic mesh whose elements disagree on a shared edge's mid-edge node is refused, naming
/// the element and the edge.
#[test]
fn non_conforming_quadratic_mesh_is_refused() {
    let linear = mesh::cuboid(DVec3::splat(0.1), [1, 1, 1]).unwrap();
    let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
    let mut positions = quadratic.positions().to_vec();
    let mut elements = quadratic.elements().to_vec();
    // Give element 1 its own copy of a mid-edge node it shares with element 0.
    let (k, shared) = (4..10)
        .map(|k| (k, elements[1][k]))
        .find(|(_, n)| elements[0][4..].contains(n))
        .expect("neighbouring elements share an edge");
    positions.push(positions[shared as usize]);
    elements[1][k] = positions.len() as u32 - 1;
    let error = mesh::QuadraticTetMesh::new(positions, elements).unwrap_err();
    let [i, j] = EDGES[k - 4];
    println!("{error}");
    assert_eq!(
        error,
        Error::NonConformingEdge {
            tet: 1,
            corners: [
                elements_corner(&quadratic, 1, i),
                elements_corner(&quadratic, 1, j)
            ],
            node: quadratic.node_count() as u32,
            other: shared,
        }
    );
}

fn elements_corner(mesh: &mesh::QuadraticTetMesh, element: usize, corner: usize) -> u32 {
    mesh.elements()[element][corner]
}

/// Contacts act on the quadratic body's own nodes (the surface of its subdivision), so a
/// quadratic cube dropped into a rapier world comes to rest on the ground collider with the
/// ground's reaction equal to its weight (1 %, the coupling tests' bound) and no node below the
/// ground by more than 1 mm (the contact margin's scale).
#[test]
fn a_quadratic_cube_rests_on_a_rapier_ground() {
    use rapier_fvm::glamx::Vec3;
    use rapier_fvm::world::FvmWorld;
    use rapier3d::prelude::{ColliderBuilder, SharedShape};

    let mut world = FvmWorld::default();
    let ground = world
        .physics
        .insert_collider(ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)), None);
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let linear = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2]).unwrap();
    let cube = DeformableBodyBuilder::quadratic(
        mesh::QuadraticTetMesh::from_linear(&linear).unwrap(),
        material,
    )
    .damping(RayleighDamping::stiffness_proportional(0.01, material.lame()).unwrap())
    .translation(DVec3::new(0.0, 0.15, 0.0))
    .build()
    .unwrap();
    let cube = world.soft_bodies.insert(cube);
    let reaction = common::settled_reaction(&mut world, cube, ground);
    let body = &world.soft_bodies[cube];
    let weight = body.total_mass() * 9.81;
    let lowest = body
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min);
    println!(
        "quadratic cube: reaction {reaction:.4} N vs weight {weight:.4} N, lowest node {:.3} mm",
        lowest * 1e3
    );
    assert!((reaction / weight - 1.0).abs() < 0.01);
    assert!(lowest > -1e-3);
}

/// Curved boundary edges follow the true shape: the quadratic sphere's volume (the sum of its
/// quadrature weights, total mass over density) is far closer to `4/3 π r³` than the flat
/// mesh's of the same cells, and a curved cylinder's side nodes all lie on the circle.
#[test]
fn curved_quadratic_meshes_follow_the_round_shape() {
    let radius: f64 = 0.1;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let material = Material::new(MaterialModel::Corotated, 1e6, 0.3, 1000.0).unwrap();
    let flat = mesh::sphere(radius, 4).unwrap();
    let curved = mesh::QuadraticTetMesh::sphere(radius, 4).unwrap();
    let body = DeformableBodyBuilder::quadratic(curved.clone(), material)
        .build()
        .unwrap();
    let flat_error = flat.volume() / exact - 1.0;
    let curved_error = body.total_mass() / 1000.0 / exact - 1.0;
    println!(
        "sphere, 4 cells across: flat volume {:+.3}%, curved quadratic {:+.4}%",
        100.0 * flat_error,
        100.0 * curved_error
    );
    assert!(curved_error.abs() < 0.1 * flat_error.abs());
    for p in curved.positions() {
        assert!(p.length() <= radius * (1.0 + 1e-12));
    }
    let cylinder = mesh::QuadraticTetMesh::cylinder(radius, 0.2, 4, 3).unwrap();
    let side = |p: &DVec3| DVec3::new(p.x, 0.0, p.z).length();
    let outermost = cylinder.positions().iter().map(side).fold(0.0, f64::max);
    assert!((outermost / radius - 1.0).abs() < 1e-12);
}

/// Attachments act on a quadratic body's nodes as on a linear one's: a quadratic rod glued at
/// its root to a kinematic body driven around a 5 cm circle once a second keeps the glued nodes
/// on the path to 0.1 mm, with each integrator (the setting and bound of the linear-element
/// test in `tests/coupling.rs`, but a tenth of its stiffness-proportional damping: with that
/// heavy damping the explicit step of quadratic elements, whose corner masses are small, is
/// about 12 times shorter than linear ones', and the test took over 2 minutes). Measured:
/// 0.0855 mm implicit, below a micrometre explicit.
#[test]
fn glued_quadratic_nodes_follow_a_moving_kinematic_body() {
    for integrator in [
        None,
        Some(IntegratorKind::Explicit),
        Some(IntegratorKind::Implicit),
    ] {
        let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
        let linear = mesh::cuboid(DVec3::new(0.01, 0.1, 0.01), [1, 5, 1]).unwrap();
        let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
        let root = quadratic.nodes_where(|p| p.y >= 0.1 - 1e-9);
        let rod = DeformableBodyBuilder::quadratic(quadratic, material)
            .damping(RayleighDamping::stiffness_proportional(1e-3, material.lame()).unwrap())
            .translation(DVec3::new(common::GLUED_PATH_RADIUS, 0.4, 0.0))
            .build()
            .unwrap();
        let worst = common::glued_path_error(rod, &root, integrator);
        println!(
            "{integrator:?}: quadratic glued nodes' largest distance from the path {:.4} mm",
            worst * 1e3
        );
        assert!(worst < 1e-4, "{integrator:?}: {worst:e} m");
    }
}

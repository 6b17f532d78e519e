//! Initial velocities from the builder: `angvel` spins the placed body about its centre of mass,
//! composing with `linvel`, so that `angular_momentum()` is `I ω` for the inertia of the lumped
//! nodal masses computed here independently; `nodes_linvel` gives regions their own velocity;
//! bad values are refused; a free spinning block keeps its angular momentum when stepped.

mod common;

use rapier_fvm::body::SPEED_OF_LIGHT;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;

/// Half extents (m) of the test block: three different principal moments.
const HALF: DVec3 = DVec3::new(0.2, 0.1, 0.05);

fn material() -> Material {
    Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap()
}

/// The test block with 8 x 4 x 2 cells.
fn block() -> DeformableBodyBuilder {
    DeformableBodyBuilder::new(mesh::cuboid(HALF, [8, 4, 2]).unwrap(), material())
}

/// The inertia tensor (kg m²) of `body`'s nodal masses about their centre of mass, at their
/// current positions: `Σ m (|r|² 1 - r rᵀ)`.
fn nodal_inertia(body: &DeformableBody) -> DMat3 {
    let total: f64 = body.masses().iter().sum();
    let center = body
        .positions()
        .iter()
        .zip(body.masses())
        .fold(DVec3::ZERO, |sum, (x, m)| sum + *x * *m)
        / total;
    let mut inertia = DMat3::ZERO;
    for (x, m) in body.positions().iter().zip(body.masses()) {
        let r = *x - center;
        let outer = DMat3::from_cols(r * r.x, r * r.y, r * r.z);
        inertia += (DMat3::IDENTITY * r.length_squared() - outer) * *m;
    }
    inertia
}

/// `|a - b|` relative to `|b|`.
fn relative_error(a: DVec3, b: DVec3) -> f64 {
    (a - b).length() / b.length()
}

#[test]
fn a_block_spun_about_a_principal_axis_carries_i_omega_along_it() {
    // About z, the block's axis of largest inertia. Against the nodal inertia it is exact to
    // round-off. The lumped masses sit on the mesh's nodes, which weigh the second moment of each
    // axis as the trapezoidal rule does: a² (1 + 2/n²) / 3 per unit mass for half extent a in n
    // cells, so that I_zz = m (a² (1 + 2/n_x²) + b² (1 + 2/n_y²)) / 3, 5 % above the continuum's
    // m (a² + b²) / 3 on 8 x 4 cells.
    let omega = DVec3::new(0.0, 0.0, 3.0);
    let body = block().angvel(omega).build().unwrap();
    let expected = nodal_inertia(&body) * omega;
    let momentum = body.angular_momentum();
    assert!(
        relative_error(momentum, expected) < 1e-12,
        "{momentum} vs {expected}"
    );
    assert!(
        momentum.x.abs() + momentum.y.abs() < 1e-12 * momentum.z,
        "{momentum}"
    );
    let trapezoidal = |half: f64, cells: f64| half * half * (1.0 + 2.0 / (cells * cells)) / 3.0;
    let closed_form = body.total_mass() * (trapezoidal(HALF.x, 8.0) + trapezoidal(HALF.y, 4.0));
    assert!((momentum.z - closed_form * omega.z).abs() < 1e-12 * momentum.z);
    // No linear momentum, the kinetic energy ω·Iω/2.
    assert!(body.linear_momentum().length() < 1e-12 * momentum.length());
    let kinetic = 0.5 * omega.dot(expected);
    assert!((body.kinetic_energy() - kinetic).abs() < 1e-12 * kinetic);
}

#[test]
fn angvel_spins_the_placed_body_about_its_centre_of_mass_and_composes_with_linvel() {
    // Rotated and translated, the block spins about its placed centre of mass about an axis
    // that is not principal: L = I ω with I the placed (rotated) inertia, p = m v, and the
    // kinetic energy splits into the translation's and the spin's.
    let (linvel, omega) = (DVec3::new(0.5, -1.0, 2.0), DVec3::new(1.0, -2.0, 0.5));
    let rotation = DVec3::new(0.3, 0.7, -0.2);
    let body = block()
        .rotation(rotation)
        .translation(DVec3::new(3.0, 1.0, -2.0))
        .linvel(linvel)
        .angvel(omega)
        .build()
        .unwrap();
    let inertia = nodal_inertia(&body);
    let rest_inertia = nodal_inertia(&block().build().unwrap());
    let turn = DMat3::from_quat(DQuat::from_scaled_axis(rotation));
    let placed = turn * rest_inertia * turn.transpose();
    for column in 0..3 {
        assert!(relative_error(placed.col(column), inertia.col(column)) < 1e-12);
    }
    let momentum = body.angular_momentum();
    assert!(
        relative_error(momentum, inertia * omega) < 1e-12,
        "{momentum}"
    );
    let mass = body.total_mass();
    assert!(relative_error(body.linear_momentum(), linvel * mass) < 1e-12);
    let kinetic = 0.5 * mass * linvel.length_squared() + 0.5 * omega.dot(inertia * omega);
    assert!((body.kinetic_energy() - kinetic).abs() < 1e-12 * kinetic);
}

#[test]
fn pinned_nodes_stay_at_rest_under_angvel_and_region_velocities() {
    let mesh = mesh::cuboid(HALF, [8, 4, 2]).unwrap();
    let left = mesh.nodes_where(|p| p.x <= -HALF.x + 1e-9);
    let right = mesh.nodes_where(|p| p.x >= 0.1 - 1e-9);
    let tip = mesh.nodes_where(|p| p.x >= HALF.x - 1e-9);
    let body = DeformableBodyBuilder::new(mesh, material())
        .angvel(DVec3::Z)
        .nodes_linvel(left.iter().copied(), DVec3::X)
        .nodes_linvel(right.iter().copied(), DVec3::Y)
        .nodes_linvel(tip.iter().copied(), DVec3::NEG_Y)
        .pinned_nodes(left.iter().copied())
        .build()
        .unwrap();
    let center = body.center_of_mass();
    for (node, (x, v)) in body.positions().iter().zip(body.velocities()).enumerate() {
        let id = node as u32;
        let expected = if left.contains(&id) {
            DVec3::ZERO
        } else if tip.contains(&id) {
            DVec3::NEG_Y
        } else if right.contains(&id) {
            DVec3::Y
        } else {
            DVec3::Z.cross(*x - center)
        };
        assert_eq!(*v, expected, "node {node} at {x}");
    }
}

#[test]
fn bad_angular_and_region_velocities_are_refused() {
    let error = |builder: DeformableBodyBuilder| builder.build().unwrap_err();
    assert!(matches!(
        error(block().angvel(DVec3::new(f64::NAN, 0.0, 0.0))),
        Error::NonFiniteInput {
            parameter: "angvel"
        }
    ));
    assert!(matches!(
        error(block().nodes_linvel([0], DVec3::splat(f64::INFINITY))),
        Error::NonFiniteInput {
            parameter: "nodes_linvel"
        }
    ));
    let node_count = block().build().unwrap().node_count();
    assert!(matches!(
        error(block().nodes_linvel([node_count as u32], DVec3::X)),
        Error::NodeOutOfRange { node, .. } if node == node_count
    ));
    // 1e10 rad/s moves the corners 0.23 m from the centre at 2.3e9 m/s.
    assert!(matches!(
        error(block().angvel(DVec3::new(0.0, 0.0, 1e10))),
        Error::SpeedOutOfRange { speed, .. } if speed > SPEED_OF_LIGHT
    ));
    assert!(matches!(
        error(block().nodes_linvel([3], DVec3::new(0.0, 4e8, 0.0))),
        Error::SpeedOutOfRange { node: 3, .. }
    ));
}

#[test]
fn a_free_spinning_block_keeps_its_angular_momentum() {
    // Zero gravity, damped, spun at 3 rad/s about z and drifting: the block stretches under the
    // spin and its damping takes out the breathing, but no load acts on it. Stepped explicitly
    // (symplectic Euler, which keeps Σ m x × v exactly under torque-free forces), L and p are
    // kept to round-off (1e-15 relative measured over 60 frames; 1e-12 allowed) while the
    // kinetic energy falls into elastic energy and the damping.
    // Backward Euler's steps move the nodes along chords of the turn and fall short of the
    // angular momentum by h Σ m v₀ × v₁ per step (3.5 % in 1 s of 1/240 s substeps), which the
    // implicit integrator gives back; what is left is the torque of the out-of-balance force
    // each of the 240 solves keeps, within 1e-6 of its force scale (2.8e-5 measured on this
    // soft, stretching block; 1e-4 allowed).
    let omega = DVec3::new(0.0, 0.0, 3.0);
    let linvel = DVec3::new(0.2, 0.0, 0.0);
    for (kind, tolerance) in [
        (IntegratorKind::Explicit, 1e-12),
        (IntegratorKind::Implicit, 1e-4),
    ] {
        let mut world = FvmWorld::default();
        world.physics.gravity = Vec3::ZERO;
        world.coupling.integrator.force = Some(kind);
        let damping = RayleighDamping::stiffness_proportional(0.01, material().lame()).unwrap();
        let body = block()
            .damping(damping)
            .linvel(linvel)
            .angvel(omega)
            .build()
            .unwrap();
        let (angular0, linear0) = (body.angular_momentum(), body.linear_momentum());
        let kinetic0 = body.kinetic_energy();
        let handle = world.soft_bodies.insert(body);
        common::run(&mut world, 60).unwrap();
        let body = &world.soft_bodies[handle];
        let angular_change = relative_error(body.angular_momentum(), angular0);
        let linear_change = relative_error(body.linear_momentum(), linear0);
        assert!(
            angular_change < tolerance && linear_change < 1e-12,
            "{kind:?}: angular momentum changed by {angular_change:e}, linear by {linear_change:e}"
        );
        assert!(body.kinetic_energy() < kinetic0, "{kind:?}");
        assert!(
            body.elastic_energy() > 0.0,
            "{kind:?}: the spin stretches the block"
        );
    }
}

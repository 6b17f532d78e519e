//! Implicit (backward Euler) dynamics of 2D bodies: rigid motion kept (a damped free body
//! spinning for 10 s, a hinged plate swinging with the compound-pendulum period), linear
//! momentum exact, and the static limit reached.

use rapier_fvm::damping::RayleighDamping;
use rapier_fvm::glamx::DVec2;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{
    PlanarBody, PlanarBodyBuilder, PlaneModel, TriangleMesh, edge_loads, solve_planar_equilibrium,
    step_implicit,
};
use rapier_fvm::statics::StaticSettings;

const FRAME: f64 = 1.0 / 60.0;

fn settings() -> StaticSettings {
    StaticSettings::default()
}

/// The spin `Σ m (x − c) × (v − v_c)` (kg m²/s) and its kinetic energy (J) about the centre
/// of mass.
fn spin(body: &PlanarBody) -> (f64, f64) {
    let mass = body.total_mass();
    let c = (body.masses().iter().zip(body.positions()))
        .map(|(m, x)| *x * *m)
        .sum::<DVec2>()
        / mass;
    let vc = body.linear_momentum() / mass;
    let mut angular = 0.0;
    let mut energy = 0.0;
    for ((m, x), v) in body
        .masses()
        .iter()
        .zip(body.positions())
        .zip(body.velocities())
    {
        angular += m * (*x - c).perp_dot(*v - vc);
        energy += 0.5 * m * (*v - vc).length_squared();
    }
    (angular, energy)
}

/// A free 0.2 m rubber disk with Rayleigh damping (stiffness time 2 ms), spinning at 5 rad/s
/// and moving at 1 m/s, under gravity, stepped implicitly at 1/60 s for 10 s: its spin's
/// angular momentum kept to 1e-6, its kinetic energy from the first second to the last to 1e-4
/// (backward Euler alone would drain most of both), linear momentum changed by gravity alone to
/// 1e-9. A step's velocity is the chord's, `(x₊ − x₀)/h`: at the angular momentum `I ω₀` a
/// rotation by `θ` per step (`sin θ = ω₀ h`) has the kinetic energy `I ω₀² / (2 cos²(θ/2))`,
/// `θ²/4` = 1.7e-3 above the start's, which the first step sets (less the centrifugal
/// stretch's share, about 1.4e-4) and no later step changes.
#[test]
fn a_spinning_body_keeps_its_spin() {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0).unwrap();
    let damping = RayleighDamping::stiffness_proportional(2e-3, rubber.lame()).unwrap();
    for plane in [PlaneModel::PlaneStress, PlaneModel::PlaneStrain] {
        let mut body = PlanarBodyBuilder::new(TriangleMesh::disk(0.1, 5).unwrap(), rubber)
            .plane(plane)
            .thickness(0.02)
            .damping(damping)
            .build()
            .unwrap();
        let positions = body.positions().to_vec();
        for (v, x) in body.velocities_mut().iter_mut().zip(positions) {
            *v = DVec2::X + x.perp() * 5.0;
        }
        let (l0, e0) = spin(&body);
        let p0 = body.linear_momentum();
        let gravity = DVec2::new(0.0, -9.81);
        let loads = vec![DVec2::ZERO; body.positions().len()];
        let mut given = 0.0;
        let mut after_one_second = 0.0;
        for frame in 1..=600 {
            let report = step_implicit(&mut body, FRAME, gravity, &loads, &settings()).unwrap();
            given += report.angular_momentum_given_back;
            if frame == 60 {
                after_one_second = spin(&body).1;
            }
        }
        let (l1, e1) = spin(&body);
        let p1 = body.linear_momentum();
        let expected = p0 + gravity * (body.total_mass() * 10.0);
        let theta = (5.0 * FRAME).asin();
        let chord = 1.0 / (theta / 2.0).cos().powi(2) - 1.0;
        println!(
            "{plane:?}: spin {l0:.6e} → {l1:.6e}, energy {e0:.6e} → {after_one_second:.6e} → {e1:.6e} (chord offset {chord:.3e}), given back {given:.3e}"
        );
        assert!((l1 / l0 - 1.0).abs() < 1e-6, "{plane:?}: {l0} → {l1}");
        assert!(
            (e1 / after_one_second - 1.0).abs() < 1e-4,
            "{plane:?}: {after_one_second} → {e1}"
        );
        let offset = after_one_second / e0 - 1.0;
        assert!(
            offset > 0.0 && offset < chord,
            "{plane:?}: offset {offset} against {chord}"
        );
        assert!(
            (p1 - expected).length() < 1e-9 * expected.length(),
            "{p1} against {expected}"
        );
    }
}

/// A stiff 0.3 m × 0.05 m steel plate held at one corner node, released with its centre of mass
/// 10° from below the pin: a compound pendulum, `T = 2π √(I_p / (M g d))` for small swings. It
/// swings with that period to 1 % (measured +0.81 %: the 10° amplitude lengthens it by 0.19 %,
/// steps of 1/60 s, `ω h` = 0.12, by about 0.6 %, which shrinks as `h²`: +0.23 % in all at
/// 1/240 s, +0.05 % at 2°), and keeps its amplitude to 1 % over three periods, where backward
/// Euler alone would damp the swing.
#[test]
fn a_hinged_plate_swings_with_the_pendulum_period() {
    let steel = Material::new(MaterialModel::Corotated, 2e11, 0.3, 7800.0).unwrap();
    let (length, depth) = (0.3, 0.05);
    let mesh = TriangleMesh::rectangle(DVec2::new(length, depth), [12, 2]).unwrap();
    let mut plate = PlanarBodyBuilder::new(mesh, steel)
        .plane(PlaneModel::PlaneStress)
        .thickness(0.01)
        .pinned_nodes([0])
        .build()
        .unwrap();
    let amplitude = 10f64.to_radians();
    let turn = -std::f64::consts::FRAC_PI_2 + amplitude - (depth / length).atan();
    let rotation = rapier_fvm::glamx::DMat2::from_angle(turn);
    for x in plate.positions_mut() {
        *x = rotation * *x;
    }
    let mass = plate.total_mass();
    let arm = DVec2::new(length, depth).length() / 2.0;
    let inertia_about_pin: f64 = (plate.masses().iter().zip(plate.mesh().rest_positions()))
        .map(|(m, p)| m * p.length_squared())
        .sum();
    let period = std::f64::consts::TAU * (inertia_about_pin / (mass * 9.81 * arm)).sqrt();
    let gravity = DVec2::new(0.0, -9.81);
    let loads = vec![DVec2::ZERO; plate.positions().len()];
    // The angle of the centre of mass from below the pin (the pin stays at the origin).
    let angle = |plate: &PlanarBody| {
        let c = (plate.masses().iter().zip(plate.positions()))
            .map(|(m, x)| *x * *m)
            .sum::<DVec2>();
        c.x.atan2(-c.y)
    };
    let (mut crossings, mut last, mut extreme) = (Vec::new(), angle(&plate), 0.0f64);
    let mut t = 0.0;
    while crossings.len() < 7 {
        step_implicit(&mut plate, FRAME, gravity, &loads, &settings()).unwrap();
        t += FRAME;
        let a = angle(&plate);
        if (a > 0.0) != (last > 0.0) {
            crossings.push(t - FRAME * a / (a - last));
        }
        if crossings.len() >= 5 {
            extreme = extreme.max(a.abs());
        }
        last = a;
    }
    let measured = (crossings[6] - crossings[0]) / 3.0;
    println!(
        "period {measured:.5} s against {period:.5} s; amplitude {extreme:.5} against {amplitude:.5} rad"
    );
    assert!(
        (measured / period - 1.0).abs() < 1e-2,
        "period {measured} against {period}"
    );
    assert!(
        (extreme / amplitude - 1.0).abs() < 1e-2,
        "amplitude {extreme} against {amplitude}"
    );
}

/// Stepped implicitly with damping (stiffness time 50 ms), a bar pulled at its end settles
/// where the static solver puts it: tip displacement within 1e-6 after 10 s (its slowest mode,
/// about 10 rad/s, decays by `e⁻³⁰` meanwhile).
#[test]
fn a_damped_bar_settles_at_the_static_solution() {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.4, 1000.0).unwrap();
    let mesh = TriangleMesh::rectangle(DVec2::new(0.5, 0.05), [20, 2]).unwrap();
    let clamped = mesh.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9);
    let end = mesh.nodes_on_line(DVec2::new(0.5, 0.0), DVec2::Y, 1e-9);
    let damping = RayleighDamping::stiffness_proportional(5e-2, rubber.lame()).unwrap();
    let mut bar = PlanarBodyBuilder::new(mesh, rubber)
        .plane(PlaneModel::PlaneStrain)
        .thickness(0.05)
        .damping(damping)
        .pinned_nodes(clamped)
        .build()
        .unwrap();
    let loads = edge_loads(&bar, &end, DVec2::new(50.0, 20.0), true);
    let mut statics = bar.clone();
    solve_planar_equilibrium(&mut statics, &loads, &settings()).unwrap();
    for _ in 0..600 {
        let report = step_implicit(&mut bar, FRAME, DVec2::ZERO, &loads, &settings()).unwrap();
        // Clamped along an edge, the bar has no rigid rotation to keep.
        assert_eq!(report.angular_momentum_given_back, 0.0);
    }
    let tip = end[1];
    let rest = bar.mesh().rest_positions()[tip];
    let (moved, expected) = (bar.positions()[tip] - rest, statics.positions()[tip] - rest);
    println!("tip {moved} against {expected}");
    assert!((moved - expected).length() < 1e-6 * expected.length());
}

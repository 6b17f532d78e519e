//! Loads against closed forms: a thick-walled tube under internal pressure (Lamé), a cantilever
//! under an end traction (Timoshenko), a pneumatic finger (the pressure's work against the
//! elastic energy, momentum of a free finger), a cable, and the follower forces' consistency.

mod common;

use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};

/// Inner and outer radii (m) and Young's modulus (Pa) of the tube; the pressure (Pa) is small
/// against the modulus so that linear elasticity's closed form applies (strains about 1e-4).
const INNER: f64 = 0.01;
const OUTER: f64 = 0.02;
const YOUNG: f64 = 1e6;
const PRESSURE: f64 = 100.0;

/// Lamé's radial displacement (m) of the bore of a long tube in plane strain under internal
/// pressure `p`: `u(a) = (1 + ν) p a² / (E (b² − a²)) ((1 − 2ν) a + b²/a)`.
fn lame_bore_displacement(nu: f64) -> f64 {
    let (a, b) = (INNER, OUTER);
    (1.0 + nu) * PRESSURE * a * a / (YOUNG * (b * b - a * a)) * ((1.0 - 2.0 * nu) * a + b * b / a)
}

/// The mean radial displacement (m) of the bore's nodes in the middle sixth of a tube twelve
/// wall thicknesses long, with both ends clamped, at equilibrium under the internal pressure,
/// `cells_through` cells through the wall (8 times as many around, 6 times along).
fn tube_bore_displacement(
    cells_through: usize,
    nu: f64,
    treatment: VolumetricTreatment,
) -> (usize, f64) {
    let half_height = 6.0 * (OUTER - INNER);
    let mesh = mesh::tube(
        INNER,
        OUTER,
        half_height,
        8 * cells_through,
        cells_through,
        6 * cells_through,
    )
    .unwrap();
    let ends = mesh.nodes_where(|p| p.y.abs() >= half_height - 1e-9);
    let bore = mesh.surface_triangles_where(|p| p.x.hypot(p.z) <= INNER * (1.0 + 1e-9));
    let middle = mesh
        .nodes_where(|p| p.x.hypot(p.z) <= INNER * (1.0 + 1e-9) && p.y.abs() <= half_height / 6.0);
    let material = Material::new(MaterialModel::Linear, YOUNG, nu, 1000.0).unwrap();
    let tets = mesh.tet_count();
    let rest: Vec<DVec3> = mesh.positions().to_vec();
    let mut tube = DeformableBodyBuilder::new(mesh, material)
        .pinned_nodes(ends)
        .volumetric(treatment)
        .build()
        .unwrap();
    tube.add_load(Load::Pressure {
        triangles: bore,
        pressure: PRESSURE,
    })
    .unwrap();
    let settings = StaticSettings {
        tolerance: 1e-9,
        ..StaticSettings::default()
    };
    statics::solve_equilibrium(&mut tube, DVec3::ZERO, &settings).unwrap();
    let radial: f64 = (middle.iter())
        .map(|&n| {
            let (p, x) = (rest[n as usize], tube.positions()[n as usize]);
            x.x.hypot(x.z) - p.x.hypot(p.z)
        })
        .sum::<f64>()
        / middle.len() as f64;
    (tets, radial)
}

/// The bore's displacement converges to Lamé's within 2 % (the bound) at ν = 0.3 with
/// plain linear tetrahedra (measured −7.18 %, −1.71 %, −0.53 % at 2, 4, 6 cells through the
/// wall), and at ν = 0.4999 with nodal averaging, the locking-free option of linear tetrahedra
/// (−27.9 %, −8.34 %, −1.63 % at 1, 2, 4; −0.13 % at 6, 124k tets, left out for its 90 s),
/// where the plain tetrahedra lock (−74 % at 4, printed). The tube's polygonal bore and its
/// clamped ends (six wall thicknesses from the measured middle) are part of the discretization
/// error, which the printed sequence shows falling.
#[test]
fn thick_tube_under_internal_pressure_matches_lame() {
    for (nu, treatment, levels) in [
        (0.3, VolumetricTreatment::PerElement, [2, 4, 6]),
        (0.4999, VolumetricTreatment::NodalAverage, [1, 2, 4]),
    ] {
        let exact = lame_bore_displacement(nu);
        println!("ν = {nu}, {treatment:?}: Lamé u(a) = {:.6e} m", exact);
        let mut error = f64::INFINITY;
        for cells in levels {
            let (tets, u) = tube_bore_displacement(cells, nu, treatment);
            error = u / exact - 1.0;
            println!(
                "  {cells} cells through the wall, {tets:6} tets: u(a) = {u:.6e} m, {:+.3} %",
                100.0 * error
            );
        }
        assert!(error.abs() < 0.02, "ν = {nu}: {:+.3} %", 100.0 * error);
    }
    let (_, locked) = tube_bore_displacement(4, 0.4999, VolumetricTreatment::PerElement);
    println!(
        "ν = 0.4999 per element (locking), 4 cells through: {:+.1} %",
        100.0 * (locked / lame_bore_displacement(0.4999) - 1.0)
    );
}

/// Tip deflection (m) of a cantilever of length `L`, square side `s`, under an end load `P` (N):
/// Timoshenko, `P L³ / (3 E I) + P L / (κ G A)` with Cowper's `κ = 10 (1 + ν) / (12 + 11 ν)`.
fn timoshenko_end_load(load: f64, length: f64, side: f64, young: f64, nu: f64) -> f64 {
    let (area, inertia) = (side * side, side.powi(4) / 12.0);
    let shear = young / (2.0 * (1.0 + nu));
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    load * length.powi(3) / (3.0 * young * inertia) + load * length / (kappa * shear * area)
}

/// A cantilever of `half` extents (m) along x, linear material of Young's modulus `young` (Pa)
/// at ν = 0, on a cage of 27-node hexahedra of `cells` with the element-averaged volumetric
/// term, its face x = −half.x pinned.
fn clamped_cage_beam(half: DVec3, cells: [usize; 3], young: f64) -> DeformableBody {
    let cage = mesh::QuadraticHexMesh::cuboid(half, cells).unwrap();
    let clamped = cage.nodes_where(|p| p.x <= -half.x + 1e-9);
    let material = Material::new(MaterialModel::Linear, young, 0.0, 1000.0).unwrap();
    DeformableBodyBuilder::quadratic_hex(cage, material)
        .pinned_nodes(clamped)
        .volumetric(VolumetricTreatment::ElementAverage)
        .build()
        .unwrap()
}

/// A 1 m cantilever of 0.1 m square section (E = 1e8 Pa, ν = 0, clamped face pinned) on a cage
/// of 27-node hexahedra, loaded by a uniform downward traction of 1 kPa on its free end face (a
/// 10 N end load): the mean deflection of the end face within 2 % (the bound) of
/// Timoshenko's for an end load (at ν = 0 the clamp holds back no Poisson contraction, so the 3D
/// beam is the beam theory's); measured −0.07 % at 5 x 1 x 1 cells, −0.01 % at 10 x 2 x 2. The
/// traction is a dead load: the deflection (about 0.4 % of the length) is linear in it.
#[test]
fn cantilever_under_end_traction_matches_timoshenko() {
    let (half, young, traction) = (DVec3::new(0.5, 0.05, 0.05), 1e8, 1e3);
    let expected = timoshenko_end_load(traction * 0.01, 1.0, 0.1, young, 0.0);
    println!("Timoshenko end load: {:.4} mm", expected * 1e3);
    let mut error = f64::INFINITY;
    for cells in [[5, 1, 1], [10, 2, 2]] {
        let mut beam = clamped_cage_beam(half, cells, young);
        let tip = beam.mesh().nodes_where(|p| p.x >= half.x - 1e-9);
        let end = beam
            .mesh()
            .surface_triangles_where(|p| p.x >= half.x - 1e-9);
        beam.add_load(Load::Traction {
            triangles: end,
            traction: DVec3::new(0.0, -traction, 0.0),
        })
        .unwrap();
        let height = |b: &DeformableBody| {
            tip.iter()
                .map(|&n| b.positions()[n as usize].y)
                .sum::<f64>()
                / tip.len() as f64
        };
        let rest = height(&beam);
        statics::solve_equilibrium(&mut beam, DVec3::ZERO, &StaticSettings::default()).unwrap();
        let deflection = rest - height(&beam);
        error = deflection / expected - 1.0;
        println!(
            "cage {cells:?}: tip {:.4} mm, {:+.2} %",
            deflection * 1e3,
            100.0 * error
        );
    }
    assert!(error.abs() < 0.02, "{:+.2} %", 100.0 * error);
}

/// Half-extents (m) of the pneumatic finger: 10 cm long (x, base at x = −5 cm), 2 cm square.
const FINGER: DVec3 = DVec3::new(0.05, 0.01, 0.01);

/// A pneumatic finger: a silicone-like beam (stable Neo-Hookean, E = 100 kPa, ν = 0.45) of
/// 2.5 mm cubes with an inner chamber 8 cm long, 1 cm wide and 1 cm high, whose floor (7.5 mm)
/// is three times as thick as its roof (2.5 mm), so that inflating it stretches the roof and
/// bends the finger toward its floor (−y). Returns the body, built with its base pinned if
/// `clamped`, the chamber's pressure load, and the tip's node (the centre of the free end).
fn pneumatic_finger(clamped: bool) -> (DeformableBody, LoadHandle, usize) {
    let lattice = mesh::cuboid(FINGER, [40, 8, 8]).unwrap();
    let in_chamber =
        |p: DVec3| p.x.abs() < 0.04 && p.y > -0.0025 && p.y < 0.0075 && p.z.abs() < 0.005;
    let kept: Vec<[u32; 4]> = (lattice.tets().iter())
        .filter(|t| {
            let centre: DVec3 = t
                .iter()
                .map(|&n| lattice.positions()[n as usize])
                .sum::<DVec3>()
                / 4.0;
            !in_chamber(centre)
        })
        .copied()
        .collect();
    // The nodes inside the chamber are left unused: number the others anew.
    let mut index = vec![u32::MAX; lattice.node_count()];
    let mut positions = Vec::new();
    for &n in kept.iter().flatten() {
        if index[n as usize] == u32::MAX {
            index[n as usize] = positions.len() as u32;
            positions.push(lattice.positions()[n as usize]);
        }
    }
    let tets = kept.iter().map(|t| t.map(|n| index[n as usize])).collect();
    let mesh = TetMesh::new(positions, tets).unwrap();
    let on_chamber_wall = |p: DVec3| {
        p.x.abs() <= 0.04 + 1e-9
            && p.y >= -0.0025 - 1e-9
            && p.y <= 0.0075 + 1e-9
            && p.z.abs() <= 0.005 + 1e-9
    };
    let chamber = mesh.surface_triangles_where(on_chamber_wall);
    let base = mesh.nodes_where(|p| p.x <= -FINGER.x + 1e-9);
    let tip = mesh.nearest_node(DVec3::new(FINGER.x, 0.0, 0.0)) as usize;
    let silicone = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.45, 1070.0).unwrap();
    let mut builder = DeformableBodyBuilder::new(mesh, silicone);
    if clamped {
        builder = builder.pinned_nodes(base);
    }
    let mut finger = builder.build().unwrap();
    let pressure = finger
        .add_load(Load::Pressure {
            triangles: chamber,
            pressure: 0.0,
        })
        .unwrap();
    (finger, pressure, tip)
}

/// The angle (rad) the finger's free end has turned about z, from its top and bottom edge
/// midpoints' nodes: positive toward +y.
fn tip_angle(finger: &DeformableBody) -> f64 {
    let node = |y: f64| finger.mesh().nearest_node(DVec3::new(FINGER.x, y, 0.0)) as usize;
    let (top, bottom) = (node(FINGER.y), node(-FINGER.y));
    let edge = finger.positions()[top] - finger.positions()[bottom];
    (-edge.x).atan2(edge.y)
}

/// The clamped finger inflated in 16 static steps to 5 kPa bends toward its thick floor, more at
/// every step (the tip angle printed against the pressure). The work the pressure did, `∫ p dV
/// = P ΔV(P) − ∫ ΔV dp` (Simpson's rule over the steps, exact to about 1e-7 here), equals the
/// elastic energy stored within 1e-3 (the bound): the pressure is a conservative load
/// on the closed chamber, and the static solves stop at 1e-10 of the load.
#[test]
fn pneumatic_finger_bends_and_the_pressure_work_is_the_elastic_energy() {
    let (mut finger, chamber, tip) = pneumatic_finger(true);
    let volume = |f: &DeformableBody| {
        f.load(chamber)
            .unwrap()
            .enclosed_volume(f.positions())
            .unwrap()
    };
    let rest_volume = volume(&finger);
    println!(
        "chamber volume at rest {:.4} cm³, tip at {:?}",
        rest_volume * 1e6,
        finger.positions()[tip]
    );
    let (steps, full) = (16, 5e3);
    let settings = StaticSettings {
        tolerance: 1e-10,
        ..StaticSettings::default()
    };
    let mut growth = vec![0.0];
    let mut angle = 0.0;
    println!("pressure (kPa)  tip angle (°)  chamber volume change (cm³)");
    for k in 1..=steps {
        let pressure = full * k as f64 / steps as f64;
        finger
            .set_load(chamber, LoadValue::Scalar(pressure))
            .unwrap();
        statics::solve_equilibrium(&mut finger, DVec3::ZERO, &settings).unwrap();
        let now = tip_angle(&finger);
        println!(
            "{:14.3}  {:13.3}  {:.5}",
            pressure * 1e-3,
            now.to_degrees(),
            (volume(&finger) - rest_volume) * 1e6
        );
        assert!(
            now < angle,
            "the finger bends toward its floor, more at every step"
        );
        angle = now;
        growth.push(volume(&finger) - rest_volume);
    }
    let dp = full / steps as f64;
    let simpson: f64 = (0..steps / 2)
        .map(|i| dp / 3.0 * (growth[2 * i] + 4.0 * growth[2 * i + 1] + growth[2 * i + 2]))
        .sum();
    let work = full * growth[steps] - simpson;
    let elastic = finger.elastic_energy();
    println!(
        "∫ p dV = {work:.6e} J, elastic energy {elastic:.6e} J, {:+.2e}",
        work / elastic - 1.0
    );
    assert!((work / elastic - 1.0).abs() < 1e-3);
}

/// The free finger (no pin, no gravity), inflated from rest to 5 kPa over 0.25 s and held,
/// keeps zero linear and angular momentum while it writhes: the chamber's pressure is internal.
/// Explicit steps keep both to round-off (bound 1e-12 of the largest `Σ m |v|` of the run, and
/// of it times the finger's 5 cm half-length for the angular momentum; measured 8e-16); implicit
/// steps to the linear solves' accuracy (bound 1e-9, measured 4.2e-13): the forces, the
/// pressure's among them, sum to zero at every configuration, so each Newton update leaves an
/// out-of-balance force that sums to zero whatever the step's tolerance.
#[test]
fn free_pneumatic_finger_keeps_its_momentum() {
    let frame = 1.0 / 60.0;
    for (kind, frames) in [
        (IntegratorKind::Explicit, 20),
        (IntegratorKind::Implicit, 60),
    ] {
        // The default explicit and implicit integrators, the choice forced.
        let integrator = AutomaticIntegrator {
            force: Some(kind),
            ..AutomaticIntegrator::default()
        };
        let (mut finger, chamber, _) = pneumatic_finger(false);
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let (mut worst, mut largest): (f64, f64) = (0.0, 0.0);
        for k in 1..=frames {
            let pressure = 5e3 * (k as f64 * frame / 0.25).min(1.0);
            finger
                .set_load(chamber, LoadValue::Scalar(pressure))
                .unwrap();
            (integrator.step(
                &mut finger,
                &mut constraints,
                &mut workspace,
                frame,
                DVec3::ZERO,
            ))
            .unwrap();
            let (linear, angular, scale) = common::momenta(&finger);
            worst = worst.max(linear.length()).max(angular.length() / FINGER.x);
            largest = largest.max(scale);
        }
        let worst = worst / largest;
        println!(
            "{kind:?}, {frames} frames: largest Σ m|v| {largest:.3e} kg m/s, worst momentum {worst:.2e} of it"
        );
        let bound = match kind {
            IntegratorKind::Explicit => 1e-12,
            _ => 1e-9,
        };
        assert!(worst < bound, "{kind:?}: {worst:e}");
    }
}

/// A cable run straight along the cantilever of the end-traction test, 3 cm above its axis,
/// through the nodes on that line from the clamped face to the free end where it is anchored,
/// and pulled with 20 N: it bends the beam by a constant moment `M = T e` (and shortens it by
/// `T L / (E A)`), so that the free end turns by `M L / (E I)` (Euler–Bernoulli; a constant
/// moment has no shear). Within 2 % on the 10 x 2 x 2 cage (measured −0.78 %), the cable
/// following the bent beam through its eyelets.
#[test]
fn cable_bends_a_cantilever_by_its_moment() {
    let (half, young, tension, offset) = (DVec3::new(0.5, 0.05, 0.05), 1e8, 20.0, 0.025);
    let mut beam = clamped_cage_beam(half, [10, 2, 2], young);
    let rest = beam.mesh().positions().to_vec();
    let mut path = beam
        .mesh()
        .nodes_where(|p| (p.y - offset).abs() < 1e-9 && p.z.abs() < 1e-9);
    path.sort_by(|a, b| rest[*a as usize].x.total_cmp(&rest[*b as usize].x));
    println!("the cable runs through {} eyelets", path.len());
    beam.add_load(Load::Cable { path, tension }).unwrap();
    statics::solve_equilibrium(&mut beam, DVec3::ZERO, &StaticSettings::default()).unwrap();
    let node = |y: f64| beam.mesh().nearest_node(DVec3::new(half.x, y, 0.0)) as usize;
    let edge = beam.positions()[node(half.y)] - beam.positions()[node(-half.y)];
    let angle = (-edge.x).atan2(edge.y);
    let expected = tension * offset * 1.0 / (young * 0.1f64.powi(4) / 12.0);
    let error = angle / expected - 1.0;
    println!(
        "end rotation {:.5}°, Euler–Bernoulli {:.5}°, {:+.2} %",
        angle.to_degrees(),
        expected.to_degrees(),
        100.0 * error
    );
    assert!(error.abs() < 0.02);
}

/// A 10 cm block standing on its pinned base, pressed by 100 Pa on its top face: an open
/// surface whose rim is free, where the follower pressure has a part no potential gives (see
/// `rapier_fvm::load`). The static solve meets the exact follower load at equilibrium, which
/// at a strain of 1e-4 is the dead traction `−p ŷ` on the rest face to within 1e-3 of the
/// displacement (the difference is of the order of the strain; measured +6.3e-5), and implicit
/// steps under it converge and settle to the same state within 1e-3 (measured −1.4e-7).
#[test]
fn pressure_on_an_open_face_with_a_free_rim_converges_to_the_follower_load() {
    let half = 0.05;
    let block = |load: fn(Vec<[u32; 3]>) -> Load| {
        let mesh = mesh::cuboid(DVec3::splat(half), [4, 4, 4]).unwrap();
        let base = mesh.nodes_where(|p| p.y <= -half + 1e-9);
        let top = mesh.surface_triangles_where(|p| p.y >= half - 1e-9);
        let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
        let damping = RayleighDamping::stiffness_proportional(5e-3, rubber.lame()).unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, rubber)
            .pinned_nodes(base)
            .damping(damping)
            .build()
            .unwrap();
        body.add_load(load(top)).unwrap();
        body
    };
    let follower = |triangles| Load::Pressure {
        triangles,
        pressure: 1e2,
    };
    let dead = |triangles| Load::Traction {
        triangles,
        traction: DVec3::new(0.0, -1e2, 0.0),
    };
    let top_centre = |b: &DeformableBody| {
        let n = b.mesh().nearest_node(DVec3::new(0.0, half, 0.0)) as usize;
        b.positions()[n].y - half
    };
    let settings = StaticSettings::default();
    let mut pressed = block(follower);
    let report = statics::solve_equilibrium(&mut pressed, DVec3::ZERO, &settings).unwrap();
    let mut pulled = block(dead);
    statics::solve_equilibrium(&mut pulled, DVec3::ZERO, &settings).unwrap();
    let (u_pressure, u_traction) = (top_centre(&pressed), top_centre(&pulled));
    println!(
        "top centre: pressure {u_pressure:.6e} m ({} Newton iterations), dead traction {u_traction:.6e} m, {:+.2e}",
        report.iterations,
        u_pressure / u_traction - 1.0
    );
    assert!(u_pressure < 0.0 && (u_pressure / u_traction - 1.0).abs() < 1e-3);
    let mut stepped = block(follower);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let implicit = ImplicitIntegrator::default();
    for _ in 0..60 {
        implicit
            .step(
                &mut stepped,
                &mut constraints,
                &mut workspace,
                1.0 / 60.0,
                DVec3::ZERO,
            )
            .unwrap();
    }
    let settled = top_centre(&stepped);
    println!(
        "implicit, after 1 s: {settled:.6e} m, {:+.2e}",
        settled / u_pressure - 1.0
    );
    assert!((settled / u_pressure - 1.0).abs() < 1e-3);
}

/// A soft tetrahedral beam (10 x 1 x 1 cm, 40 x 4 x 4 cells, E = 1e5 Pa, undamped) clamped at
/// both ends and falling under gravity onto a taut cable of 10 N along its top edge, anchored
/// in both clamped faces, stepped explicitly for half a second at the default stable step: the
/// cable's transverse stiffness `2T/d` at a node (8000 N/m over its 2.5 mm segments) is 30
/// times the elements' (about `E d`, 250 N/m). With the step bounded by the elements alone the
/// cable's mode grows until elements crush (`TooManySubsteps` in the first frame; at 30 N a
/// non-finite state); with the cable's stiffness in the bound the beam sags and swings, its
/// energy (kinetic, elastic, gravitational and the cable's `T L`) kept within 1 % of the
/// largest kinetic energy of the run (symplectic Euler's energy error is bounded and of the
/// order of the step; measured 2.8e-3).
#[test]
fn an_explicit_step_is_stable_under_a_stiff_cable() {
    let half = DVec3::new(0.05, 0.005, 0.005);
    let beam = mesh::cuboid(half, [40, 4, 4]).unwrap();
    let clamped = beam.nodes_where(|p| p.x.abs() > half.x - 1e-9);
    let mut path = beam.nodes_where(|p| (p.y - half.y).abs() < 1e-9 && p.z.abs() < 1e-9);
    let rest = beam.positions().to_vec();
    path.sort_by(|a, b| rest[*a as usize].x.total_cmp(&rest[*b as usize].x));
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mut body = DeformableBodyBuilder::new(beam, material)
        .pinned_nodes(clamped)
        .build()
        .unwrap();
    let cable = Load::Cable {
        path,
        tension: 10.0,
    };
    body.add_load(cable).unwrap();
    let integrator = AutomaticIntegrator {
        force: Some(IntegratorKind::Explicit),
        ..AutomaticIntegrator::default()
    };
    let gravity = DVec3::new(0.0, -9.81, 0.0);
    let energy = |b: &DeformableBody| {
        b.kinetic_energy()
            + b.elastic_energy()
            + b.gravity_potential_energy(gravity)
            + b.load_potential_energy()
    };
    let start = energy(&body);
    let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let (mut drift, mut kinetic): (f64, f64) = (0.0, 0.0);
    for _ in 0..30 {
        let frame = 1.0 / 60.0;
        (integrator.step(&mut body, &mut constraints, &mut workspace, frame, gravity)).unwrap();
        drift = drift.max((energy(&body) - start).abs());
        kinetic = kinetic.max(body.kinetic_energy());
    }
    println!(
        "stiff cable, explicit: critical step {:.3e} s, largest kinetic energy {kinetic:.3e} J, \
         energy drift {:.2e} of it",
        SymplecticEuler::critical_time_step(&body),
        drift / kinetic
    );
    assert!(
        kinetic > 0.0 && drift < 0.01 * kinetic,
        "{drift:e} of {kinetic:e}"
    );
}

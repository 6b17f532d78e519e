//! Materials that differ by region inside one body, against closed forms: a bar of two
//! materials in tension (springs in series), a two-layer cantilever (the transformed section),
//! the total mass and weight, and a body whose every element is given another material behaving
//! as a body of that material; the explicit step stays stable with a stiff region. (A world
//! with region materials written and read back: `tests/serialize.rs`.)

use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};

/// Young's modulus (Pa) and density (kg/m³) of the soft material, and the stiff one's factors.
const SOFT: f64 = 1e6;
const SOFT_DENSITY: f64 = 1000.0;
const STIFF_FACTOR: f64 = 4.0;
const DENSE_FACTOR: f64 = 2.5;

fn material(model: MaterialModel, young: f64, nu: f64, density: f64) -> Material {
    Material::new(model, young, nu, density).unwrap()
}

/// The element kinds a body is built of.
#[derive(Debug, Clone, Copy)]
enum Kind {
    LinearTets,
    QuadraticTets,
    HexCage,
}

const KINDS: [Kind; 3] = [Kind::LinearTets, Kind::QuadraticTets, Kind::HexCage];

/// A builder of a box of `half` extents (m) and `cells`, of `kind`, made of `base`, its nodes
/// where `pinned` holds pinned, and per element the centroid of its nodes (m).
fn box_builder(
    kind: Kind,
    half: DVec3,
    cells: [usize; 3],
    base: Material,
    pinned: impl Fn(DVec3) -> bool,
) -> (DeformableBodyBuilder, Vec<DVec3>) {
    let centroid = |positions: &[DVec3], nodes: &[u32]| {
        nodes.iter().map(|&n| positions[n as usize]).sum::<DVec3>() / nodes.len() as f64
    };
    match kind {
        Kind::LinearTets => {
            let mesh = mesh::cuboid(half, cells).unwrap();
            let centres = (mesh.tets().iter())
                .map(|t| centroid(mesh.positions(), t))
                .collect();
            let pins = mesh.nodes_where(pinned);
            (
                DeformableBodyBuilder::new(mesh, base).pinned_nodes(pins),
                centres,
            )
        }
        Kind::QuadraticTets => {
            let linear = mesh::cuboid(half, cells).unwrap();
            let centres = (linear.tets().iter())
                .map(|t| centroid(linear.positions(), t))
                .collect();
            let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).unwrap();
            let pins = quadratic.nodes_where(pinned);
            let builder = DeformableBodyBuilder::quadratic(quadratic, base).pinned_nodes(pins);
            (builder, centres)
        }
        Kind::HexCage => {
            let cage = mesh::QuadraticHexMesh::cuboid(half, cells).unwrap();
            let positions = cage.subdivided().positions();
            let centres = (cage.elements().iter())
                .map(|e| centroid(positions, e))
                .collect();
            let pins = cage.nodes_where(pinned);
            let builder = DeformableBodyBuilder::quadratic_hex(cage, base).pinned_nodes(pins);
            (builder, centres)
        }
    }
}

/// The elements whose centroid satisfies `inside`.
fn elements_where(centres: &[DVec3], inside: impl Fn(DVec3) -> bool) -> Vec<u32> {
    (0..centres.len() as u32)
        .filter(|&e| inside(centres[e as usize]))
        .collect()
}

/// A bar 1 m long (x from −0.5 m) of 0.1 m square section, its left half soft (E) and its
/// right half stiff (4E, 2.5 times as dense), ν = 0, linear law, both end faces pinned, the right
/// one moved 1 mm along x: the bar stretches as two springs in series, the stress
/// `σ = δ / (L/2 (1/E + 1/(4E)))` in both halves and the displacement `σ (x + 0.5)/E` on the
/// left half, `σ/2 (1/E) + σ x/(4E)` on the right. Every element kind represents that piecewise
/// linear field exactly (the halves meet at element faces), so every node's displacement and
/// every tetrahedron's stress match to the static solve's tolerance (1e-10 relative; bound
/// 1e-8). The masses sum to `ρ V/2 + 2.5 ρ V/2` to round-off (1e-12).
#[test]
fn a_bar_of_two_materials_stretches_as_springs_in_series() {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let stretch = 1e-3;
    let soft = material(MaterialModel::Linear, SOFT, 0.0, SOFT_DENSITY);
    let stiff = material(
        MaterialModel::Linear,
        STIFF_FACTOR * SOFT,
        0.0,
        DENSE_FACTOR * SOFT_DENSITY,
    );
    let stress = stretch / (0.5 / SOFT + 0.5 / (STIFF_FACTOR * SOFT));
    let expected = |x: f64| {
        if x <= 0.0 {
            stress * (x + 0.5) / SOFT
        } else {
            stress * 0.5 / SOFT + stress * x / (STIFF_FACTOR * SOFT)
        }
    };
    for kind in KINDS {
        let ends = |p: DVec3| p.x.abs() >= half.x - 1e-9;
        let (builder, centres) = box_builder(kind, half, [4, 1, 1], soft, ends);
        let right = elements_where(&centres, |c| c.x > 0.0);
        let mut bar = builder.region_material(right, stiff).build().unwrap();
        let mass = bar.total_mass();
        let volume = 8.0 * half.x * half.y * half.z;
        let expected_mass = SOFT_DENSITY * volume * (0.5 + 0.5 * DENSE_FACTOR);
        assert!(
            (mass / expected_mass - 1.0).abs() < 1e-12,
            "{kind:?}: mass {mass} kg, expected {expected_mass} kg"
        );
        let rest = bar.positions().to_vec();
        for x in bar.positions_mut() {
            if x.x >= half.x - 1e-9 {
                x.x += stretch;
            }
        }
        let settings = StaticSettings {
            tolerance: 1e-10,
            ..StaticSettings::default()
        };
        statics::solve_equilibrium(&mut bar, DVec3::ZERO, &settings).unwrap();
        let worst = (rest.iter().zip(bar.positions()))
            .map(|(p, x)| ((x - p) - DVec3::X * expected(p.x)).length() / stretch)
            .fold(0.0, f64::max);
        let worst_stress = (bar.cauchy_stresses().iter())
            .map(|s| (s.x_axis.x / stress - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "{kind:?}: stress {stress:.6} Pa (series springs), worst node off by {worst:.1e} \
             of the stretch, worst σ_xx off by {worst_stress:.1e}"
        );
        assert!(
            worst < 1e-8 && worst_stress < 1e-8,
            "{kind:?}: {worst:e}, {worst_stress:e}"
        );
    }
}

/// Tip deflection (m) of a cantilever of length `L` under an end load `P` (N), its section of
/// width `b` made of `layers` (thickness (m) and Young's modulus (Pa) from the bottom up), all
/// at ν = 0: Timoshenko's `P L³ / (3 (EI)) + P L / (κ Σ G_i A_i)`, `(EI)` of the transformed
/// section about its neutral axis `ȳ = Σ E_i A_i y_i / Σ E_i A_i`, `κ = 10/12` (Cowper's
/// rectangle at ν = 0), `G = E/2`.
fn layered_timoshenko(load: f64, length: f64, width: f64, layers: &[(f64, f64)]) -> f64 {
    let mut bottom = 0.0;
    let mut placed = Vec::new();
    for &(thickness, young) in layers {
        placed.push((bottom + 0.5 * thickness, thickness, young));
        bottom += thickness;
    }
    let axial: f64 = placed.iter().map(|(_, t, e)| e * width * t).sum();
    let neutral = placed
        .iter()
        .map(|(y, t, e)| e * width * t * y)
        .sum::<f64>()
        / axial;
    let bending: f64 = (placed.iter())
        .map(|(y, t, e)| e * width * (t.powi(3) / 12.0 + t * (y - neutral).powi(2)))
        .sum();
    let shear: f64 = placed.iter().map(|(_, t, e)| 0.5 * e * width * t).sum();
    load * length.powi(3) / (3.0 * bending) + load * length / (10.0 / 12.0 * shear)
}

/// A cantilever 2 m long of 0.1 m square section, its lower half (y < 0) of E = 1e6 Pa and its
/// upper half four times as stiff (ν = 0, linear law), on a cage of 27-node hexahedra two
/// elements high (the layers meet at element faces), clamped at x = −1 m and loaded by a
/// downward end traction of 100 Pa (a 1 N end load): the end face's mean deflection within
/// 0.5 % of the transformed-section beam (Timoshenko, above; measured +0.02 %). The bound: the
/// homogeneous beam on such a cage meets its Timoshenko value within 0.1 % (test `loads`), and
/// the layered shear term, taken as `κ Σ G_i A_i`, is 0.11 % of the deflection, so even a shear
/// stiffness off by half would move the reference by less than 0.1 %.
#[test]
fn a_two_layer_cantilever_bends_as_its_transformed_section() {
    let half = DVec3::new(1.0, 0.05, 0.05);
    let (traction, young) = (100.0, 1e6);
    let base = material(MaterialModel::Linear, young, 0.0, 1000.0);
    let top = material(MaterialModel::Linear, STIFF_FACTOR * young, 0.0, 1000.0);
    let expected = layered_timoshenko(
        traction * 0.01,
        2.0,
        0.1,
        &[(0.05, young), (0.05, STIFF_FACTOR * young)],
    );
    let clamp = |p: DVec3| p.x <= -half.x + 1e-9;
    let (builder, centres) = box_builder(Kind::HexCage, half, [20, 2, 2], base, clamp);
    let upper = elements_where(&centres, |c| c.y > 0.0);
    let mut beam = builder
        .region_material(upper, top)
        .volumetric(VolumetricTreatment::ElementAverage)
        .build()
        .unwrap();
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
    let error = deflection / expected - 1.0;
    println!(
        "two-layer cantilever: tip {:.4} mm, transformed section {:.4} mm, {:+.2} %",
        1e3 * deflection,
        1e3 * expected,
        100.0 * error
    );
    assert!(error.abs() < 0.005, "{:+.2} %", 100.0 * error);
}

/// Positions and velocities moved off rest by a fixed pseudo-random pattern (up to 4 % of the
/// box's size, and 0.3 m/s).
fn disturb(body: &mut DeformableBody) {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for x in body.positions_mut() {
        *x += DVec3::new(next(), next(), next()) * 0.008;
    }
    for v in body.velocities_mut() {
        *v = DVec3::new(next(), next(), next()) * 0.6;
    }
}

/// The largest difference between `a` and `b`, over the largest entry of `a`.
fn relative_difference(a: &[DVec3], b: &[DVec3]) -> f64 {
    let scale = a.iter().map(|v| v.length()).fold(0.0, f64::max);
    let worst = (a.iter().zip(b))
        .map(|(x, y)| (x - y).length())
        .fold(0.0, f64::max);
    worst / scale
}

/// A body of material A whose every element is given material B (E and ρ changed) is a body of
/// material B: the same masses, internal forces (elastic and Rayleigh damping: the same β, the
/// region's damping being the body's scaled by `E_B/E_A`), elastic energy, stresses, critical
/// explicit step, and the same
/// implicit step (so the same tangent), for each model and element kind, both volumetric
/// treatments of quadratic elements, all to 1e-12 relative (the factor `E_B/E_A` rounds
/// differently from `E_B`; measured about 1e-15).
#[test]
fn every_element_given_another_material_is_a_body_of_that_material() {
    let half = DVec3::new(0.1, 0.05, 0.05);
    for model in [
        MaterialModel::Linear,
        MaterialModel::StVenantKirchhoff,
        MaterialModel::Corotated,
        MaterialModel::StableNeoHookean,
    ] {
        let a = material(model, SOFT, 0.35, SOFT_DENSITY);
        let b = material(model, 3.7 * SOFT, 0.35, 2.3 * SOFT_DENSITY);
        let damping = |m: Material| RayleighDamping::stiffness_proportional(0.002, m.lame());
        for kind in KINDS {
            for treatment in [
                VolumetricTreatment::PerElement,
                VolumetricTreatment::ElementAverage,
            ] {
                let build = |regions: bool| {
                    let base = if regions { a } else { b };
                    let (builder, centres) = box_builder(kind, half, [2, 1, 1], base, |_| false);
                    let all = 0..centres.len() as u32;
                    let builder = if regions {
                        builder.region_material(all, b)
                    } else {
                        builder
                    };
                    let mut body = builder
                        .damping(damping(base).unwrap())
                        .volumetric(treatment)
                        .build()
                        .unwrap();
                    disturb(&mut body);
                    body
                };
                let label = format!("{model:?} {kind:?} {treatment:?}");
                let (mut given, mut plain) = (build(true), build(false));
                assert!(given.has_region_materials() && !plain.has_region_materials());
                assert_eq!(given.element_material(1), Some(b), "{label}");
                compare_bodies(&mut given, &mut plain, &label);
            }
        }
    }
}

/// Asserts that `given` and `plain` agree to 1e-12 (see the test above).
fn compare_bodies(given: &mut DeformableBody, plain: &mut DeformableBody, label: &str) {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs();
    for (m, n) in given.masses().iter().zip(plain.masses()) {
        assert!(close(*m, *n), "{label}: mass {m} against {n}");
    }
    let forces = relative_difference(&plain.internal_forces(), &given.internal_forces());
    assert!(forces < 1e-12, "{label}: forces differ by {forces:e}");
    let (e, f) = (given.elastic_energy(), plain.elastic_energy());
    assert!(close(e, f), "{label}: energy {e} against {f}");
    let stress = |b: &DeformableBody| -> Vec<DVec3> {
        b.cauchy_stresses()
            .iter()
            .flat_map(|s| s.to_cols_array_2d().map(DVec3::from))
            .collect()
    };
    let stresses = relative_difference(&stress(plain), &stress(given));
    assert!(stresses < 1e-12, "{label}: stresses differ by {stresses:e}");
    let (s, t) = (
        SymplecticEuler::critical_time_step(given),
        SymplecticEuler::critical_time_step(plain),
    );
    assert!(close(s, t), "{label}: critical step {s} against {t}");
    let implicit = AutomaticIntegrator {
        force: Some(IntegratorKind::Implicit),
        ..AutomaticIntegrator::default()
    };
    let gravity = DVec3::new(0.0, -9.81, 0.0);
    for body in [&mut *given, &mut *plain] {
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        (implicit.step(body, &mut constraints, &mut workspace, 0.01, gravity)).unwrap();
    }
    let moved = relative_difference(plain.positions(), given.positions());
    assert!(moved < 1e-12, "{label}: implicit step differs by {moved:e}");
}

/// A free bar whose right half is 100 times as stiff as its left (and as dense: its wave speed
/// ten times the left's), set vibrating, stepped explicitly at the automatic substep: the
/// critical step counts the stiff half (a tenth of the soft body's; at 0.9 of the soft body's
/// step the stiff half's modes grow until the state is refused, asserted: refused or the energy
/// doubled), and the energy
/// (kinetic and elastic) stays within 1 % of its start over 0.2 s (symplectic Euler's energy
/// error is bounded and of the order of the step).
#[test]
fn an_explicit_step_is_stable_with_a_stiff_region() {
    let half = DVec3::new(0.1, 0.02, 0.02);
    let soft = material(MaterialModel::StableNeoHookean, SOFT, 0.3, SOFT_DENSITY);
    let stiff = material(
        MaterialModel::StableNeoHookean,
        100.0 * SOFT,
        0.3,
        SOFT_DENSITY,
    );
    let (builder, centres) = box_builder(Kind::LinearTets, half, [10, 2, 2], soft, |_| false);
    let right = elements_where(&centres, |c| c.x > 0.0);
    let mut bar = builder.region_material(right, stiff).build().unwrap();
    let soft_step = {
        let (builder, _) = box_builder(Kind::LinearTets, half, [10, 2, 2], soft, |_| false);
        SymplecticEuler::critical_time_step(&builder.build().unwrap())
    };
    let critical = SymplecticEuler::critical_time_step(&bar);
    for (x, v) in bar.positions().to_vec().iter().zip(bar.velocities_mut()) {
        *v = DVec3::new(0.0, 0.5 * (x.x / half.x).powi(2) - 0.1, 0.0);
    }
    let energy = |b: &DeformableBody| b.kinetic_energy() + b.elastic_energy();
    let start = energy(&bar);
    let frame = 1.0 / 60.0;
    let run = |body: &mut DeformableBody, substeps: Substeps| -> Result<f64, Error> {
        let mut integrator = AutomaticIntegrator {
            force: Some(IntegratorKind::Explicit),
            ..AutomaticIntegrator::default()
        };
        integrator.explicit.substeps = substeps;
        let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        let mut drift: f64 = 0.0;
        for _ in 0..12 {
            integrator.step(body, &mut constraints, &mut workspace, frame, DVec3::ZERO)?;
            drift = drift.max((energy(body) - start).abs() / start);
        }
        Ok(drift)
    };
    let soft_substeps = (frame / (0.9 * soft_step)).ceil() as u32;
    let unbounded = run(&mut bar.clone(), Substeps::Fixed(soft_substeps));
    let drift = run(&mut bar, Substeps::Automatic).unwrap();
    println!(
        "stiff half: critical step {critical:.3e} s ({:.3} of the soft bar's {soft_step:.3e} s), \
         energy drift {drift:.2e}; at 0.9 of the soft bar's step: {unbounded:?}",
        critical / soft_step
    );
    assert!(
        critical < 0.2 * soft_step,
        "{critical:e} against {soft_step:e}"
    );
    assert!(drift < 0.01, "{drift:e}");
    assert!(
        matches!(
            unbounded,
            Err(Error::NonFiniteState { .. } | Error::ElementCrushed { .. }) | Ok(1.0..)
        ),
        "at the soft bar's step: {unbounded:?}"
    );
}

/// What a region material cannot be: of another model, on an element the body lacks, with
/// nodal averaging (its patches mix elements) or with an embedded mesh: typed errors.
#[test]
fn a_region_material_the_body_cannot_take_is_refused() {
    let half = DVec3::splat(0.05);
    let soft = material(MaterialModel::Corotated, SOFT, 0.3, SOFT_DENSITY);
    let build = |edit: &dyn Fn(DeformableBodyBuilder) -> DeformableBodyBuilder| {
        let (builder, _) = box_builder(Kind::LinearTets, half, [2, 2, 2], soft, |_| false);
        edit(builder).build().map(|_| ()).unwrap_err().to_string()
    };
    let stiff = |model| material(model, 2.0 * SOFT, 0.3, SOFT_DENSITY);
    let cases: [(
        &str,
        &dyn Fn(DeformableBodyBuilder) -> DeformableBodyBuilder,
    ); 4] = [
        ("another model", &|b| {
            b.region_material([0], stiff(MaterialModel::StableNeoHookean))
        }),
        ("an element beyond the body", &|b| {
            b.region_material([40], stiff(MaterialModel::Corotated))
        }),
        ("nodal averaging", &|b| {
            b.region_material([0], stiff(MaterialModel::Corotated))
                .volumetric(VolumetricTreatment::NodalAverage)
        }),
        ("an embedded mesh", &|b| {
            b.region_material([0], stiff(MaterialModel::Corotated))
                .embedded(mesh::cuboid(DVec3::splat(0.04), [1, 1, 1]).unwrap())
        }),
    ];
    let expected = [
        "a region's material must have its body's model",
        "element 40 does not exist: the body has 40 elements",
        "VolumetricTreatment::NodalAverage with region materials is not supported",
        "an embedded mesh with region materials is not supported",
    ];
    for ((what, edit), expected) in cases.into_iter().zip(expected) {
        let message = build(edit);
        println!("{what}: {message}");
        assert!(message.contains(expected), "{what}: {message}");
    }
}

/// The body's weight and a body force load on a bar whose halves differ in density: gravity
/// pulls `Σ ρ_e V_e g` (the masses), a force density `b` (N/m³) pushes `b V` whatever the
/// densities (1e-12); a later region material takes precedence where two overlap; a quadratic
/// body reports each element's material; a region material equal to the body's leaves a body of
/// one material.
#[test]
fn body_forces_and_weights_count_each_region_s_density() {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let volume = 8.0 * half.x * half.y * half.z;
    let soft = material(MaterialModel::Corotated, SOFT, 0.3, SOFT_DENSITY);
    let dense = material(MaterialModel::Corotated, SOFT, 0.3, 4.0 * SOFT_DENSITY);
    let stiff = material(
        MaterialModel::Corotated,
        2.0 * SOFT,
        0.3,
        3.0 * SOFT_DENSITY,
    );
    for kind in KINDS {
        let (builder, centres) = box_builder(kind, half, [4, 1, 1], soft, |_| false);
        let right = elements_where(&centres, |c| c.x > 0.0);
        let last = elements_where(&centres, |c| c.x > 0.25);
        let mut bar = builder
            .region_material(right, dense)
            .region_material(last.clone(), stiff)
            .build()
            .unwrap();
        // Left half 1000, third quarter 4000, last quarter 3000 kg/m³.
        let expected = SOFT_DENSITY * volume * (0.5 + 0.25 * 4.0 + 0.25 * 3.0);
        let weight = bar.total_mass();
        assert!(
            (weight / expected - 1.0).abs() < 1e-12,
            "{kind:?}: {weight} kg"
        );
        assert_eq!(
            bar.element_material(last[0] as usize),
            Some(stiff),
            "{kind:?}"
        );
        assert_eq!(bar.element_material(0), Some(soft), "{kind:?}");
        assert_eq!(bar.element_material(bar.element_count()), None);
        let b = DVec3::new(0.0, 0.0, 700.0);
        bar.add_load(Load::BodyForce { density: b }).unwrap();
        // Moving every node 1 m along z changes the potential −Σ f·x by −(Σ f)_z.
        let before = bar.load_potential_energy();
        for x in bar.positions_mut() {
            x.z += 1.0;
        }
        let pushed = before - bar.load_potential_energy();
        assert!(
            (pushed / (b.z * volume) - 1.0).abs() < 1e-12,
            "{kind:?}: {pushed} N"
        );
        let (builder, _) = box_builder(kind, half, [4, 1, 1], soft, |_| false);
        let same = builder.region_material([0], soft).build().unwrap();
        assert!(!same.has_region_materials(), "{kind:?}");
    }
}

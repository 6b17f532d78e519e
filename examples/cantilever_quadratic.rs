//! Accuracy per cost on the reference cantilever (L = 1 m, 0.1 x 0.1 m, E = 1e8 Pa, ν = 0.3,
//! ρ = 1000 kg/m³, clamped face pinned): linear and quadratic tetrahedra against a coarse cage of
//! quadratic hexahedra.
//!
//! 1. Static equilibrium and first bending frequency per resolution, against Timoshenko beam
//!    theory, at ν = 0.3 and at ν = 0 (where the clamped face does not hold back the Poisson
//!    contraction, so the 3D beam and Timoshenko's agree).
//! 2. The volumetric term per quadrature point or projected per element (mean dilatation; linear
//!    pressure on hexahedra), from ν = 0 to the nearly incompressible 0.499.
//! 3. Dynamics: released from rest with stiffness-proportional damping `β = 2/ω₁` (the first mode
//!    critically damped; the equilibrium does not depend on it), 1.5 s, tip averaged over the
//!    last 0.25 s; wall time per step of 1/240 s and 1/60 s, per implicit scheme, with Newton
//!    iterations and tangent factorizations per step. Newton reuses earlier factorizations (the
//!    chord method, `ImplicitIntegrator::reuse_factorization`) except in the rows marked `off`,
//!    which measure the same setting with a fresh tangent at every iteration, side by side.
//!    (Explicit steps are not offered: this heavy stiffness-proportional damping makes the
//!    explicit stability limit tiny.)
//!
//! 4. The first bending frequency: modal (inverse iteration), and measured from free vibration
//!    stepped by each implicit scheme at 1/240 s and 1/60 s (numerical damping and period
//!    elongation included), beside the frequency at which the scheme steps the modal one.
//!
//! The tip deflection is the mean vertical displacement of the free face's nodes.
//! Run with `cargo run --release --example cantilever_quadratic`. The last line is a JSON object
//! for the most accurate dynamic setting within the time target of 1.2 ms per step (or
//! the fastest, if none is).

use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};
use std::time::Instant;

const LENGTH: f64 = 1.0;
const SIDE: f64 = 0.1;
const YOUNG: f64 = 1e8;
const POISSON: f64 = 0.3;
const DENSITY: f64 = 1000.0;
const GRAVITY: DVec3 = DVec3::new(0.0, -9.81, 0.0);
/// The target: within 1 % at or below this wall time per step (ms).
const TARGET_MS: f64 = 1.2;

/// Timoshenko tip deflection (m): `q L⁴/(8EI) + q L²/(2κGA)`, Cowper's κ for a rectangle.
fn timoshenko_tip(nu: f64) -> f64 {
    let (area, inertia) = (SIDE * SIDE, SIDE.powi(4) / 12.0);
    let q = DENSITY * area * GRAVITY.length();
    let shear = YOUNG / (2.0 * (1.0 + nu));
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    q * LENGTH.powi(4) / (8.0 * YOUNG * inertia) + q * LENGTH.powi(2) / (2.0 * kappa * shear * area)
}

/// Euler–Bernoulli first clamped-free bending frequency (rad/s).
fn euler_bernoulli_omega() -> f64 {
    let (area, inertia) = (SIDE * SIDE, SIDE.powi(4) / 12.0);
    1.875_104_068_7f64.powi(2) / LENGTH.powi(2) * (YOUNG * inertia / (DENSITY * area)).sqrt()
}

/// The Timoshenko beam's first frequency at ν = 0.3 (Hz), shear flexibility and rotary inertia
/// included; computed with 400 beam elements in `benches/compare/common.py`.
const TIMOSHENKO_FREQUENCY_HZ: f64 = 5.069;

/// The elements of a beam.
#[derive(Clone, Copy)]
enum Kind {
    /// Linear tetrahedra, five per cell.
    LinearTet,
    /// Quadratic (10-node) tetrahedra, five per cell.
    QuadraticTet,
    /// A cage of quadratic (27-node) hexahedra, one per cell.
    QuadraticHex,
}

/// A beam setting: element kind, cells per axis, material model, Poisson's ratio, and how the
/// volumetric term is evaluated.
#[derive(Clone, Copy)]
struct Beam {
    kind: Kind,
    cells: [usize; 3],
    model: MaterialModel,
    nu: f64,
    volumetric: VolumetricTreatment,
}

impl Beam {
    /// A beam of linear elasticity.
    fn linear(kind: Kind, cells: [usize; 3], nu: f64, volumetric: VolumetricTreatment) -> Self {
        Self {
            kind,
            cells,
            model: MaterialModel::Linear,
            nu,
            volumetric,
        }
    }

    /// The elements' order and the cells per axis, for the tables.
    fn label(&self) -> String {
        let order = match self.kind {
            Kind::LinearTet => "linear",
            Kind::QuadraticTet => "quadratic",
            Kind::QuadraticHex => "hex27 cage",
        };
        let [x, y, z] = self.cells;
        format!("{order} {x}x{y}x{z}")
    }

    /// The clamped beam along +x and the nodes of its free face.
    fn build(&self, damping: Option<f64>) -> Result<(DeformableBody, Vec<usize>), Error> {
        let half = DVec3::new(LENGTH / 2.0, SIDE / 2.0, SIDE / 2.0);
        let linear = mesh::cuboid(half, self.cells)?;
        let material = Material::new(self.model, YOUNG, self.nu, DENSITY)?;
        let clamped = |p: DVec3| p.x <= -half.x + 1e-9;
        let mut builder = match self.kind {
            Kind::LinearTet => {
                let pins = linear.nodes_where(clamped);
                DeformableBodyBuilder::new(linear, material).pinned_nodes(pins)
            }
            Kind::QuadraticTet => {
                let quadratic = mesh::QuadraticTetMesh::from_linear(&linear)?;
                let pins = quadratic.nodes_where(clamped);
                DeformableBodyBuilder::quadratic(quadratic, material).pinned_nodes(pins)
            }
            Kind::QuadraticHex => {
                let cage = mesh::QuadraticHexMesh::cuboid(half, self.cells)?;
                let pins = cage.nodes_where(clamped);
                DeformableBodyBuilder::quadratic_hex(cage, material).pinned_nodes(pins)
            }
        };
        if let Some(beta) = damping {
            builder = builder.damping(RayleighDamping::stiffness_proportional(
                beta,
                material.lame(),
            )?);
        }
        let body = builder
            .volumetric(self.volumetric)
            .translation(DVec3::X * half.x)
            .build()?;
        let tip = (0..body.node_count())
            .filter(|&n| body.mesh().positions()[n].x >= half.x - 1e-9)
            .collect();
        Ok((body, tip))
    }
}

/// A short name of a volumetric treatment for the tables.
fn volumetric_label(treatment: VolumetricTreatment) -> &'static str {
    match treatment {
        VolumetricTreatment::PerElement => "per point",
        VolumetricTreatment::NodalAverage => "nodal avg",
        VolumetricTreatment::ElementAverage => "projected",
    }
}

/// Mean height of the tip nodes (m).
fn tip_height(body: &DeformableBody, tip: &[usize]) -> f64 {
    tip.iter().map(|&n| body.positions()[n].y).sum::<f64>() / tip.len() as f64
}

/// Free degrees of freedom.
fn dofs(body: &DeformableBody) -> usize {
    3 * (0..body.node_count())
        .filter(|&n| !body.is_pinned(n))
        .count()
}

/// Static tip error against Timoshenko and the first frequency (Hz).
fn static_case(beam: &Beam) -> Result<(f64, f64, usize), Error> {
    let (mut body, tip) = beam.build(None)?;
    let rest = tip_height(&body, &tip);
    statics::solve_equilibrium(&mut body, GRAVITY, &StaticSettings::default())?;
    let deflection = rest - tip_height(&body, &tip);
    let frequency = statics::fundamental_frequency(&body)?;
    Ok((
        deflection / timoshenko_tip(beam.nu) - 1.0,
        frequency,
        dofs(&body),
    ))
}

/// How a dynamic case is stepped.
#[derive(Clone, Copy)]
enum Stepper {
    BackwardEuler,
    Bdf2,
}

impl Stepper {
    fn label(&self) -> &'static str {
        match self {
            Self::BackwardEuler => "implicit BE",
            Self::Bdf2 => "implicit BDF2",
        }
    }
}

/// The outcome of a dynamic case.
struct Dynamic {
    error: f64,
    ms_per_step: f64,
    dofs: usize,
    /// Newton iterations per step, on average.
    newton_per_step: f64,
    /// Cholesky factorizations per step, on average.
    factorizations_per_step: f64,
}

fn dynamic_case(beam: &Beam, stepper: Stepper, dt: f64, reuse: bool) -> Result<Dynamic, Error> {
    let (mut body, tip) = beam.build(Some(2.0 / euler_bernoulli_omega()))?;
    let rest = tip_height(&body, &tip);
    let steps = (1.5 / dt).round() as usize;
    let averaged = (0.25 / dt).round() as usize;
    let mut implicit = ImplicitIntegrator {
        reuse_factorization: reuse,
        ..Default::default()
    };
    if let Stepper::Bdf2 = stepper {
        implicit.scheme = ImplicitScheme::Bdf2;
    }
    let (mut sum, mut newton, mut factorizations) = (0.0, 0usize, 0usize);
    let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let start = Instant::now();
    for step in 0..steps {
        let report = implicit.step(&mut body, &mut free, &mut workspace, dt, GRAVITY)?;
        newton += report.newton_iterations;
        factorizations += report.factorizations;
        if step >= steps - averaged {
            sum += rest - tip_height(&body, &tip);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    Ok(Dynamic {
        error: sum / averaged as f64 / timoshenko_tip(beam.nu) - 1.0,
        ms_per_step: seconds * 1e3 / steps as f64,
        dofs: dofs(&body),
        newton_per_step: newton as f64 / steps as f64,
        factorizations_per_step: factorizations as f64 / steps as f64,
    })
}

/// The frequency (Hz) at which a scheme steps an undamped mode of `frequency` (Hz) with steps of
/// `dt` (s): `arg(z)/(2π dt)` for the mode's amplification `z` per step, `z = 1/(1 - iθ)` for
/// backward Euler and the root near 1 of `(3 - 2iθ) z² - 4z + 1 = 0` for BDF2, `θ = ω dt`.
fn stepped_frequency(frequency: f64, stepper: Stepper, dt: f64) -> f64 {
    let theta = 2.0 * std::f64::consts::PI * frequency * dt;
    let phase = match stepper {
        Stepper::BackwardEuler => theta.atan(),
        Stepper::Bdf2 => {
            // z = (2 + sqrt(1 + 2iθ)) / (3 - 2iθ); arg z = arg(numerator) - arg(denominator).
            let (modulus, angle) = ((1.0 + 4.0 * theta * theta).sqrt(), (2.0 * theta).atan());
            let root = (
                modulus.sqrt() * (angle / 2.0).cos(),
                modulus.sqrt() * (angle / 2.0).sin(),
            );
            (root.1).atan2(2.0 + root.0) + (2.0 * theta / 3.0).atan()
        }
    };
    phase / (2.0 * std::f64::consts::PI * dt)
}

/// The first bending frequency (Hz) from free vibration: the beam, undamped, released from its
/// static deflection under gravity with gravity switched off, stepped for 1 s (about five
/// periods, before backward Euler's numerical damping at 1/60 s takes the amplitude near the
/// Newton tolerance); the period is the mean spacing of the tip's upward crossings of its rest
/// height (linearly interpolated).
fn vibration_frequency(beam: &Beam, stepper: Stepper, dt: f64) -> Result<f64, Error> {
    let (mut body, tip) = beam.build(None)?;
    let rest = tip_height(&body, &tip);
    statics::solve_equilibrium(&mut body, GRAVITY, &StaticSettings::default())?;
    let implicit = ImplicitIntegrator {
        scheme: match stepper {
            Stepper::BackwardEuler => ImplicitScheme::BackwardEuler,
            Stepper::Bdf2 => ImplicitScheme::Bdf2,
        },
        ..Default::default()
    };
    let mut crossings = Vec::new();
    let mut before = tip_height(&body, &tip) - rest;
    let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for step in 1..=(1.0 / dt).round() as usize {
        implicit.step(&mut body, &mut free, &mut workspace, dt, DVec3::ZERO)?;
        let now = tip_height(&body, &tip) - rest;
        if before < 0.0 && now >= 0.0 {
            crossings.push((step as f64 - now / (now - before)) * dt);
        }
        before = now;
    }
    match crossings.as_slice() {
        [first, .., last] => Ok((crossings.len() - 1) as f64 / (last - first)),
        _ => Ok(f64::NAN),
    }
}

/// Prints the beam and its Timoshenko references.
fn print_intro() {
    println!(
        "Cantilever L = {LENGTH} m, {SIDE} x {SIDE} m, E = {YOUNG:e} Pa, rho = {DENSITY} kg/m^3, clamped face pinned"
    );
    println!(
        "Timoshenko tip: {:.3} mm (nu = 0.3), {:.3} mm (nu = 0); first frequency {TIMOSHENKO_FREQUENCY_HZ} Hz (nu = 0.3)\n",
        timoshenko_tip(POISSON) * 1e3,
        timoshenko_tip(0.0) * 1e3
    );
}

/// Table 1: static tip error at ν = 0.3 and ν = 0 and the first frequency per resolution.
fn static_table() -> Result<(), Error> {
    println!("1. Static equilibrium (linear elasticity) and first frequency");
    println!(
        "{:<18} {:>6} {:>14} {:>14} {:>11} {:>10}",
        "elements", "dofs", "tip err nu=0.3", "tip err nu=0", "f1 (Hz)", "f1 err"
    );
    let resolutions = [
        (Kind::LinearTet, [10, 1, 1]),
        (Kind::LinearTet, [20, 2, 2]),
        (Kind::LinearTet, [40, 4, 4]),
        (Kind::QuadraticTet, [5, 1, 1]),
        (Kind::QuadraticTet, [10, 1, 1]),
        (Kind::QuadraticTet, [20, 2, 2]),
        (Kind::QuadraticTet, [40, 4, 4]),
        (Kind::QuadraticHex, [2, 1, 1]),
        (Kind::QuadraticHex, [4, 1, 1]),
        (Kind::QuadraticHex, [5, 1, 1]),
        (Kind::QuadraticHex, [10, 1, 1]),
        (Kind::QuadraticHex, [20, 2, 2]),
    ];
    for (kind, cells) in resolutions {
        let beam = |nu| Beam::linear(kind, cells, nu, VolumetricTreatment::PerElement);
        let (error, frequency, dofs) = static_case(&beam(POISSON))?;
        let (error_nu0, _, _) = static_case(&beam(0.0))?;
        println!(
            "{:<18} {:>6} {:>13.2}% {:>13.2}% {:>11.4} {:>9.2}%",
            beam(POISSON).label(),
            dofs,
            100.0 * error,
            100.0 * error_nu0,
            frequency,
            100.0 * (frequency / TIMOSHENKO_FREQUENCY_HZ - 1.0)
        );
    }
    Ok(())
}

/// Table 2: static tip error per volumetric treatment, from ν = 0 to 0.499.
fn volumetric_table() -> Result<(), Error> {
    println!("\n2. Volumetric treatment (static, linear elasticity): tip error vs Timoshenko");
    println!(
        "{:<18} {:<15} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "elements", "volumetric", "dofs", "nu=0", "nu=0.3", "nu=0.45", "nu=0.49", "nu=0.499"
    );
    // One row per case: elements, cells, volumetric treatment.
    #[rustfmt::skip]
    let volumetric_cases = [
        (Kind::LinearTet, [40, 4, 4], VolumetricTreatment::PerElement),
        (Kind::LinearTet, [40, 4, 4], VolumetricTreatment::NodalAverage),
        (Kind::QuadraticTet, [10, 1, 1], VolumetricTreatment::PerElement),
        (Kind::QuadraticTet, [10, 1, 1], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticTet, [20, 1, 1], VolumetricTreatment::PerElement),
        (Kind::QuadraticTet, [20, 1, 1], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticTet, [10, 2, 2], VolumetricTreatment::PerElement),
        (Kind::QuadraticTet, [10, 2, 2], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticTet, [20, 2, 2], VolumetricTreatment::PerElement),
        (Kind::QuadraticTet, [20, 2, 2], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticHex, [5, 1, 1], VolumetricTreatment::PerElement),
        (Kind::QuadraticHex, [5, 1, 1], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticHex, [10, 1, 1], VolumetricTreatment::ElementAverage),
        (Kind::QuadraticHex, [20, 2, 2], VolumetricTreatment::ElementAverage),
    ];
    for (kind, cells, volumetric) in volumetric_cases {
        let beam = |nu| Beam::linear(kind, cells, nu, volumetric);
        let errors =
            [0.0, 0.3, 0.45, 0.49, 0.499].map(|nu| static_case(&beam(nu)).map(|(e, _, _)| e));
        let (_, _, dofs) = static_case(&beam(0.45))?;
        print!(
            "{:<18} {:<15} {:>6}",
            beam(0.45).label(),
            format!("{volumetric:?}"),
            dofs
        );
        for error in errors {
            print!(" {:>8.2}%", 100.0 * error?);
        }
        println!();
    }
    Ok(())
}

/// The best dynamic case so far: its beam, scheme label, step (s) and outcome.
type Best = (Beam, &'static str, f64, Dynamic);

/// Whether `outcome` beats `best`: within [`TARGET_MS`] first, then smaller error or faster.
fn is_better(outcome: &Dynamic, best: Option<&Best>) -> bool {
    match best {
        None => true,
        Some((_, _, _, b)) => {
            let fits = |d: &Dynamic| d.ms_per_step <= TARGET_MS;
            match (fits(outcome), fits(b)) {
                (true, false) => true,
                (false, true) => false,
                (true, true) => outcome.error.abs() < b.error.abs(),
                (false, false) => outcome.ms_per_step < b.ms_per_step,
            }
        }
    }
}

/// Prints the header of table 3.
fn print_dynamic_header() {
    println!("\n3. Dynamics to rest (nu = 0.3), error of the settled tip vs Timoshenko");
    println!(
        "{:<18} {:<12} {:<14} {:<10} {:<6} {:>8} {:>6} {:>9} {:>9} {:>11} {:>13}",
        "elements",
        "model",
        "integrator",
        "volumetric",
        "reuse",
        "dt",
        "dofs",
        "error",
        "ms/step",
        "newton/step",
        "factors/step"
    );
}

/// Prints the row of table 3 for one dynamic case.
fn print_dynamic_row(beam: &Beam, stepper: Stepper, dt: f64, reuse: bool, outcome: &Dynamic) {
    println!(
        "{:<18} {:<12} {:<14} {:<10} {:<6} {:>8} {:>6} {:>8.2}% {:>9.3} {:>11.2} {:>13.2}",
        beam.label(),
        format!("{:?}", beam.model),
        stepper.label(),
        volumetric_label(beam.volumetric),
        if reuse { "on" } else { "off" },
        format!("1/{:.0}", 1.0 / dt),
        outcome.dofs,
        100.0 * outcome.error,
        outcome.ms_per_step,
        outcome.newton_per_step,
        outcome.factorizations_per_step
    );
}

/// Table 3: the dynamic cases, each with both models at 1/240 s and 1/60 s; returns the best.
fn dynamic_table() -> Result<Option<Best>, Error> {
    print_dynamic_header();
    let mut best: Option<Best> = None;
    let per_element = VolumetricTreatment::PerElement;
    let averaged = VolumetricTreatment::ElementAverage;
    // One row per case: elements, cells, scheme, volumetric treatment, factorization reuse.
    #[rustfmt::skip]
    let dynamic_cases = [
        (Kind::LinearTet, [20, 2, 2], Stepper::BackwardEuler, per_element, true),
        (Kind::LinearTet, [40, 4, 4], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticTet, [5, 1, 1], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticTet, [10, 1, 1], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticTet, [10, 1, 1], Stepper::BackwardEuler, per_element, false),
        (Kind::QuadraticTet, [10, 1, 1], Stepper::Bdf2, per_element, true),
        (Kind::QuadraticTet, [20, 2, 2], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticTet, [20, 1, 1], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticHex, [4, 1, 1], Stepper::BackwardEuler, averaged, true),
        (Kind::QuadraticHex, [5, 1, 1], Stepper::BackwardEuler, per_element, true),
        (Kind::QuadraticHex, [5, 1, 1], Stepper::BackwardEuler, averaged, true),
        (Kind::QuadraticHex, [5, 1, 1], Stepper::BackwardEuler, averaged, false),
        (Kind::QuadraticHex, [5, 1, 1], Stepper::Bdf2, averaged, true),
        (Kind::QuadraticHex, [10, 1, 1], Stepper::BackwardEuler, averaged, true),
    ];
    for (kind, cells, stepper, volumetric, reuse) in dynamic_cases {
        for model in [MaterialModel::Linear, MaterialModel::Corotated] {
            for dt in [1.0 / 240.0, 1.0 / 60.0] {
                let beam = Beam {
                    model,
                    ..Beam::linear(kind, cells, POISSON, volumetric)
                };
                let outcome = dynamic_case(&beam, stepper, dt, reuse)?;
                print_dynamic_row(&beam, stepper, dt, reuse, &outcome);
                if is_better(&outcome, best.as_ref()) {
                    best = Some((beam, stepper.label(), dt, outcome));
                }
            }
        }
    }
    Ok(best)
}

/// Table 4: the modal first frequency and the one measured from free vibration per scheme.
fn frequency_table() -> Result<(), Error> {
    println!(
        "\n4. First bending frequency (nu = 0.3): modal, and from 1 s of free vibration (undamped, released from the static deflection)"
    );
    println!(
        "{:<18} {:<12} {:>10} {:>9} {:<14} {:>8} {:>10} {:>9} {:>14}",
        "elements",
        "volumetric",
        "modal Hz",
        "error",
        "integrator",
        "dt",
        "free Hz",
        "error",
        "scheme on modal"
    );
    for (kind, cells, volumetric) in [
        (
            Kind::QuadraticTet,
            [10, 1, 1],
            VolumetricTreatment::PerElement,
        ),
        (
            Kind::QuadraticHex,
            [5, 1, 1],
            VolumetricTreatment::ElementAverage,
        ),
    ] {
        let beam = Beam::linear(kind, cells, POISSON, volumetric);
        let (_, modal, _) = static_case(&beam)?;
        for stepper in [Stepper::BackwardEuler, Stepper::Bdf2] {
            for dt in [1.0 / 240.0, 1.0 / 60.0] {
                let free = vibration_frequency(&beam, stepper, dt)?;
                println!(
                    "{:<18} {:<12} {:>10.4} {:>8.2}% {:<14} {:>8} {:>10.4} {:>8.2}% {:>14.4}",
                    beam.label(),
                    volumetric_label(volumetric),
                    modal,
                    100.0 * (modal / TIMOSHENKO_FREQUENCY_HZ - 1.0),
                    stepper.label(),
                    format!("1/{:.0}", 1.0 / dt),
                    free,
                    100.0 * (free / TIMOSHENKO_FREQUENCY_HZ - 1.0),
                    stepped_frequency(modal, stepper, dt)
                );
            }
        }
    }
    Ok(())
}

fn main() -> Result<(), Error> {
    print_intro();
    static_table()?;
    volumetric_table()?;
    let best = dynamic_table()?;
    frequency_table()?;
    let (beam, stepper, dt, outcome) = best.expect("at least one case ran");
    println!(
        "{{\"setting\": \"{} {:?} {stepper} {} dt=1/{:.0}\", \"rel_error\": {:.5}, \"ms_per_step\": {:.4}, \"dofs\": {}}}",
        beam.label(),
        beam.model,
        volumetric_label(beam.volumetric),
        1.0 / dt,
        outcome.error,
        outcome.ms_per_step,
        outcome.dofs
    );
    Ok(())
}

//! The implicit integrator's linear solver and tolerances, measured.
//!
//! 1. `sizes`: milliseconds per backward Euler frame, Newton and conjugate gradient iterations,
//!    with the direct (Cholesky) solve, the conjugate gradient (relative tolerance 1e-3) and the
//!    automatic choice, on the stiff reference beam (L = 1 m, 0.1 x 0.1 m, E = 1e9 Pa, ν = 0.3,
//!    ρ = 1000 kg/m³, stable Neo-Hookean, clamped at one end, frames of 1/60 s) at about 1.6k,
//!    13k and 100k tetrahedra, and on a soft cube (0.2 m, E = 1e5 Pa, hanging from its top face,
//!    steps of 1/240 s) at about 5k to 100k tetrahedra; first a small beam at small steps (E =
//!    1e8 Pa, 0.2 ms, 270 free degrees of freedom), below the automatic choice's size floor.
//! 2. `calibrate`: the constants of `LinearSolver::Automatic`. Frames of exactly one Newton
//!    iteration separate the cost of a Cholesky factorization from that of a matrix-vector
//!    product (the conjugate gradient at fixed iteration counts); the conjugate gradient's
//!    iterations to 1e-3 are compared with the bound `sqrt(κ) ln(2/tol) / 2`.
//! 3. `knobs`: the Newton tolerance (direct solve) and the conjugate gradient tolerance (Newton
//!    tolerance 1e-6): cost per frame and the error of the tip position after 20 frames of 1/60 s
//!    on a beam of E = 1e7 Pa (1.6k tetrahedra), against a reference run with the direct solve
//!    and a Newton tolerance of 1e-10.
//!
//! Run with `cargo run --release --example solver_knobs [sizes|calibrate|knobs]...` (all three
//! by default). The last line is a JSON summary.

use rapier_fvm::linear_solver::{AUTOMATIC_CG_TOLERANCE, predict};
use rapier_fvm::prelude::*;
use std::time::Instant;

fn gravity() -> DVec3 {
    DVec3::new(0.0, -9.81, 0.0)
}

/// The reference beam along +x from x = 0 (clamped), and the node at the centre of its free end.
fn beam(cells: [usize; 3], young: f64) -> Result<(DeformableBody, usize), Error> {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let mesh = mesh::cuboid(half, cells)?;
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let tip = mesh.nearest_node(DVec3::new(half.x, 0.0, 0.0)) as usize;
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0)?;
    let body = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .build()?;
    Ok((body, tip))
}

/// A soft 0.2 m cube of `n³` cells hanging from its top face.
fn soft_cube(n: usize) -> Result<DeformableBody, Error> {
    let mesh = mesh::cuboid(DVec3::splat(0.1), [n, n, n])?;
    let top = mesh.nodes_where(|p| p.y >= 0.1 - 1e-9);
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
    DeformableBodyBuilder::new(mesh, material)
        .pinned_nodes(top)
        .build()
}

/// Per-frame averages of a run.
#[derive(Debug, Clone, Copy)]
struct Run {
    ms: f64,
    /// The fastest frame (ms), less disturbed by other work on the machine.
    fastest: f64,
    newton: f64,
    cg: f64,
    converged: bool,
}

/// Times `frames` frames of `dt` after `warm_up` untimed ones (the first builds the sparsity
/// pattern and, for the direct solve, the symbolic factorization).
fn run(
    body: &mut DeformableBody,
    integrator: &ImplicitIntegrator,
    dt: f64,
    warm_up: usize,
    frames: usize,
) -> Result<Run, Error> {
    let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    for _ in 0..warm_up {
        integrator.step(body, &mut free, &mut workspace, dt, gravity())?;
    }
    let start = Instant::now();
    let (mut newton, mut cg, mut converged) = (0, 0, true);
    let mut fastest = f64::INFINITY;
    for _ in 0..frames {
        let frame = Instant::now();
        let report = integrator.step(body, &mut free, &mut workspace, dt, gravity())?;
        fastest = fastest.min(frame.elapsed().as_secs_f64() * 1e3);
        newton += report.newton_iterations;
        cg += report.linear_iterations;
        converged &= report.converged;
    }
    let n = frames as f64;
    Ok(Run {
        ms: start.elapsed().as_secs_f64() * 1e3 / n,
        fastest,
        newton: newton as f64 / n,
        cg: cg as f64 / n,
        converged,
    })
}

fn with_solver(linear_solver: LinearSolver) -> ImplicitIntegrator {
    ImplicitIntegrator {
        linear_solver,
        ..Default::default()
    }
}

fn cg(tolerance: f64, max_iterations: usize) -> LinearSolver {
    LinearSolver::ConjugateGradient {
        tolerance,
        max_iterations,
    }
}

/// Free degrees of freedom of `body`.
fn free_dofs(body: &DeformableBody) -> usize {
    3 * (0..body.node_count())
        .filter(|&n| !body.is_pinned(n))
        .count()
}

/// [`run`] on a copy of `body`, after one untimed frame.
fn run_copy(
    body: &DeformableBody,
    integrator: &ImplicitIntegrator,
    dt: f64,
    frames: usize,
) -> Result<Run, Error> {
    run(&mut body.clone(), integrator, dt, 1, frames)
}

/// Prints the header of the `sizes` table.
fn print_sizes_header() {
    println!("== direct vs conjugate gradient (CG tolerance {AUTOMATIC_CG_TOLERANCE:e})");
    println!(
        "{:>12} {:>7} {:>6} {:>6} | {:>10} {:>7} | {:>10} {:>7} {:>9} {:>5} | {:>10} {:>6} {:>8}",
        "case",
        "tets",
        "dofs",
        "√κ",
        "direct ms",
        "Newton",
        "CG ms",
        "Newton",
        "CG its",
        "conv",
        "auto ms",
        "auto",
        "pred CG"
    );
}

/// A `sizes` case: name, body, frame step (s), timed frames, conjugate gradient iteration limit.
type SizeCase = (String, DeformableBody, f64, usize, usize);

/// The cases of the `sizes` table.
fn size_cases() -> Result<Vec<SizeCase>, Error> {
    Ok(vec![
        (
            "small step".into(),
            beam([10, 2, 2], 1e8)?.0,
            2e-4,
            100,
            5000,
        ),
        (
            "beam 1.6k".into(),
            beam([20, 4, 4], 1e9)?.0,
            1.0 / 60.0,
            3,
            5000,
        ),
        (
            "beam 13k".into(),
            beam([40, 8, 8], 1e9)?.0,
            1.0 / 60.0,
            2,
            5000,
        ),
        (
            "beam 100k".into(),
            beam([80, 16, 16], 1e9)?.0,
            1.0 / 60.0,
            1,
            1000,
        ),
        ("cube 5k".into(), soft_cube(10)?, 1.0 / 240.0, 5, 5000),
        ("cube 20k".into(), soft_cube(16)?, 1.0 / 240.0, 5, 5000),
        ("cube 53k".into(), soft_cube(22)?, 1.0 / 240.0, 3, 5000),
        ("cube 98k".into(), soft_cube(27)?, 1.0 / 240.0, 3, 5000),
    ])
}

/// Times one `sizes` case with each solver; prints its row and pushes its JSON object.
fn size_case(case: SizeCase, json: &mut Vec<String>) -> Result<(), Error> {
    let (name, body, dt, frames, max_cg) = case;
    let prediction = predict(&body, dt, AUTOMATIC_CG_TOLERANCE);
    let free = free_dofs(&body);
    let direct = run_copy(&body, &with_solver(LinearSolver::Direct), dt, frames)?;
    let iterative = run_copy(
        &body,
        &with_solver(cg(AUTOMATIC_CG_TOLERANCE, max_cg)),
        dt,
        frames,
    )?;
    let automatic = run_copy(&body, &with_solver(LinearSolver::Automatic), dt, frames)?;
    let choice = if automatic.cg > 0.0 { "CG" } else { "direct" };
    let (tets, sqrt_kappa, predicted) = (
        body.mesh().tet_count(),
        prediction.condition.sqrt(),
        prediction.cg_iterations,
    );
    let (direct_ms, direct_newton, automatic_ms) = (direct.ms, direct.newton, automatic.ms);
    let (cg_ms, cg_newton, cg_its, cg_converged) = (
        iterative.ms,
        iterative.newton,
        iterative.cg,
        iterative.converged,
    );
    println!(
        "{name:>12} {tets:>7} {free:>6} {sqrt_kappa:>6.0} | {direct_ms:>10.1} {direct_newton:>7.2} | {cg_ms:>10.1} {cg_newton:>7.2} {cg_its:>9.0} {cg_converged:>5} | {automatic_ms:>10.1} {choice:>6} {predicted:>8.0}"
    );
    json.push(format!(
        "{{\"case\": \"{name}\", \"tets\": {tets}, \"free_dofs\": {free}, \"sqrt_kappa\": {sqrt_kappa:.1}, \"direct_ms\": {direct_ms:.2}, \"direct_newton\": {direct_newton:.2}, \"cg_ms\": {cg_ms:.2}, \"cg_newton\": {cg_newton:.2}, \"cg_iterations_per_frame\": {cg_its:.1}, \"cg_converged\": {cg_converged}, \"automatic_ms\": {automatic_ms:.2}, \"automatic\": \"{choice}\"}}"
    ));
    Ok(())
}

/// Part 1: the direct solve against the conjugate gradient and the automatic choice, by size.
fn sizes(json: &mut Vec<String>) -> Result<(), Error> {
    print_sizes_header();
    for case in size_cases()? {
        size_case(case, json)?;
    }
    Ok(())
}

/// Prints the header of the `calibrate` table.
fn print_calibrate_header() {
    println!("== calibration: one Newton iteration per frame");
    println!(
        "{:>12} {:>6} | {:>11} {:>11} {:>12} {:>8} | {:>9} {:>6} {:>8} {:>7}",
        "case",
        "dofs",
        "Cholesky ms",
        "mat-vec ms",
        "ratio R",
        "R/√n",
        "CG/solve",
        "√κ",
        "bound",
        "C"
    );
}

/// An integrator that stops after one Newton iteration, with `linear_solver`.
fn one_iteration(linear_solver: LinearSolver) -> ImplicitIntegrator {
    ImplicitIntegrator {
        tolerance: 1e-14,
        max_newton_iterations: 1,
        linear_solver,
        ..Default::default()
    }
}

/// Measures one `calibrate` case; prints its row and pushes its JSON object.
fn calibrate_case(
    name: &str,
    body: &DeformableBody,
    dt: f64,
    json: &mut Vec<String>,
) -> Result<(), Error> {
    let free = free_dofs(body);
    let frames = 6;
    let (few, many) = (10, 210);
    let direct = run_copy(body, &one_iteration(LinearSolver::Direct), dt, frames)?;
    let short = run_copy(body, &one_iteration(cg(1e-30, few)), dt, frames)?;
    let long = run_copy(body, &one_iteration(cg(1e-30, many)), dt, frames)?;
    // Each frame does the same work: the fastest is the least disturbed.
    let product = (long.fastest - short.fastest) / (many - few) as f64;
    let rest = short.fastest - few as f64 * product;
    let cholesky = direct.fastest - rest;
    // Iterations of a converged solve at the automatic tolerance, against the bound.
    let mut probe = body.clone();
    let solved = run(
        &mut probe,
        &with_solver(cg(AUTOMATIC_CG_TOLERANCE, 20_000)),
        dt,
        0,
        1,
    )?;
    let per_solve = solved.cg / solved.newton.max(1.0);
    let prediction = predict(body, dt, AUTOMATIC_CG_TOLERANCE);
    let bound = prediction.condition.sqrt() * (2.0 / AUTOMATIC_CG_TOLERANCE).ln() / 2.0;
    println!(
        "{name:>12} {free:>6} | {cholesky:>11.2} {product:>11.4} {:>12.1} {:>8.2} | {per_solve:>9.0} {:>6.0} {bound:>8.0} {:>7.3}",
        cholesky / product,
        cholesky / product / (free as f64).sqrt(),
        prediction.condition.sqrt(),
        per_solve / bound
    );
    json.push(format!(
        "{{\"case\": \"{name}\", \"free_dofs\": {free}, \"cholesky_ms\": {cholesky:.3}, \"matvec_ms\": {product:.5}, \"ratio\": {:.2}, \"cg_per_solve\": {per_solve:.1}, \"bound\": {bound:.1}}}",
        cholesky / product
    ));
    Ok(())
}

/// Part 2: the constants of `LinearSolver::Automatic`, measured.
fn calibrate(json: &mut Vec<String>) -> Result<(), Error> {
    print_calibrate_header();
    let cases: Vec<(String, DeformableBody, f64)> = vec![
        ("beam 1.6k".into(), beam([20, 4, 4], 1e9)?.0, 1.0 / 60.0),
        ("beam 13k".into(), beam([40, 8, 8], 1e9)?.0, 1.0 / 60.0),
        ("cube 5k".into(), soft_cube(10)?, 1.0 / 240.0),
        ("cube 20k".into(), soft_cube(16)?, 1.0 / 240.0),
        ("cube 53k".into(), soft_cube(22)?, 1.0 / 240.0),
        ("cube 98k".into(), soft_cube(27)?, 1.0 / 240.0),
        ("beam 100k".into(), beam([80, 16, 16], 1e9)?.0, 1.0 / 60.0),
    ];
    for (name, body, dt) in cases {
        calibrate_case(&name, &body, dt, json)?;
    }
    Ok(())
}

fn knobs(json: &mut Vec<String>) -> Result<(), Error> {
    let (frames, dt, young) = (20, 1.0 / 60.0, 1e7);
    let tip_after = |integrator: ImplicitIntegrator| -> Result<(DVec3, Run, f64), Error> {
        let (mut body, tip) = beam([20, 4, 4], young)?;
        let rest = body.positions()[tip];
        let run = run(&mut body, &integrator, dt, 0, frames)?;
        Ok((
            body.positions()[tip],
            run,
            (body.positions()[tip] - rest).length(),
        ))
    };
    let (reference, reference_run, displacement) = tip_after(ImplicitIntegrator {
        tolerance: 1e-10,
        linear_solver: LinearSolver::Direct,
        ..Default::default()
    })?;
    println!(
        "== tolerances: beam E = {young:e} Pa, 1.6k tets, {frames} frames of 1/60 s; reference (direct, Newton 1e-10) {:.1} ms/frame, {:.2} Newton/frame, tip moved {:.4} m",
        reference_run.ms, reference_run.newton, displacement
    );
    println!(
        "{:>22} {:>9} {:>9} {:>10} {:>14} {:>10}",
        "setting", "ms/frame", "Newton", "CG its", "tip error (m)", "relative"
    );
    let mut rows = Vec::new();
    let mut report = |label: String, integrator: ImplicitIntegrator| -> Result<(), Error> {
        let (tip, run, _) = tip_after(integrator)?;
        let error = (tip - reference).length();
        println!(
            "{label:>22} {:>9.1} {:>9.2} {:>10.1} {error:>14.3e} {:>10.2e}",
            run.ms,
            run.newton,
            run.cg,
            error / displacement
        );
        rows.push(format!(
            "{{\"setting\": \"{label}\", \"ms_per_frame\": {:.2}, \"newton_per_frame\": {:.2}, \"cg_per_frame\": {:.1}, \"tip_error_m\": {error:.3e}}}",
            run.ms, run.newton, run.cg
        ));
        Ok(())
    };
    for tolerance in [1e-2, 1e-4, 1e-6, 1e-8] {
        report(
            format!("direct, Newton {tolerance:e}"),
            ImplicitIntegrator {
                tolerance,
                linear_solver: LinearSolver::Direct,
                ..Default::default()
            },
        )?;
    }
    for tolerance in [1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8] {
        report(
            format!("CG {tolerance:e}, Newton 1e-6"),
            with_solver(cg(tolerance, 100_000)),
        )?;
    }
    report(
        "automatic, Newton 1e-6".into(),
        with_solver(LinearSolver::Automatic),
    )?;
    json.extend(rows);
    Ok(())
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let wants = |part: &str| args.is_empty() || args.iter().any(|a| a == part);
    let mut json = Vec::new();
    if wants("calibrate") {
        calibrate(&mut json)?;
    }
    if wants("sizes") {
        sizes(&mut json)?;
    }
    if wants("knobs") {
        knobs(&mut json)?;
    }
    println!("{{\"rows\": [{}]}}", json.join(", "));
    Ok(())
}

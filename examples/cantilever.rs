//! The reference cantilever: a 1 m beam (0.1 x 0.1 m, E = 1e8 Pa, ν = 0.3,
//! ρ = 1000 kg/m³) clamped at one end and sagging under gravity, against Timoshenko beam theory.
//!
//! 1. Static equilibrium (Newton + sparse Cholesky) at increasing resolution: linear tetrahedra
//!    are stiff in bending, and the table shows the error shrink as the mesh is refined.
//! 2. Explicit dynamics at 40 x 4 x 4 cells: released from rest, the undamped beam oscillates about
//!    its static shape; the tip deflection averaged over whole periods is the static deflection.
//!
//! Run with `cargo run --release --example cantilever`. The last line is a JSON summary.

use rapier_fvm::prelude::*;
use rapier_fvm::statics::{self, StaticSettings};
use std::time::Instant;

const LENGTH: f64 = 1.0;
const SIDE: f64 = 0.1;
const YOUNG: f64 = 1e8;
const POISSON: f64 = 0.3;
const DENSITY: f64 = 1000.0;
const GRAVITY: DVec3 = DVec3::new(0.0, -9.81, 0.0);

/// Timoshenko tip deflection (m): `q L⁴/(8EI) + q L²/(2κGA)`, Cowper's κ for a rectangle.
fn timoshenko() -> f64 {
    let (area, inertia) = (SIDE * SIDE, SIDE.powi(4) / 12.0);
    let q = DENSITY * area * GRAVITY.length();
    let shear = YOUNG / (2.0 * (1.0 + POISSON));
    let kappa = 10.0 * (1.0 + POISSON) / (12.0 + 11.0 * POISSON);
    q * LENGTH.powi(4) / (8.0 * YOUNG * inertia) + q * LENGTH.powi(2) / (2.0 * kappa * shear * area)
}

/// The clamped beam along +x with `cells` cubes, and the node nearest the free end's centre.
fn beam(cells: [usize; 3], model: MaterialModel) -> Result<(DeformableBody, usize), Error> {
    let half = DVec3::new(LENGTH / 2.0, SIDE / 2.0, SIDE / 2.0);
    let mesh = mesh::cuboid(half, cells)?;
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let tip = mesh.nearest_node(DVec3::new(half.x, 0.0, 0.0)) as usize;
    let material = Material::new(model, YOUNG, POISSON, DENSITY)?;
    let body = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .build()?;
    Ok((body, tip))
}

fn main() -> Result<(), Error> {
    let reference = timoshenko();
    println!(
        "Cantilever L = {LENGTH} m, {SIDE} x {SIDE} m, E = {YOUNG:e} Pa, nu = {POISSON}, rho = {DENSITY} kg/m^3"
    );
    println!("Timoshenko tip deflection: {:.3} mm\n", reference * 1e3);

    println!("Static equilibrium, linear elasticity");
    println!(
        "{:>14} {:>7} {:>11} {:>9} {:>10}",
        "cells", "tets", "tip (mm)", "error", "solve (ms)"
    );
    for n in [1, 2, 4, 6, 8] {
        let cells = [10 * n, n, n];
        let (mut body, tip) = beam(cells, MaterialModel::Linear)?;
        let start = Instant::now();
        let rest = body.positions()[tip].y;
        statics::solve_equilibrium(&mut body, GRAVITY, &StaticSettings::default())?;
        let deflection = rest - body.positions()[tip].y;
        println!(
            "{:>14} {:>7} {:>11.3} {:>8.2}% {:>10.1}",
            format!("{cells:?}"),
            body.mesh().tet_count(),
            deflection * 1e3,
            100.0 * (deflection / reference - 1.0),
            start.elapsed().as_secs_f64() * 1e3
        );
    }

    let cells = [40, 4, 4];
    let (mut body, tip) = beam(cells, MaterialModel::StVenantKirchhoff)?;
    let frequency = statics::fundamental_frequency(&body)?;
    let frame = 1.0 / 240.0;
    let frames_per_period = 1.0 / (frequency * frame);
    let periods = 3.0;
    let frames = (periods * frames_per_period).round() as usize;
    let integrator = SymplecticEuler::default();
    let rest = body.positions()[tip].y;
    println!(
        "\nExplicit dynamics, St. Venant-Kirchhoff, {cells:?} cells, {} tets",
        body.mesh().tet_count()
    );
    println!(
        "first mode {frequency:.3} Hz; {frames} frames of {:.2} ms ({periods} periods)",
        frame * 1e3
    );
    println!("{:>8} {:>10} {:>11}", "time (s)", "tip (mm)", "substeps");
    let mut deflection_sum = 0.0;
    let mut substeps = 0;
    // Nothing touches the beam; the workspace keeps the solver's caches between frames.
    let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let start = Instant::now();
    for i in 0..frames {
        let report = integrator.step(&mut body, &mut free, &mut workspace, frame, GRAVITY)?;
        substeps = report.substeps;
        let deflection = rest - body.positions()[tip].y;
        deflection_sum += deflection;
        if i % (frames / 12).max(1) == 0 {
            println!(
                "{:>8.3} {:>10.3} {:>11}",
                (i + 1) as f64 * frame,
                deflection * 1e3,
                report.substeps
            );
        }
    }
    let wall = start.elapsed().as_secs_f64();
    let ms_per_step = wall * 1e3 / frames as f64;
    let mean = deflection_sum / frames as f64;
    let rel_error = mean / reference - 1.0;
    println!(
        "mean tip deflection over {periods} periods: {:.3} mm ({:+.2}% vs Timoshenko); {ms_per_step:.2} ms per {:.2} ms step ({substeps} substeps)",
        mean * 1e3,
        100.0 * rel_error,
        frame * 1e3
    );
    println!(
        "{{\"tip_deflection_m\": {mean:.6e}, \"reference_m\": {reference:.6e}, \"rel_error\": {rel_error:.4}, \"tets\": {}, \"nodes\": {}, \"ms_per_step\": {ms_per_step:.3}, \"step_s\": {frame:.6}, \"substeps\": {substeps}, \"first_mode_hz\": {frequency:.4}}}",
        body.mesh().tet_count(),
        body.node_count()
    );
    Ok(())
}

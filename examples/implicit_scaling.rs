//! Implicit integration cost on the stiff reference beam (L = 1 m, 0.1 x 0.1 m, E = 1e9 Pa,
//! ν = 0.3, ρ = 1000 kg/m³, stable Neo-Hookean) at about 1.6k, 13k and 100k tetrahedra, frames
//! of 1/60 s with backward Euler, beside the substeps the explicit integrator would need; then the
//! Young's modulus at which the automatic choice switches from explicit to implicit for a beam
//! of 1 cm cells.
//!
//! Run with `cargo run --release --example implicit_scaling`. The last line is a JSON summary.

use rapier_fvm::prelude::*;
use std::time::Instant;

fn beam(cells: [usize; 3], young: f64) -> Result<DeformableBody, Error> {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let mesh = mesh::cuboid(half, cells)?;
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.3, 1000.0)?;
    DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .build()
}

fn main() -> Result<(), Error> {
    let gravity = DVec3::new(0.0, -9.81, 0.0);
    let frame = 1.0 / 60.0;
    let frames = 3;
    println!(
        "{:>14} {:>8} {:>8} {:>13} {:>16} {:>18}",
        "cells", "tets", "nodes", "ms/frame", "Newton/frame", "explicit substeps"
    );
    let mut rows = Vec::new();
    for cells in [[20, 4, 4], [40, 8, 8], [80, 16, 16]] {
        let mut body = beam(cells, 1e9)?;
        let automatic = AutomaticIntegrator::default();
        let explicit_substeps = automatic.predict(&body, frame).explicit_substeps;
        let integrator = ImplicitIntegrator::default();
        // The first frame also builds the sparsity pattern and its symbolic factorization.
        let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
        integrator.step(&mut body, &mut free, &mut workspace, frame, gravity)?;
        let start = Instant::now();
        let mut iterations = 0;
        for _ in 0..frames {
            iterations += integrator
                .step(&mut body, &mut free, &mut workspace, frame, gravity)?
                .newton_iterations;
        }
        let ms = start.elapsed().as_secs_f64() * 1e3 / frames as f64;
        let per_frame = iterations as f64 / frames as f64;
        println!(
            "{:>14} {:>8} {:>8} {ms:>13.1} {per_frame:>16.1} {explicit_substeps:>18.0}",
            format!("{cells:?}"),
            body.mesh().tet_count(),
            body.node_count()
        );
        rows.push(format!(
            "{{\"tets\": {}, \"ms_per_frame\": {ms:.2}, \"newton_per_frame\": {per_frame:.2}, \"explicit_substeps\": {explicit_substeps}}}",
            body.mesh().tet_count()
        ));
    }
    // Crossover at 1 cm cells (100 x 10 x 10 cubes, 50 000 tetrahedra): the smallest E on a
    // factor-1.25 grid at which the predicted implicit frame is cheaper.
    let mut crossover = f64::NAN;
    let mut young = 1e3;
    while young < 1e12 {
        let body = beam([100, 10, 10], young)?;
        let prediction = AutomaticIntegrator::default().predict(&body, frame);
        if prediction.cheaper() == IntegratorKind::Implicit {
            crossover = young;
            println!(
                "1 cm cells, frames of 1/60 s: implicit becomes cheaper at E = {young:.3e} Pa ({:.0} explicit substeps, predicted {:.1} ms explicit vs {:.1} ms implicit)",
                prediction.explicit_substeps,
                prediction.explicit_seconds * 1e3,
                prediction.implicit_seconds * 1e3
            );
            break;
        }
        young *= 1.25;
    }
    println!(
        "{{\"frames\": [{}], \"crossover_young_modulus_pa\": {crossover:.4e}}}",
        rows.join(", ")
    );
    Ok(())
}

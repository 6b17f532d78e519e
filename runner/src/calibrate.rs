//! `rapier-fvm calibrate`: measures the automatic integrator's [`CostModel`] on this machine.
//!
//! A soft cube (10 cm, 6 cells a side, 1 080 tetrahedra, E = 1e5 Pa, ν = 0.3, 1000 kg/m³) is
//! stepped in 1/60 s frames of one coupling substep, each integrator forced:
//!
//! - spinning free in zero gravity, explicit: seconds per tetrahedron per substep, undamped for
//!   the stable Neo-Hookean and the corotated models, then damped (the damping factor);
//! - dropped 2 cm onto the ground and left to settle, explicit: what the substeps cost beyond
//!   their tetrahedra, per contact point (found at each frame's start) per substep;
//! - the same drop, implicit: seconds per tetrahedron per Newton iteration for both models, and
//!   the Newton iterations per step; then with 16 cells a side (20 480 tetrahedra): how the
//!   cost per tetrahedron grows with the body's size.
//!
//! Each time is the whole frame (rapier's step and contact detection included), the fastest of
//! three runs, on the threads rayon is given. The result prints as a scene's `[integrator.cost]`
//! table.

use rapier_fvm::integrate::{CostModel, IntegratorKind};
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, SharedShape, Vector};
use std::time::Instant;

/// Frames each case is stepped (1 s of 1/60 s frames).
const FRAMES: usize = 60;

/// Runs of each case; the fastest counts (the others met other load on the machine).
const RUNS: usize = 3;

/// What a case measured over its frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct Sample {
    /// Seconds of stepping.
    pub seconds: f64,
    /// Tetrahedra of the body.
    pub tets: f64,
    /// Explicit substeps taken, summed over the frames.
    pub substeps: f64,
    /// Contact points found at the frames' start times their substeps, summed over the frames.
    pub contact_substeps: f64,
    /// Newton iterations, summed over the frames.
    pub newton_iterations: f64,
    /// Implicit substeps, summed over the frames.
    pub implicit_substeps: f64,
}

/// A calibration case: the material model, damping, whether the cube drops onto the ground
/// (else it spins free in zero gravity), the integrator forced, and the cells a side.
#[derive(Debug, Clone, Copy)]
struct Case {
    model: MaterialModel,
    damped: bool,
    dropped: bool,
    force: IntegratorKind,
    cells: usize,
}

/// Measures the cost model, printing each case's figures through `log`.
///
/// # Errors
/// A step's error (none is expected of these cases).
pub fn calibrate(mut log: impl FnMut(&str)) -> Result<CostModel, Error> {
    use IntegratorKind::{Explicit, Implicit};
    use MaterialModel::{Corotated, StableNeoHookean};
    let case = |model, damped, dropped, force| Case {
        model,
        damped,
        dropped,
        force,
        cells: 6,
    };
    let mut fastest = |c: Case, name: &str| -> Result<Sample, Error> {
        let mut best = measure(c)?;
        for _ in 1..RUNS {
            let sample = measure(c)?;
            if sample.seconds < best.seconds {
                best = sample;
            }
        }
        log(&format!(
            "{name:<34} {:>8.2} ms/frame  {:>7.1} substeps  {:>7.1} contact points  {:>5.2} Newton/step",
            best.seconds * 1e3 / FRAMES as f64,
            best.substeps / FRAMES as f64,
            best.contact_substeps / best.substeps.max(1.0),
            best.newton_iterations / best.implicit_substeps.max(1.0),
        ));
        Ok(best)
    };
    let free = fastest(
        case(StableNeoHookean, false, false, Explicit),
        "explicit, free",
    )?;
    let damped = fastest(
        case(StableNeoHookean, true, false, Explicit),
        "explicit, free, damped",
    )?;
    let corotated = fastest(
        case(Corotated, false, false, Explicit),
        "explicit, free, corotated",
    )?;
    let dropped = fastest(
        case(StableNeoHookean, false, true, Explicit),
        "explicit, dropped",
    )?;
    let newton = fastest(
        case(StableNeoHookean, false, true, Implicit),
        "implicit, dropped",
    )?;
    let newton_corotated = fastest(
        case(Corotated, false, true, Implicit),
        "implicit, dropped, corotated",
    )?;
    let larger = Case {
        cells: 16,
        ..case(StableNeoHookean, false, true, Implicit)
    };
    let newton_larger = fastest(larger, "implicit, dropped, 16 cells a side")?;
    let per_tet_substep = |s: &Sample| s.seconds / (s.tets * s.substeps);
    let explicit_tet = per_tet_substep(&free);
    let per_tet_iteration = |s: &Sample| s.seconds / (s.tets * s.newton_iterations);
    let contact_seconds = dropped.seconds - explicit_tet * dropped.tets * dropped.substeps;
    // Per tetrahedron per iteration c (T/1000)^α at both sizes: α from their ratio, c at 1000.
    let (small, large) = (
        per_tet_iteration(&newton),
        per_tet_iteration(&newton_larger),
    );
    let exponent = ((large / small).ln() / (newton_larger.tets / newton.tets).ln()).clamp(0.0, 1.0);
    let at_thousand = |s: &Sample| per_tet_iteration(s) / (s.tets / 1000.0).powf(exponent);
    Ok(CostModel {
        explicit_tet,
        explicit_tet_corotated: per_tet_substep(&corotated),
        explicit_damped_factor: (per_tet_substep(&damped) / explicit_tet).max(1.0),
        explicit_contact_point: (contact_seconds / dropped.contact_substeps.max(1.0)).max(0.0),
        newton_tet: at_thousand(&newton),
        newton_size_exponent: exponent,
        newton_tet_corotated: at_thousand(&newton_corotated),
        newton_iterations: newton.newton_iterations / newton.implicit_substeps.max(1.0),
    })
}

/// The cost model as a scene's `[integrator.cost]` table.
pub fn as_toml(cost: &CostModel) -> String {
    let rows = [
        (
            "explicit_tet",
            cost.explicit_tet,
            "s per tetrahedron per explicit substep",
        ),
        (
            "explicit_tet_corotated",
            cost.explicit_tet_corotated,
            "the same, corotated model",
        ),
        (
            "explicit_damped_factor",
            cost.explicit_damped_factor,
            "damped over undamped",
        ),
        (
            "explicit_contact_point",
            cost.explicit_contact_point,
            "s per contact point per sweep per substep",
        ),
        (
            "newton_tet",
            cost.newton_tet,
            "s per tetrahedron per Newton iteration at 1000 tetrahedra",
        ),
        (
            "newton_size_exponent",
            cost.newton_size_exponent,
            "per-tetrahedron Newton cost grows as (T/1000)^this",
        ),
        (
            "newton_tet_corotated",
            cost.newton_tet_corotated,
            "the same, corotated model",
        ),
        (
            "newton_iterations",
            cost.newton_iterations,
            "per implicit substep, until a body has its own",
        ),
    ];
    let mut table = String::from("[integrator.cost]\n");
    for (key, value, about) in rows {
        table += &format!("{:<36} # {about}\n", format!("{key} = {value:.4e}"));
    }
    table
}

/// Steps one case for [`FRAMES`] frames and adds up what it took.
fn measure(case: Case) -> Result<Sample, Error> {
    let mut world = FvmWorld::default();
    world.coupling.substeps = 1;
    world.coupling.integrator.force = Some(case.force);
    let half = 0.05;
    let mut translation = DVec3::new(0.0, 1.0, 0.0);
    if case.dropped {
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.5),
            None,
        );
        translation.y = half + 0.02;
    } else {
        world.physics.gravity = Vector::ZERO;
    }
    let material = Material::new(case.model, 1e5, 0.3, 1000.0)?;
    let mut builder =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(half), [case.cells; 3])?, material)
            .translation(translation);
    if case.damped {
        builder = builder.damping(RayleighDamping::stiffness_proportional(
            2e-3,
            material.lame(),
        )?);
    }
    if !case.dropped {
        builder = builder.angvel(DVec3::new(0.0, 5.0, 0.0));
    }
    let body = builder.build()?;
    let tets = body.mesh().tet_count() as f64;
    let handle = world.soft_bodies.insert(body);
    let mut sample = Sample {
        tets,
        ..Sample::default()
    };
    for _ in 0..FRAMES {
        let start = Instant::now();
        let results = world.step();
        sample.seconds += start.elapsed().as_secs_f64();
        for (h, result) in results {
            let report = result?;
            if h != handle {
                continue;
            }
            if let Some(explicit) = report.explicit {
                let substeps = f64::from(explicit.substeps);
                sample.substeps += substeps;
                sample.contact_substeps += substeps * report.prediction.contact_points as f64;
            }
            if let Some(implicit) = report.implicit {
                sample.newton_iterations += implicit.newton_iterations as f64;
                sample.implicit_substeps += f64::from(implicit.substeps);
            }
        }
    }
    Ok(sample)
}

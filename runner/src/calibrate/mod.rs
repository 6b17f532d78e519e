//! `rapier-fvm calibrate`: measures the automatic integrator's [`CostModel`] on this machine.
//!
//! A soft cube (10 cm, 6 cells a side, 1 080 tetrahedra, E = 1e5 Pa, ν = 0.3, 1000 kg/m³) is
//! stepped in 1/60 s frames of one coupling substep, each integrator forced:
//!
//! - spinning free in zero gravity, explicit: seconds per tetrahedron per substep, undamped for
//!   the stable Neo-Hookean and the corotated models, then damped (the damping factor);
//! - dropped 2 cm onto the ground and left to settle, explicit: what the substeps cost beyond
//!   their tetrahedra, per contact point (found at each frame's start) per substep;
//! - implicit, cases that mix the implicit work differently: the drop solved directly, with the
//!   factorization reused and without, and with 12 cells a side (8 640 tetrahedra); the drop by
//!   the automatic linear solver (the conjugate gradient, at 6 and 16 cells a side, 20 480
//!   tetrahedra); the cube resting on the ground under four 100 g boxes (dynamic rigid
//!   partners, whose response each energy evaluation solves), at 6 and 3 cells a side (135
//!   tetrahedra). Every implicit frame's integration time (the automatic report's) and work are
//!   fitted together ([`fit`]); the corotated drop, against the same drop of the stable
//!   Neo-Hookean model, gives its Newton iteration.
//!
//! Explicit times are whole frames (rapier's step and contact detection included); each case's
//! run is the fastest of three, on the threads rayon is given. The result prints as a scene's
//! `[integrator.cost]` table.

mod fit;

pub use fit::ImplicitFrame;
use rapier_fvm::integrate::{CostModel, IntegratorKind};
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape, Vector};
use std::time::Instant;

/// Frames each case is stepped (1 s of 1/60 s frames).
const FRAMES: usize = 60;

/// Runs of each case; the fastest counts (the others met other load on the machine).
const RUNS: usize = 3;

/// What a case measured over its frames.
#[derive(Debug, Clone, Default)]
pub struct Sample {
    /// Seconds of stepping (whole frames).
    pub seconds: f64,
    /// Tetrahedra of the body.
    pub tets: f64,
    /// Explicit substeps taken, summed over the frames.
    pub substeps: f64,
    /// Contact points found at the frames' start times their substeps, summed over the frames.
    pub contact_substeps: f64,
    /// Implicit substeps, summed over the frames.
    pub implicit_substeps: f64,
    /// Each implicit frame's integration time and work.
    pub implicit_frames: Vec<ImplicitFrame>,
}

/// A calibration case: the material model, damping, the cube's start (free, dropped, or
/// resting under boxes), the integrator forced, the cells a side, and the implicit
/// integrator's linear solver and factorization reuse.
#[derive(Debug, Clone, Copy)]
struct Case {
    model: MaterialModel,
    damped: bool,
    start: Start,
    force: IntegratorKind,
    cells: usize,
    solver: LinearSolver,
    reuse: bool,
}

/// Where a case's cube starts.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Start {
    /// Spinning at 5 rad/s in zero gravity.
    Free,
    /// 2 cm above the ground.
    Dropped,
    /// On the ground under four 4 cm boxes of 100 g.
    UnderBoxes,
}

/// Measures the cost model, printing each case's figures through `log`.
///
/// # Errors
/// A step's error (none is expected of these cases).
pub fn calibrate(mut log: impl FnMut(&str)) -> Result<CostModel, Error> {
    let explicit = explicit_constants(&mut log)?;
    let implicit = implicit_constants(&mut log)?;
    Ok(CostModel {
        explicit_tet: explicit.explicit_tet,
        explicit_tet_corotated: explicit.explicit_tet_corotated,
        explicit_damped_factor: explicit.explicit_damped_factor,
        explicit_contact_point: explicit.explicit_contact_point,
        ..implicit
    })
}

/// A case of the stable Neo-Hookean or corotated `model` on 6 cells a side, undamped unless
/// `damped`, from `start`, with `force`d integrator and the automatic linear solver.
fn case(model: MaterialModel, damped: bool, start: Start, force: IntegratorKind) -> Case {
    Case {
        model,
        damped,
        start,
        force,
        cells: 6,
        solver: LinearSolver::Automatic,
        reuse: true,
    }
}

/// The fastest of [`RUNS`] runs of `case`, its line (named `name`) given to `log`.
fn fastest(case: Case, name: &str, log: &mut impl FnMut(&str)) -> Result<Sample, Error> {
    let mut best = measure(case)?;
    for _ in 1..RUNS {
        let sample = measure(case)?;
        if sample.seconds < best.seconds {
            best = sample;
        }
    }
    log(&describe(&best, name));
    Ok(best)
}

/// The explicit constants (the rest [`CostModel::default`]'s): per tetrahedron per substep
/// spinning free, undamped, damped and corotated, and per contact point from the drop.
fn explicit_constants(log: &mut impl FnMut(&str)) -> Result<CostModel, Error> {
    use MaterialModel::{Corotated, StableNeoHookean};
    let explicit = |model, damped, start| case(model, damped, start, IntegratorKind::Explicit);
    let free = fastest(
        explicit(StableNeoHookean, false, Start::Free),
        "explicit, free",
        log,
    )?;
    let damped = fastest(
        explicit(StableNeoHookean, true, Start::Free),
        "explicit, free, damped",
        log,
    )?;
    let corotated = fastest(
        explicit(Corotated, false, Start::Free),
        "explicit, free, corotated",
        log,
    )?;
    let dropped = fastest(
        explicit(StableNeoHookean, false, Start::Dropped),
        "explicit, dropped",
        log,
    )?;
    let per_tet_substep = |s: &Sample| s.seconds / (s.tets * s.substeps);
    let explicit_tet = per_tet_substep(&free);
    let contact_seconds = dropped.seconds - explicit_tet * dropped.tets * dropped.substeps;
    Ok(CostModel {
        explicit_tet,
        explicit_tet_corotated: per_tet_substep(&corotated),
        explicit_damped_factor: (per_tet_substep(&damped) / explicit_tet).max(1.0),
        explicit_contact_point: (contact_seconds / dropped.contact_substeps.max(1.0)).max(0.0),
        ..CostModel::default()
    })
}

/// The implicit constants (the rest [`CostModel::default`]'s): the frames of the implicit
/// cases fitted together ([`fit::fit`]), the corotated drop's against the same drop's with the
/// stable Neo-Hookean model for its Newton iteration, and the Newton iterations a substep of
/// that drop (by the automatic linear solver) as the assumption.
fn implicit_constants(log: &mut impl FnMut(&str)) -> Result<CostModel, Error> {
    let automatic = case(
        MaterialModel::StableNeoHookean,
        false,
        Start::Dropped,
        IntegratorKind::Implicit,
    );
    let direct = Case {
        solver: LinearSolver::Direct,
        ..automatic
    };
    let under_boxes = Case {
        start: Start::UnderBoxes,
        ..direct
    };
    let cases = [
        (direct, "implicit, dropped, direct"),
        (
            Case {
                reuse: false,
                ..direct
            },
            "implicit, dropped, direct, no reuse",
        ),
        (
            Case {
                cells: 12,
                ..direct
            },
            "implicit, dropped, direct, 12 cells",
        ),
        (automatic, "implicit, dropped"),
        (
            Case {
                cells: 16,
                ..automatic
            },
            "implicit, dropped, 16 cells",
        ),
        (under_boxes, "implicit, under boxes, direct"),
        (
            Case {
                cells: 3,
                ..under_boxes
            },
            "implicit, under boxes, direct, 3 cells",
        ),
    ];
    let mut frames = Vec::new();
    let (mut newton_iterations, mut paired) = (1.0, Vec::new());
    for (c, name) in cases {
        let sample = fastest(c, name, log)?;
        if c.solver == LinearSolver::Automatic && c.cells == 6 {
            let iterations: f64 = (sample.implicit_frames.iter())
                .map(|f| f.newton_iterations)
                .sum();
            newton_iterations = iterations / sample.implicit_substeps.max(1.0);
            paired.clone_from(&sample.implicit_frames);
        }
        frames.extend(sample.implicit_frames);
    }
    let corotated = Case {
        model: MaterialModel::Corotated,
        ..automatic
    };
    let corotated = fastest(corotated, "implicit, dropped, corotated", log)?;
    Ok(CostModel {
        newton_iterations,
        ..fit::fit(&frames, (&corotated.implicit_frames, &paired))
    })
}

/// A case's line: its time and work per frame (the implicit work per substep).
fn describe(sample: &Sample, name: &str) -> String {
    let mut line = format!(
        "{name:<38} {:>8.2} ms/frame",
        sample.seconds * 1e3 / FRAMES as f64
    );
    if sample.implicit_frames.is_empty() {
        line += &format!(
            " {:>7.1} substeps {:>6.1} contact points",
            sample.substeps / FRAMES as f64,
            sample.contact_substeps / sample.substeps.max(1.0),
        );
    } else {
        let per_substep = |count: fn(&ImplicitFrame) -> f64| {
            sample.implicit_frames.iter().map(count).sum::<f64>()
                / sample.implicit_substeps.max(1.0)
        };
        line += &format!(
            " {:>5.2} Newton {:>5.2} factorizations {:>6.1} CG iterations {:>5.2} energy evaluations a substep",
            per_substep(|f| f.newton_iterations),
            per_substep(|f| f.factorizations),
            per_substep(|f| f.linear_iterations),
            per_substep(|f| f.energy_evaluations),
        );
    }
    line
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
            "s per tetrahedron per Newton iteration beyond its factorization, at 1000 tetrahedra",
        ),
        (
            "newton_size_exponent",
            cost.newton_size_exponent,
            "per-tetrahedron Newton and factorization costs grow as (T/1000)^this",
        ),
        (
            "newton_tet_corotated",
            cost.newton_tet_corotated,
            "the same, corotated model",
        ),
        (
            "factorization_tet",
            cost.factorization_tet,
            "s per tetrahedron per factorization with its assembly at 1000 tetrahedra",
        ),
        (
            "energy_evaluation",
            cost.energy_evaluation,
            "s per evaluation of the energy, whatever the size",
        ),
        (
            "partner_evaluation",
            cost.partner_evaluation,
            "s per evaluation of the energy per dynamic rigid body touched",
        ),
        (
            "conjugate_gradient_iteration",
            cost.conjugate_gradient_iteration,
            "s per conjugate gradient iteration",
        ),
        (
            "conjugate_gradient_tet",
            cost.conjugate_gradient_tet,
            "s per tetrahedron per conjugate gradient iteration",
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
    let (mut world, handle) = world_of(case)?;
    let tets = world.soft_bodies[handle].mesh().tet_count() as f64;
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
                sample.implicit_substeps += f64::from(implicit.substeps);
                sample.implicit_frames.push(ImplicitFrame {
                    seconds: report.seconds,
                    tets,
                    newton_iterations: implicit.newton_iterations as f64,
                    factorizations: implicit.factorizations as f64,
                    linear_iterations: implicit.linear_iterations as f64,
                    energy_evaluations: implicit.energy_evaluations as f64,
                    rigid_partners: report.prediction.rigid_partners as f64,
                });
            }
        }
    }
    Ok(sample)
}

/// The world of `case`: its cube (and ground, and boxes), frames of one coupling substep, the
/// case's integrator forced.
fn world_of(case: Case) -> Result<(FvmWorld, DeformableBodyHandle), Error> {
    let mut world = FvmWorld::default();
    world.coupling.substeps = 1;
    world.coupling.integrator.force = Some(case.force);
    world.coupling.integrator.implicit.linear_solver = case.solver;
    world.coupling.integrator.implicit.reuse_factorization = case.reuse;
    let half = 0.05;
    let mut translation = DVec3::new(0.0, 1.0, 0.0);
    if case.start == Start::Free {
        world.physics.gravity = Vector::ZERO;
    } else {
        world.physics.insert_collider(
            ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.5),
            None,
        );
        translation.y = if case.start == Start::Dropped {
            half + 0.02
        } else {
            half
        };
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
    if case.start == Start::Free {
        builder = builder.angvel(DVec3::new(0.0, 5.0, 0.0));
    }
    let handle = world.soft_bodies.insert(builder.build()?);
    if case.start == Start::UnderBoxes {
        // Four 4 cm boxes side by side on the top face, 1 mm above it.
        let side = 0.02f32;
        for k in 0..4 {
            let x = (side + 0.001) * if k % 2 == 0 { -1.0 } else { 1.0 };
            let z = (side + 0.001) * if k < 2 { -1.0 } else { 1.0 };
            let y = 2.0 * half as f32 + side + 0.001;
            let body = RigidBodyBuilder::dynamic()
                .translation(Vector::new(x, y, z))
                .build();
            let body = world.physics.bodies.insert(body);
            let collider = ColliderBuilder::cuboid(side, side, side).mass(0.1).build();
            (world.physics.colliders).insert_with_parent(collider, body, &mut world.physics.bodies);
        }
    }
    Ok((world, handle))
}

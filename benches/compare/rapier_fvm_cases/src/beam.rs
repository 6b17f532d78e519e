//! Scenes 1-3 on the clamped beam (x = 0 face pinned, gravity -y): static tip deflection over
//! the knobs at two steps (`cantilever`), over Poisson's ratio (`poisson`), and the undamped
//! vibration released straight under gravity (`vibration`).

use crate::budget::{CASE_LIMIT_S, Deadline};
use crate::knobs::{self, Body, Stepper};
use crate::record::{self, Record};
use compare_common::beam::{
    SETTLE_S, StaticTip, VIBRATION_S, vibration_fields, vibration_settings,
};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use rapier_fvm::element::ElementOrder::{Linear as Lin, Quadratic as Quad};
use rapier_fvm::prelude::*;
use serde_json::json;
use std::f64::consts::PI;

/// The corotated model (the crate's choice for games).
const COROTATED: MaterialModel = MaterialModel::Corotated;
/// Linear elasticity (small deflection).
const LINEAR: MaterialModel = MaterialModel::Linear;

/// The static cases of scene 1, run at both steps: resolutions of each order, the material
/// models, nodal averaging, both implicit schemes, looser Newton tolerances, and explicit steps.
const CANTILEVER: &[(Body, Stepper)] = &[
    (Body::new(Lin, [10, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Lin, [20, 2, 2], COROTATED), Stepper::BE),
    (Body::new(Lin, [40, 4, 4], COROTATED), Stepper::BE),
    (
        Body::new(Lin, [20, 2, 2], COROTATED).with_volumetric(NODAL),
        Stepper::BE,
    ),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Quad, [10, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Quad, [20, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Quad, [20, 2, 2], COROTATED), Stepper::BE),
    (Body::new(Quad, [10, 1, 1], COROTATED), Stepper::BDF2),
    (Body::new(Quad, [20, 1, 1], COROTATED), Stepper::BDF2),
    (Body::new(Quad, [5, 1, 1], LINEAR), Stepper::BE),
    (Body::new(Quad, [10, 1, 1], LINEAR), Stepper::BE),
    (Body::new(Quad, [20, 1, 1], LINEAR), Stepper::BE),
    (Body::new(Quad, [10, 1, 1], COROTATED), BE_TOL_1E3),
    (Body::new(Quad, [10, 1, 1], COROTATED), BE_TOL_1E4),
    (Body::new(Lin, [10, 1, 1], COROTATED), Stepper::Explicit),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::Explicit),
];

/// The `--quick` subset of [`CANTILEVER`]: the coarsest body of each order.
const CANTILEVER_QUICK: &[(Body, Stepper)] = &[
    (Body::new(Lin, [10, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::BE),
];

/// The bodies of scene 2, each run at every ν of the sweep (backward Euler, 1/240 s): linear
/// tetrahedra per element and nodally averaged, quadratic per element and with the element
/// average (mean dilatation, two elements across the section).
const POISSON: &[Body] = &[
    Body::new(Lin, [20, 2, 2], COROTATED),
    Body::new(Lin, [20, 2, 2], COROTATED).with_volumetric(NODAL),
    Body::new(Quad, [10, 1, 1], COROTATED),
    Body::new(Quad, [10, 2, 2], COROTATED).with_volumetric(ELEMENT_AVERAGE),
];

/// The `--quick` subset of [`POISSON`].
const POISSON_QUICK: &[Body] = &[
    Body::new(Lin, [10, 1, 1], COROTATED),
    Body::new(Quad, [5, 1, 1], COROTATED),
];

/// The cases of scene 3, each run at every step: both implicit schemes and explicit steps, on
/// the peers' linear resolution and on quadratic beams.
const VIBRATION: &[(Body, Stepper)] = &[
    (Body::new(Lin, [20, 2, 2], COROTATED), Stepper::BE),
    (Body::new(Lin, [20, 2, 2], COROTATED), Stepper::BDF2),
    (Body::new(Lin, [20, 2, 2], COROTATED), Stepper::Explicit),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::BDF2),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::Explicit),
    (Body::new(Quad, [10, 1, 1], COROTATED), Stepper::BE),
    (Body::new(Quad, [10, 1, 1], COROTATED), Stepper::BDF2),
    (Body::new(Quad, [10, 1, 1], LINEAR), Stepper::BDF2),
];

/// The `--quick` subset of [`VIBRATION`].
const VIBRATION_QUICK: &[(Body, Stepper)] = &[
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::BDF2),
    (Body::new(Quad, [5, 1, 1], COROTATED), Stepper::Explicit),
];

/// Nodal averaging of the volumetric term (linear tetrahedra).
const NODAL: VolumetricTreatment = VolumetricTreatment::NodalAverage;
/// Mean dilatation per element (quadratic tetrahedra).
const ELEMENT_AVERAGE: VolumetricTreatment = VolumetricTreatment::ElementAverage;
/// Backward Euler with looser Newton tolerances.
const BE_TOL_1E3: Stepper = Stepper::Implicit(ImplicitScheme::BackwardEuler, 1e-3);
/// Backward Euler with a Newton tolerance of 1e-4.
const BE_TOL_1E4: Stepper = Stepper::Implicit(ImplicitScheme::BackwardEuler, 1e-4);

/// The gravity of every scene (m/s²).
pub const GRAVITY: DVec3 = DVec3::new(0.0, -G, 0.0);

/// Scene 1: static tip deflection at dt = 1/240 and 1/60 over the knobs.
pub fn scene_cantilever(quick: bool) {
    let cases = if quick { CANTILEVER_QUICK } else { CANTILEVER };
    for dt in [1.0 / 240.0, 1.0 / 60.0] {
        for &(body, stepper) in cases {
            static_case("cantilever", body, stepper, dt, BEAM_NU);
        }
    }
}

/// Scene 2: the static case over Poisson's ratio, dt = 1/240, backward Euler.
pub fn scene_poisson(quick: bool) {
    let bodies = if quick { POISSON_QUICK } else { POISSON };
    for &body in bodies {
        for nu in POISSON_SWEEP {
            static_case("poisson", body, Stepper::BE, 1.0 / 240.0, nu);
        }
    }
}

/// Scene 3: the undamped beam released straight under gravity oscillates about its static
/// deflection for 2 s; a damped-oscillation fit gives its first frequency and damping ratio.
pub fn scene_vibration(quick: bool) {
    let (cases, dts): (&[(Body, Stepper)], &[f64]) = if quick {
        (VIBRATION_QUICK, &[1.0 / 240.0])
    } else {
        (VIBRATION, &[1.0 / 1000.0, 1.0 / 240.0, 1.0 / 60.0])
    };
    for &(body, stepper) in cases {
        for &dt in dts {
            vibration_case(body, stepper, dt);
        }
    }
}

/// The mean vertical displacement of the tip-face nodes after every step of a beam run.
struct BeamRun {
    ts: Vec<f64>,
    us: Vec<f64>,
    timer: Timer,
    /// Newton iterations (implicit) or substeps (explicit) summed over the steps, their
    /// largest, and the steps that did not meet the Newton tolerance.
    work_sum: usize,
    work_max: usize,
    unconverged: usize,
    /// The library's error that ended the run early, if any.
    failure: Option<String>,
    nodes: usize,
    dofs: usize,
}

impl BeamRun {
    /// Finite and within 100 m to the end, without a failed step.
    fn completed(&self) -> bool {
        self.failure.is_none()
    }

    /// The solver's work per step, for the line.
    fn work_fields(&self, stepper: Stepper) -> serde_json::Value {
        let steps = self.ts.len().max(1) as f64;
        let unit = match stepper {
            Stepper::Implicit(..) => "Newton iterations",
            Stepper::Explicit => "explicit substeps",
        };
        json!({
            "work_unit": unit,
            "work_per_step": self.work_sum as f64 / steps,
            "work_max": self.work_max,
            "unconverged_steps": self.unconverged,
        })
    }
}

/// Runs the beam for `t_end` at step `dt`, every step timed on this thread's CPU clock; `Err`
/// with the reason when the budget stops it.
fn run_beam(
    body: Body,
    stepper: Stepper,
    dt: f64,
    nu: f64,
    beta: Option<f64>,
    t_end: f64,
) -> Result<BeamRun, String> {
    let deadline = Deadline::start(CASE_LIMIT_S);
    let half = DVec3::new(BEAM_L / 2.0, BEAM_H / 2.0, BEAM_B / 2.0);
    let material = Material::new(body.model, BEAM_E, nu, BEAM_RHO).map_err(|e| e.to_string())?;
    let mut soft = body
        .build(half, DVec3::X * half.x, material, beta, |p| p.x <= 1e-9)
        .and_then(|b| b.build())
        .map_err(|e| format!("could not build the beam: {e}"))?;
    let tip = knobs::nodes_where(&soft, |p| p.x >= BEAM_L - 1e-9);
    let y0: Vec<f64> = tip.iter().map(|&n| soft.positions()[n].y).collect();
    let steps = (t_end / dt).round() as usize;
    let mut run = BeamRun {
        ts: Vec::with_capacity(steps),
        us: Vec::with_capacity(steps),
        timer: Timer::new(CpuClock::Thread),
        work_sum: 0,
        work_max: 0,
        unconverged: 0,
        failure: None,
        nodes: soft.node_count(),
        dofs: knobs::dofs(&soft),
    };
    let mut workspace = SolverWorkspace::new();
    for k in 0..steps {
        match run
            .timer
            .time(|| stepper.step(&mut soft, &mut workspace, dt, GRAVITY))
        {
            Ok(work) => {
                run.work_sum += work.iterations;
                run.work_max = run.work_max.max(work.iterations);
                run.unconverged += usize::from(!work.converged);
            }
            // Not an instability: the explicit integrator refuses a frame past `max_substeps`.
            Err(e @ Error::TooManySubsteps { .. }) => {
                return Err(format!("explicit integration refused: {e}"));
            }
            Err(e) => {
                run.failure = Some(e.to_string());
                break;
            }
        }
        if !knobs::body_ok(&soft) {
            run.failure = Some("a node went non-finite or beyond 100 m".into());
            break;
        }
        let u: f64 = tip
            .iter()
            .zip(&y0)
            .map(|(&n, y0)| soft.positions()[n].y - y0)
            .sum();
        run.ts.push((k + 1) as f64 * dt);
        run.us.push(u / tip.len() as f64);
        deadline.check(k + 1, steps)?;
    }
    Ok(run)
}

/// `1/240`.
fn dt_label(dt: f64) -> String {
    format!("1/{}", (1.0 / dt).round())
}

/// The line's head: scene, case label, series and settings (`extra` added to them).
fn beam_record(
    scene: &str,
    body: Body,
    stepper: Stepper,
    (dt, nu): (f64, f64),
    extra: Record,
) -> Record {
    let case = format!(
        "{} {} {} {} dt={} nu={nu}",
        body.order_name(),
        body.resolution(),
        body.constitutive(),
        stepper.label(),
        dt_label(dt),
    );
    let series = format!("{} {}", body.series(), stepper.label());
    let mut settings = record::object(body.settings());
    settings.extend(record::object(stepper.settings()));
    settings.extend(record::object(json!({
        "dt": dt, "nu": nu, "E": BEAM_E, "gravity": "-y",
        "time_clock": CpuClock::Thread.name(),
    })));
    settings.extend(extra);
    record::base(scene, &case, &series, settings, body.elements())
}

/// Settles the beam under gravity with the first mode critically damped and measures its tip
/// deflection against Timoshenko's; `settled`: the drift over the averaging window is below 1 %
/// of the reference.
fn static_case(scene: &str, body: Body, stepper: Stepper, dt: f64, nu: f64) {
    let beta = 2.0 / (2.0 * PI * beam_eb_frequency());
    let extra = record::object(json!({
        "damping_beta": beta, "settle_s": SETTLE_S,
        "settling": "stiffness-proportional damping beta = 2/omega_1 (first mode critically \
                     damped), tip averaged over the last 0.25 s",
    }));
    let r = beam_record(scene, body, stepper, (dt, nu), extra);
    let run = match run_beam(body, stepper, dt, nu, Some(beta), SETTLE_S) {
        Ok(run) => run,
        Err(reason) => return record::skipped(r, &reason),
    };
    let tip = StaticTip::measure(&run.ts, &run.us, run.completed(), nu);
    emit_run(r, run, stepper, tip.fields());
}

/// One undamped vibration case: the fit of the tip's oscillation against Timoshenko's first
/// frequency; the damping ratio is all numerical (the beam has no damping).
fn vibration_case(body: Body, stepper: Stepper, dt: f64) {
    let r = beam_record(
        "vibration",
        body,
        stepper,
        (dt, BEAM_NU),
        vibration_settings(),
    );
    let run = match run_beam(body, stepper, dt, BEAM_NU, None, VIBRATION_S) {
        Ok(run) => run,
        Err(reason) => return record::skipped(r, &reason),
    };
    let measures = vibration_fields(&run.ts, &run.us, run.completed(), dt);
    emit_run(r, run, stepper, measures);
}

/// Completes a beam case's line with the run's node and dof counts, `measures`, its failure,
/// work and times, and emits it.
fn emit_run(mut r: Record, run: BeamRun, stepper: Stepper, measures: serde_json::Value) {
    if let Some(settings) = r.get_mut("settings").and_then(|s| s.as_object_mut()) {
        settings.insert("nodes".into(), json!(run.nodes));
        settings.insert("dofs".into(), json!(run.dofs));
    }
    record::extend(&mut r, measures);
    record::extend(
        &mut r,
        json!({
            "failure": run.failure,
            "solver_work": run.work_fields(stepper),
        }),
    );
    record::extend(&mut r, run.timer.fields());
    record::emit(r);
}

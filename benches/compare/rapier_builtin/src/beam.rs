//! Scenes 1-3 on the clamped beam (x = 0 face pinned, gravity -z): static tip deflection at
//! several resolutions and steps (`cantilever`), over Poisson's ratio (`poisson`), and the free
//! vibration released straight under gravity (`vibration`).

use crate::budget::{Budget, CASE_LIMIT_S};
use crate::record::{self, Record};
use crate::setup::{self, Damping, FEM_CG_CAP_CHECKS, Grid, Material, SOLVERS, Solver};
use compare_common::beam::{
    SETTLE_S, StaticTip, VIBRATION_S, vibration_fields, vibration_settings,
};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use serde_json::json;
use std::f64::consts::PI;
use std::time::Instant;

/// Particles per axis of the three beam resolutions (200 / 1600 / 12800 tets).
const RESOLUTIONS: [[usize; 3]; 3] = [[11, 3, 3], [21, 5, 5], [41, 9, 9]];

/// The beam at `particles` resolution: x in [0, L], centred on y = 0, z in [1, 1.1].
fn grid(particles: [usize; 3]) -> Grid {
    Grid {
        center: [BEAM_L / 2.0, 0.0, 1.0 + BEAM_H / 2.0],
        size: [BEAM_L, BEAM_B, BEAM_H],
        particles,
    }
}

fn material(nu: f64) -> Material {
    Material {
        young: BEAM_E,
        poisson: nu,
        density: BEAM_RHO,
    }
}

/// Settling damping that leaves the equilibrium alone, like the scene's beta: rapier has no
/// Rayleigh input, so the first mode is critically damped by the mass-proportional
/// `deformation_damping = 2 omega_1`, and the cells are undamped because the constraint solver's
/// equilibrium moves with `elastic_damping_ratio` (11x3x3 at 1/240: 17.0 mm at 0, 25.6 mm at
/// rapier's default 1, 42.1 mm at 3; the `fem` solver's does not).
fn settle_damping() -> Damping {
    Damping {
        elastic_ratio: 0.0,
        deformation_rate: 2.0 * 2.0 * PI * beam_eb_frequency(),
    }
}

/// What a beam run recorded: the mean vertical displacement of the tip-face particles after
/// every step.
struct BeamRun {
    settings: Record,
    elements: usize,
    ts: Vec<f64>,
    us: Vec<f64>,
    timer: Timer,
    stable: bool,
    wall_s: f64,
}

/// One beam case: `t_end` seconds at step `dt`, every step timed.
fn run_beam(
    grid: &Grid,
    solver: Solver,
    dt: f64,
    nu: f64,
    damping: Damping,
    t_end: f64,
) -> BeamRun {
    let start = Instant::now();
    let mut world = setup::world(dt, solver);
    let builder = setup::grid_body(grid, material(nu), damping, solver);
    let pinned = setup::particles_where(&builder, |p| p.x < 1e-4);
    let tip = setup::particles_where(&builder, |p| p.x as f64 > BEAM_L - 1e-4);
    let z0: Vec<f64> = tip.iter().map(|&i| builder.positions[i].z as f64).collect();
    let handle = world.insert_soft_body(builder.pinned_particles(pinned.iter().map(|&i| i as u32)));
    let settings = setup::settings(&world, solver, grid, material(nu), damping);
    let (mut timer, mut ts, mut us, mut stable) =
        (Timer::new(CpuClock::Thread), vec![], vec![], true);
    for k in 0..(t_end / dt).round() as usize {
        timer.time(|| world.step());
        let sb = &world.soft_bodies[handle];
        if !setup::body_ok(sb) {
            stable = false;
            break;
        }
        let u: f64 = tip
            .iter()
            .zip(&z0)
            .map(|(&i, z0)| sb.particle_position(i).z as f64 - z0)
            .sum();
        ts.push((k + 1) as f64 * dt);
        us.push(u / tip.len() as f64);
    }
    BeamRun {
        settings,
        elements: grid.elements(),
        ts,
        us,
        timer,
        stable,
        wall_s: start.elapsed().as_secs_f64(),
    }
}

/// Scene 1: static tip deflection at dt = 1/240 and 1/60 over the resolutions, both solvers.
pub fn scene_cantilever(quick: bool) {
    let count = if quick { 1 } else { RESOLUTIONS.len() };
    for dt in [1.0 / 240.0, 1.0 / 60.0] {
        for solver in SOLVERS {
            let mut budget = Budget::new(solver, CASE_LIMIT_S);
            for particles in &RESOLUTIONS[..count] {
                let g = grid(*particles);
                match budget.check(g.num_particles()) {
                    Ok(()) => budget.record(
                        g.num_particles(),
                        static_cases("cantilever", &g, dt, BEAM_NU, solver),
                    ),
                    Err(reason) => skip_static("cantilever", &g, dt, BEAM_NU, solver, &reason),
                }
            }
        }
    }
}

/// Scene 2: the static case over Poisson's ratio at one resolution, dt = 1/240, both solvers.
pub fn scene_poisson(quick: bool) {
    let g = grid(RESOLUTIONS[if quick { 0 } else { 1 }]);
    for nu in POISSON_SWEEP {
        for solver in SOLVERS {
            static_cases("poisson", &g, 1.0 / 240.0, nu, solver);
        }
    }
}

/// Runs a static case and emits it. A `fem` case is re-run with the CG cap raised 4x (up to
/// [`FEM_CG_CAP_CHECKS`]) until two caps agree on the tip to 1 % of the reference; a check runs
/// when the run before it took at most [`CASE_LIMIT_S`], so it costs at most 4x a budgeted
/// case (CG usually stops on its tolerance first). Each `fem` line then says whether raising
/// its cap left the tip there (`cg_cap_converged`; null when not checked). Rapier does not
/// report its CG iteration counts, so the tip is the only convergence observable. Returns the
/// first run's wall time.
fn static_cases(scene: &str, g: &Grid, dt: f64, nu: f64, solver: Solver) -> f64 {
    let first = static_case(scene, g, dt, nu, solver);
    let wall_s = first.wall_s;
    let Solver::Fem { cg_cap } = solver else {
        record::emit(first.record);
        return wall_s;
    };
    let reference = beam_timoshenko_tip(nu);
    let agree = |a: &StaticRun, b: &StaticRun| match (a.tip, b.tip) {
        (Some(x), Some(y)) => Some((x - y).abs() < 0.01 * reference),
        _ => None,
    };
    let mut runs = vec![first];
    for cap in FEM_CG_CAP_CHECKS.into_iter().filter(|&c| c > cg_cap) {
        let n = runs.len();
        if n >= 2 && agree(&runs[n - 2], &runs[n - 1]) != Some(false) {
            break;
        }
        let previous_s = runs[n - 1].wall_s;
        if previous_s > CASE_LIMIT_S {
            let reason = format!(
                "the previous cap's run took {previous_s:.0} s (over the {CASE_LIMIT_S:.0} s \
                 budget), so the cg<={cap} check could take 4x that"
            );
            skip_static(scene, g, dt, nu, Solver::Fem { cg_cap: cap }, &reason);
            break;
        }
        runs.push(static_case(scene, g, dt, nu, Solver::Fem { cg_cap: cap }));
    }
    let verdicts: Vec<Option<bool>> = (0..runs.len())
        .map(|i| match (runs.get(i + 1), i.checked_sub(1)) {
            (Some(next), _) => agree(&runs[i], next),
            (None, Some(prev)) if agree(&runs[prev], &runs[i]) == Some(true) => Some(true),
            _ => None,
        })
        .collect();
    for (mut run, verdict) in runs.into_iter().zip(verdicts) {
        run.record.insert("cg_cap_converged".into(), json!(verdict));
        record::emit(run.record);
    }
    wall_s
}

fn static_case_name(g: &Grid, dt: f64, nu: f64, solver: Solver) -> String {
    format!(
        "{} dt=1/{} nu={nu} {}",
        g.label(),
        (1.0 / dt).round(),
        solver.label()
    )
}

fn skip_static(scene: &str, g: &Grid, dt: f64, nu: f64, solver: Solver, reason: &str) {
    let damping = settle_damping();
    let settings = setup::settings(&setup::world(dt, solver), solver, g, material(nu), damping);
    record::skipped(
        scene,
        &static_case_name(g, dt, nu, solver),
        settings,
        g.elements(),
        reason,
    );
}

/// A settled beam's line (not yet emitted), its tip deflection and the case's wall time.
struct StaticRun {
    record: Record,
    tip: Option<f64>,
    wall_s: f64,
}

/// Settles the beam under gravity and measures its tip deflection against Timoshenko's;
/// `settled`: the drift over the averaging window is below 1 % of the reference.
fn static_case(scene: &str, g: &Grid, dt: f64, nu: f64, solver: Solver) -> StaticRun {
    let mut run = run_beam(g, solver, dt, nu, settle_damping(), SETTLE_S);
    let tip = StaticTip::measure(&run.ts, &run.us, run.stable, nu);
    run.settings.extend(record::object(json!({
        "settle_s": SETTLE_S,
        "damping_beta": null,
        "settling": "deformation_damping = 2 omega_1 (omega_1: Euler-Bernoulli first mode; \
                     mass-proportional, first mode critically damped; rapier has no Rayleigh beta); \
                     elastic_damping_ratio 0 because it moves the constraint solver's equilibrium; \
                     tip averaged over the last 0.25 s",
    })));
    let mut r = record::base(
        scene,
        &static_case_name(g, dt, nu, solver),
        run.settings,
        run.elements,
    );
    record::extend(&mut r, tip.fields());
    record::extend(&mut r, run.timer.fields());
    StaticRun {
        record: r,
        tip: tip.tip,
        wall_s: run.wall_s,
    }
}

/// Scene 3: the undamped beam released straight under gravity oscillates about its static
/// deflection for 2 s; a damped-oscillation fit gives its first frequency and damping ratio.
pub fn scene_vibration(quick: bool) {
    let g = grid(RESOLUTIONS[if quick { 0 } else { 1 }]);
    let dts: &[f64] = if quick {
        &[1.0 / 240.0]
    } else {
        &[1.0 / 1000.0, 1.0 / 240.0, 1.0 / 60.0]
    };
    let undamped = Damping {
        elastic_ratio: 0.0,
        deformation_rate: 0.0,
    };
    for solver in SOLVERS {
        for &dt in dts {
            let mut run = run_beam(&g, solver, dt, BEAM_NU, undamped, VIBRATION_S);
            run.settings.extend(vibration_settings());
            let case = format!(
                "{} dt=1/{} {}",
                g.label(),
                (1.0 / dt).round(),
                solver.label()
            );
            let mut r = record::base("vibration", &case, run.settings, run.elements);
            record::extend(&mut r, vibration_fields(&run.ts, &run.us, run.stable, dt));
            record::extend(&mut r, run.timer.fields());
            record::emit(r);
        }
    }
}

//! The frame loop: drive the kinematic bodies, step, record each body's outcome and what the
//! per-frame audit finds and each frame's stepping time, sample the probes, save frames, then
//! render the pictures and plots and write the report with its stability verdict.

use super::build::Simulation;
use super::frame_times::{FrameTimes, StepParts};
use super::report::{
    ProbeReport, Report, RigidBodyReport, Settings, SoftBodyReport, Stability, write_report,
};
use super::writer::{View, Writer};
use crate::output::OutputError;
use crate::scene::rigid_body::RigidKind;
use crate::scene::world::WorldSpec;
use crate::scene::{Scene, SceneError};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rapier_fvm::body::DeformableBodyHandle;
use rapier_fvm::coupling::{Audit, FrameTiming, SoftStepResults};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How to run a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// The output folder (created if needed).
    pub out: PathBuf,
    /// Runs this long (s) instead of the scene's duration.
    pub duration: Option<f64>,
    /// Shows a progress bar on stderr (only when it is a terminal).
    pub progress: bool,
}

/// A run that could not be done.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene could not be built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The duration override is not positive.
    #[error("the duration must be positive and finite (s), got {0}")]
    Duration(f64),
    /// The stepping took longer than the limit given to [`run_within`].
    #[error("stopped at frame {frame} of {frames}: {stepping_s:.2} s of stepping, over the limit")]
    OverTime {
        /// The last frame stepped.
        frame: usize,
        /// The frames of the run.
        frames: usize,
        /// The stepping time so far (s).
        stepping_s: f64,
    },
}

/// Runs `scene` and writes its output into `options.out`; returns the report (also written as
/// `report.json`).
///
/// # Errors
/// [`RunError`] if the scene cannot be built or a file cannot be written. A body whose step
/// fails does not stop the run: it keeps its state, and the report records the failure.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<Report, RunError> {
    run_within(scene, options, None)
}

/// [`run`], stopped once its stepping has taken longer than `limit` (the advisor's trials: an
/// alternative slower than the scene as written is not waited for).
///
/// # Errors
/// Those of [`run`], and [`RunError::OverTime`] past the limit.
pub fn run_within(
    scene: &Scene,
    options: &RunOptions,
    limit: Option<Duration>,
) -> Result<Report, RunError> {
    let started = Instant::now();
    let mut world_spec = scene.world.clone();
    if let Some(duration) = options.duration {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(RunError::Duration(duration));
        }
        world_spec.duration = duration;
    }
    let mut sim = Simulation::build(scene)?;
    let frames = world_spec.frames();
    let dt = world_spec.dt;
    let name = scene.display_name();
    let output = (name.as_str(), &scene.output);
    let mut writer = Writer::new(output, &options.out, (frames, dt), View::Oblique)?;
    let mut bodies: Vec<SoftBodyReport> = (sim.soft.iter())
        .map(|entry| {
            let body = &sim.world.soft_bodies[entry.handle];
            SoftBodyReport::new(entry.name.clone(), entry.label.clone(), body)
        })
        .collect();
    let mut stability = Stability::default();
    let mut audit = Audit::default();
    audit.restart_world(&sim.world);
    sim.sample_probes(0.0);
    writer.frame(0, |time, patch| sim.snapshot(time, patch))?;
    let progress = progress_bar(frames, options.progress);
    let mut stepping = Duration::ZERO;
    let (mut frame_ms, mut awake) = (Vec::with_capacity(frames), Vec::with_capacity(frames));
    let mut timing = FrameTiming::default();
    for frame in 1..=frames {
        let t = frame as f64 * dt;
        let step_start = Instant::now();
        sim.drive_kinematic(t);
        sim.drive_loads(t, &scene.source)?;
        let outcomes = sim.world.step();
        let frame_time = step_start.elapsed();
        timing.accumulate(sim.world.coupling.last_frame_timing());
        stepping += frame_time;
        frame_ms.push(frame_time.as_secs_f64() * 1e3);
        if limit.is_some_and(|limit| stepping > limit) {
            return Err(RunError::OverTime {
                frame,
                frames,
                stepping_s: stepping.as_secs_f64(),
            });
        }
        awake.push(record_frame(
            &sim,
            (frame, &outcomes),
            (&mut bodies, &mut stability, &mut audit),
        ));
        sim.sample_probes(t);
        writer.frame(frame, |time, patch| sim.snapshot(time, patch))?;
        progress.set_position(frame as u64);
        let speed = t / stepping.as_secs_f64().max(1e-9);
        progress.set_message(format!("t = {t:.3} s, {speed:.2}x real time"));
    }
    progress.finish_and_clear();
    let frame_times = FrameTimes::new(frame_ms, awake, dt).with_parts(StepParts::of(&timing));
    let frame_series = frame_times.series(dt);
    let plotted = sim.probes.iter().map(|p| &p.series);
    let files = writer.finish(plotted.chain([&frame_series]))?;
    stability.final_state_finite = (sim.soft.iter())
        .map(|entry| &sim.world.soft_bodies[entry.handle])
        .all(|b| {
            b.positions()
                .iter()
                .chain(b.velocities())
                .all(|v| v.is_finite())
        });
    stability.conclude(&mut bodies);
    let stepping_s = stepping.as_secs_f64();
    let simulated = frames as f64 * dt;
    let report = Report {
        scene: scene.display_name(),
        scene_file: scene.source.path.display().to_string(),
        settings: settings(scene, &world_spec, &sim),
        soft_bodies: bodies,
        rigid_bodies: rigid_reports(&sim),
        frames,
        simulated_time: simulated,
        wall_time_s: started.elapsed().as_secs_f64(),
        stepping_time_s: stepping_s,
        ms_per_frame: stepping_s * 1e3 / frames as f64,
        speed_vs_real_time: simulated / stepping_s.max(1e-9),
        frame_times,
        stability,
        probes: (sim.probes.iter())
            .map(|p| ProbeReport::of(&p.series, p.kind.name()))
            .collect(),
        files,
    };
    write_report(&options.out, &report)?;
    Ok(report)
}

/// Records what frame `frame`'s step `outcomes` were in each soft body's report, the bodies
/// asleep, their strain, rotation and contacts, and what the `audit` of the frame finds, in
/// the reports and the `stability`; returns the soft bodies awake (neither asleep nor standing
/// in as a rigid body).
fn record_frame(
    sim: &Simulation,
    (frame, outcomes): (usize, &SoftStepResults),
    (bodies, stability, audit): (&mut [SoftBodyReport], &mut Stability, &mut Audit),
) -> usize {
    let report_of = |handle: DeformableBodyHandle| sim.soft.iter().position(|e| e.handle == handle);
    let mut awake = 0;
    for (handle, outcome) in outcomes {
        if let Some(i) = report_of(*handle) {
            bodies[i].record(outcome, stability);
        }
    }
    for (entry, report) in sim.soft.iter().zip(bodies.iter_mut()) {
        let asleep = sim.world.coupling.is_sleeping(entry.handle);
        report.asleep_frames += usize::from(asleep);
        let standing_in = sim.world.coupling.rigid_stand_in_of(entry.handle).is_some();
        report.rigid_frames += usize::from(standing_in);
        awake += usize::from(!asleep && !standing_in);
        let touching = (sim.world.coupling.constraints(entry.handle))
            .is_some_and(|constraints| constraints.pushed_by_collider());
        let body = &sim.world.soft_bodies[entry.handle];
        report.needs.record(body, &entry.rest, (touching, asleep));
    }
    let found = audit.check_world(&sim.world, outcomes);
    stability.record_system(frame, found.system);
    for (handle, body_audit) in &found.bodies {
        if let Some(i) = report_of(*handle) {
            bodies[i].record_audit(frame, body_audit);
        }
    }
    awake
}

/// A progress bar over `frames`, drawn on stderr only when it is a terminal and `show` is set.
fn progress_bar(frames: usize, show: bool) -> ProgressBar {
    let target = if show {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(frames as u64), target);
    if let Ok(style) = ProgressStyle::with_template("{bar:30} frame {pos}/{len} {msg} (eta {eta})")
    {
        bar.set_style(style);
    }
    bar
}

/// The settings used.
fn settings(scene: &Scene, world: &WorldSpec, sim: &Simulation) -> Settings {
    let integrator = &sim.world.coupling.integrator;
    Settings {
        dt: world.dt,
        duration: world.duration,
        gravity: world.gravity,
        coupling_substeps: sim.world.coupling.substeps,
        sleep_speed: sim.world.coupling.sleep.speed_threshold,
        time_until_sleep: sim.world.coupling.sleep.time_until_sleep,
        integrator: format!("{:?}", scene.integrator.kind).to_lowercase(),
        explicit_safety_factor: integrator.explicit.safety_factor,
        implicit_substeps: integrator.implicit.substeps,
        contact_margin: sim.world.coupling.contact.margin,
        contact_velocity_iterations: sim.world.coupling.contact.velocity_iterations,
        save_every: scene.output.save_every,
    }
}

/// The rigid bodies' names, kinds and masses.
fn rigid_reports(sim: &Simulation) -> Vec<RigidBodyReport> {
    (sim.rigid.iter())
        .map(|entry| RigidBodyReport {
            name: entry.name.clone(),
            kind: match entry.spec.kind {
                RigidKind::Fixed => "fixed",
                RigidKind::Dynamic => "dynamic",
                RigidKind::Kinematic => "kinematic",
            }
            .to_owned(),
            mass: sim
                .world
                .physics
                .bodies
                .get(entry.handle)
                .map_or(0.0, |b| f64::from(b.mass())),
        })
        .collect()
}

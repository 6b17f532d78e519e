//! The frame loop: drive the kinematic bodies, step, record each body's outcome, sample the
//! probes, save frames, then render the pictures and plots and write the report.

use super::build::Simulation;
use super::report::{
    Files, ProbeReport, Report, RigidBodyReport, Settings, SoftBodyReport, Stability,
};
use crate::output::{
    Camera, Coloring, OutputError, ParaViewSeries, RigidBodySnapshot, Snapshot, SoftBodySnapshot,
    plot_series, render_png, write_obj,
};
use crate::scene::rigid_body::RigidKind;
use crate::scene::{Scene, SceneError};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
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
}

/// Size of the plots (pixels).
const PLOT_SIZE: (u32, u32) = (900, 500);

/// Runs `scene` and writes its output into `options.out`; returns the report (also written as
/// `report.json`).
///
/// # Errors
/// [`RunError`] if the scene cannot be built or a file cannot be written. A body whose step
/// fails does not stop the run: it keeps its state, and the report records the failure.
pub fn run(scene: &Scene, options: &RunOptions) -> Result<Report, RunError> {
    let started = Instant::now();
    let mut world_spec = scene.world.clone();
    if let Some(duration) = options.duration {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(RunError::Duration(duration));
        }
        world_spec.duration = duration;
    }
    let mut sim = Simulation::build(scene)?;
    let out = &options.out;
    for (dir, extension) in [
        ("paraview", "vtu"),
        ("paraview", "pvd"),
        ("obj", "obj"),
        ("pictures", "png"),
        ("plots", "png"),
    ] {
        clear(&out.join(dir), extension)?;
    }
    let name = scene.display_name();
    let mut series = ParaViewSeries::new(out.join("paraview"), &name)?;
    let frames = world_spec.frames();
    let dt = world_spec.dt;
    let patch = scene.output.ground_patch;
    let picture_frames = picture_frames(scene, frames, dt);
    let mut bodies: Vec<SoftBodyReport> = (sim.soft.iter())
        .map(|entry| {
            let body = &sim.world.soft_bodies[entry.handle];
            SoftBodyReport::new(
                entry.name.clone(),
                entry.label.clone(),
                body.mesh().tet_count(),
                body.node_count(),
                body.total_mass(),
            )
        })
        .collect();
    let mut stability = Stability::default();
    let mut files = Files {
        pvd: relative(out, &series.pvd_path()),
        ..Files::default()
    };
    let mut pictured: Vec<(usize, Snapshot)> = Vec::new();
    let mut bounds: Option<(rapier_fvm::glamx::DVec3, rapier_fvm::glamx::DVec3)> = None;
    let mut save = |sim: &Simulation, frame: usize, files: &mut Files| -> Result<(), OutputError> {
        let saved = frame % scene.output.save_every == 0 || frame == frames;
        let pictured_now = picture_frames.contains(&frame);
        if !(saved || pictured_now) {
            return Ok(());
        }
        let snapshot = capture(sim, frame as f64 * dt, patch);
        if let Some((lo, hi)) = snapshot.bounds() {
            bounds = Some(bounds.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
        }
        if saved {
            files.vtu_count += series.write_frame(&snapshot)?.len();
            let obj = out.join("obj").join(format!("surface_{frame:05}.obj"));
            write_obj(&obj, &snapshot)?;
            files.obj.push(relative(out, &obj));
        }
        if pictured_now {
            pictured.push((frame, snapshot));
        }
        Ok(())
    };
    sim.sample_probes(0.0);
    save(&sim, 0, &mut files)?;
    let progress = progress_bar(frames, options.progress);
    let mut stepping = Duration::ZERO;
    for frame in 1..=frames {
        let t = frame as f64 * dt;
        let step_start = Instant::now();
        sim.drive_kinematic(t);
        let outcomes = sim.world.step();
        stepping += step_start.elapsed();
        for (handle, outcome) in &outcomes {
            if let Some(i) = sim.soft.iter().position(|e| e.handle == *handle) {
                bodies[i].record(outcome, &mut stability);
            }
        }
        sim.sample_probes(t);
        save(&sim, frame, &mut files)?;
        progress.set_position(frame as u64);
        let speed = t / stepping.as_secs_f64().max(1e-9);
        progress.set_message(format!("t = {t:.3} s, {speed:.2}x real time"));
    }
    progress.finish_and_clear();
    drop(save);
    let (lo, hi) = bounds.unwrap_or_default();
    files.pictures = render_pictures(out, &pictured, lo, hi, scene.output.picture_size, dt)?;
    for probe in &sim.probes {
        let path = out.join("plots").join(format!(
            "{}.png",
            crate::output::file_stem(&probe.series.name)
        ));
        plot_series(&path, &probe.series, PLOT_SIZE)?;
        files.plots.push(relative(out, &path));
    }
    stability.final_state_finite = sim.soft.iter().all(|entry| {
        let body = &sim.world.soft_bodies[entry.handle];
        body.positions()
            .iter()
            .chain(body.velocities())
            .all(|v| v.is_finite())
    });
    let stepping_s = stepping.as_secs_f64();
    let simulated = frames as f64 * dt;
    let report = Report {
        scene: name,
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
        stability,
        probes: sim.probes.iter().map(probe_report).collect(),
        files,
    };
    let path = out.join("report.json");
    let json = serde_json::to_string_pretty(&report).map_err(|e| OutputError::Io {
        path: path.clone(),
        source: std::io::Error::other(e),
    })?;
    std::fs::write(&path, json).map_err(OutputError::io(&path))?;
    Ok(report)
}

/// The frames whose views are rendered: those nearest the scene's picture times, or the start,
/// a third, two thirds and the end.
fn picture_frames(scene: &Scene, frames: usize, dt: f64) -> Vec<usize> {
    let mut chosen: Vec<usize> = match &scene.output.pictures {
        Some(times) => times
            .iter()
            .map(|t| ((t / dt).round().max(0.0) as usize).min(frames))
            .collect(),
        None => vec![0, frames / 3, 2 * frames / 3, frames],
    };
    chosen.sort_unstable();
    chosen.dedup();
    chosen
}

/// The world now as plain data.
fn capture(sim: &Simulation, time: f64, patch: f64) -> Snapshot {
    Snapshot {
        time,
        soft_bodies: (sim.soft.iter())
            .map(|entry| {
                let body = &sim.world.soft_bodies[entry.handle];
                SoftBodySnapshot::capture(&entry.name, &entry.label, body, &entry.rest)
            })
            .collect(),
        rigid_bodies: (sim.rigid.iter())
            .filter_map(|entry| {
                RigidBodySnapshot::of_body(&entry.name, &sim.world.physics, entry.handle, patch)
            })
            .collect(),
    }
}

/// Renders each pictured frame by material and by stress from one camera framing the box
/// `lo`..`hi` (m); returns `(time (s), file)` of each picture.
fn render_pictures(
    out: &Path,
    pictured: &[(usize, Snapshot)],
    lo: rapier_fvm::glamx::DVec3,
    hi: rapier_fvm::glamx::DVec3,
    [width, height]: [u32; 2],
    dt: f64,
) -> Result<Vec<(f64, String)>, OutputError> {
    let camera = Camera::oblique(lo, hi, width, height);
    let max_stress = pictured
        .iter()
        .map(|(_, s)| stress_scale(s))
        .fold(1.0, f64::max);
    let mut written = Vec::new();
    for (frame, snapshot) in pictured {
        let time = *frame as f64 * dt;
        for (prefix, coloring) in [
            ("view", Coloring::Material),
            ("stress", Coloring::VonMises { max: max_stress }),
        ] {
            let path = out
                .join("pictures")
                .join(format!("{prefix}_{frame:05}.png"));
            render_png(&path, snapshot, &camera, coloring)?;
            written.push((time, relative(out, &path)));
        }
    }
    Ok(written)
}

/// The top of the stress colour scale (Pa) for a snapshot: each soft body's 95th percentile of
/// nodal von Mises stress (so that a few peak nodes at a contact corner do not leave the rest in
/// the bottom colour), and the median of these over the bodies (so that one body far more
/// stressed than the others, a taut rope, does not leave them all in the bottom colour: it shows
/// in the top colour instead).
fn stress_scale(snapshot: &Snapshot) -> f64 {
    let mut per_body: Vec<f64> = (snapshot.soft_bodies.iter())
        .map(|body| {
            let mut values: Vec<f64> = (body.nodal_von_mises().into_iter())
                .filter(|v| v.is_finite())
                .collect();
            values.sort_by(f64::total_cmp);
            values.get(values.len() * 95 / 100).copied().unwrap_or(0.0)
        })
        .collect();
    per_body.sort_by(f64::total_cmp);
    per_body.get(per_body.len() / 2).copied().unwrap_or(0.0)
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

/// Creates the folder `dir` if needed and removes the files with `extension` an earlier run
/// left in it, so that the folder holds only this run's output.
fn clear(dir: &Path, extension: &str) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(OutputError::io(dir))?;
    let entries = std::fs::read_dir(dir).map_err(OutputError::io(dir))?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_file() && path.extension().is_some_and(|e| e == extension) {
            std::fs::remove_file(&path).map_err(OutputError::io(&path))?;
        }
    }
    Ok(())
}

/// `path` relative to `out`, with `/` separators.
fn relative(out: &Path, path: &Path) -> String {
    path.strip_prefix(out)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

/// The settings used.
fn settings(scene: &Scene, world: &crate::scene::world::WorldSpec, sim: &Simulation) -> Settings {
    let integrator = &sim.world.integrator;
    Settings {
        dt: world.dt,
        duration: world.duration,
        gravity: world.gravity,
        coupling_substeps: sim.world.coupling_substeps,
        integrator: format!("{:?}", scene.integrator.kind).to_lowercase(),
        explicit_safety_factor: integrator.explicit.safety_factor,
        implicit_substeps: integrator.implicit.substeps,
        contact_margin: sim.world.contact.margin,
        contact_velocity_iterations: sim.world.contact.velocity_iterations,
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

/// A probe's report.
fn probe_report(probe: &super::Probe) -> ProbeReport {
    let (times, values): (Vec<f64>, Vec<f64>) = probe.series.samples.iter().copied().unzip();
    ProbeReport {
        name: probe.series.name.clone(),
        kind: probe.kind.name().to_owned(),
        unit: probe.series.unit.clone(),
        final_value: values.last().copied().unwrap_or(f64::NAN),
        times,
        values,
    }
}

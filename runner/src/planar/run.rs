//! Running a 2D scene: the frame loop (the coupling steps the soft bodies with rapier2d's rigid
//! bodies), the probes sampled after every frame, the output folder written as for 3D scenes
//! (ParaView series of triangles, OBJ, pictures from the front, plots) and its report.

use super::build::PlanarSimulation;
use super::scene::{PlanarRigidKind, PlanarScene, PlaneSpec};
use crate::sim::report::write_report;
use crate::sim::writer::{View, Writer};
use crate::sim::{Files, FrameTimes, ProbeReport, RunError, RunOptions};
use rapier_fvm::glamx::DVec2;
use rapier_fvm::planar::PlanarStepReport;
use serde::Serialize;
use std::time::{Duration, Instant};

/// What a 2D run did (written as `report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct PlanarReport {
    /// The scene's name.
    pub scene: String,
    /// The scene file.
    pub scene_file: String,
    /// Always 2.
    pub dimension: u8,
    /// The frame step (s).
    pub dt: f64,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Gravity (m/s²).
    pub gravity: [f64; 2],
    /// The fewest coupling substeps per frame.
    pub coupling_substeps: u32,
    /// Soft–rigid friction coefficient.
    pub friction: f64,
    /// The scene's integrator setting: `"explicit"`, `"implicit"` or `"automatic"` (what each
    /// body took: [`PlanarBodyReport::implicit_frames`]).
    pub integrator: String,
    /// The soft bodies.
    pub soft_bodies: Vec<PlanarBodyReport>,
    /// The rigid bodies: name, kind and mass (kg: rapier2d's, the shape's area times its
    /// density in kg/m²).
    pub rigid_bodies: Vec<(String, String, f64)>,
    /// Frames run.
    pub frames: usize,
    /// Wall time of the run (s).
    pub wall_time_s: f64,
    /// Time spent stepping (s).
    pub stepping_time_s: f64,
    /// Stepping time per frame (ms).
    pub ms_per_frame: f64,
    /// Simulated time over stepping time.
    pub speed_vs_real_time: f64,
    /// Each frame's stepping time, and where the time went (every soft body is awake in 2D).
    pub frame_times: FrameTimes,
    /// Whether every node's position and velocity are finite at the end.
    pub final_state_finite: bool,
    /// The largest rise of the mechanical energy (J) over one frame (soft bodies' elastic,
    /// kinetic and gravity energies and dynamic rigid bodies' kinetic and gravity energies;
    /// energy stored in the contacts' penalty springs is not counted, so a contact releasing it
    /// shows as a rise), and the frame it happened in.
    pub largest_energy_rise: (f64, usize),
    /// The probes.
    pub probes: Vec<ProbeReport>,
    /// The files written.
    pub files: Files,
}

/// What a soft body is and how its steps went.
#[derive(Debug, Clone, Serialize)]
pub struct PlanarBodyReport {
    /// Its name.
    pub name: String,
    /// `"stress"` or `"strain"`.
    pub plane: String,
    /// Thickness (m).
    pub thickness: f64,
    /// Triangles (of a quadratic body, its 6-node triangles).
    pub triangles: usize,
    /// Nodes.
    pub nodes: usize,
    /// Mass (kg).
    pub mass: f64,
    /// The most explicit substeps one coupling substep took.
    pub max_explicit_substeps: u32,
    /// Frames whose last coupling substep stepped the body implicitly.
    pub implicit_frames: usize,
    /// Frames whose step failed (the body then stays where the failing step left it).
    pub failed_frames: usize,
    /// The first failure's message.
    pub first_failure: Option<String>,
}

/// Runs the 2D `scene` and writes its output into `options.out`; returns the report (also
/// written as `report.json`).
///
/// # Errors
/// [`RunError`] if the scene cannot be built or a file cannot be written.
pub fn run_planar(scene: &PlanarScene, options: &RunOptions) -> Result<PlanarReport, RunError> {
    let started = Instant::now();
    let duration = options.duration.unwrap_or(scene.world.duration);
    if !(duration.is_finite() && duration > 0.0) {
        return Err(RunError::Duration(duration));
    }
    let dt = scene.world.dt;
    let frames = ((duration / dt).round() as usize).max(1);
    let mut sim = PlanarSimulation::build(scene)?;
    let name = scene.display_name();
    let mut writer = Writer::new(
        (&name, &scene.output),
        &options.out,
        (frames, dt),
        View::Front,
    )?;
    let mut bodies: Vec<PlanarBodyReport> = body_reports(scene, &sim);
    sim.sample_probes(0.0);
    writer.frame(0, |time, patch| sim.snapshot(time, patch))?;
    let mut stepping = Duration::ZERO;
    let mut frame_ms = Vec::with_capacity(frames);
    let mut energy = mechanical_energy(&sim);
    let mut largest_rise = (f64::NEG_INFINITY, 0);
    for frame in 1..=frames {
        let t = frame as f64 * dt;
        let step_start = Instant::now();
        let outcomes = sim.coupling.step(&mut sim.physics, &mut sim.bodies);
        let frame_time = step_start.elapsed();
        stepping += frame_time;
        frame_ms.push(frame_time.as_secs_f64() * 1e3);
        let outcomes = outcomes.map_err(|e| scene.source.error("world.dt", e.to_string()))?;
        for (report, outcome) in bodies.iter_mut().zip(outcomes) {
            report.record(frame, outcome);
        }
        let now = mechanical_energy(&sim);
        if now - energy > largest_rise.0 {
            largest_rise = (now - energy, frame);
        }
        energy = now;
        sim.sample_probes(t);
        writer.frame(frame, |time, patch| sim.snapshot(time, patch))?;
    }
    let frame_times = FrameTimes::new(frame_ms, vec![bodies.len(); frames], dt);
    let frame_series = frame_times.series(dt);
    let plotted = sim.probes.iter().map(|p| &p.series);
    let files = writer.finish(plotted.chain([&frame_series]))?;
    let report = PlanarReport {
        soft_bodies: bodies,
        frame_times,
        largest_energy_rise: largest_rise,
        files,
        ..PlanarReport::of(scene, &sim, (frames, started.elapsed(), stepping))
    };
    write_report(&options.out, &report)?;
    Ok(report)
}

impl PlanarReport {
    /// The report of `scene` run in `sim` for `frames` frames, taking `wall` and `stepping`
    /// time, with no soft body, frame times, energy rise or file yet.
    fn of(
        scene: &PlanarScene,
        sim: &PlanarSimulation,
        (frames, wall, stepping): (usize, Duration, Duration),
    ) -> Self {
        let stepping_s = stepping.as_secs_f64();
        let simulated = frames as f64 * scene.world.dt;
        Self {
            scene: scene.display_name(),
            scene_file: scene.source.path.display().to_string(),
            dimension: 2,
            dt: scene.world.dt,
            simulated_time: simulated,
            gravity: scene.world.gravity,
            coupling_substeps: scene.world.coupling_substeps,
            friction: scene.world.friction,
            integrator: format!("{:?}", scene.world.integrator).to_lowercase(),
            soft_bodies: Vec::new(),
            rigid_bodies: rigid_reports(scene, sim),
            frames,
            wall_time_s: wall.as_secs_f64(),
            stepping_time_s: stepping_s,
            ms_per_frame: stepping_s * 1e3 / frames as f64,
            speed_vs_real_time: simulated / stepping_s.max(1e-9),
            frame_times: FrameTimes::default(),
            final_state_finite: (sim.bodies.iter()).all(|b| {
                b.positions()
                    .iter()
                    .chain(b.velocities())
                    .all(|v| v.is_finite())
            }),
            largest_energy_rise: (f64::NEG_INFINITY, 0),
            probes: (sim.probes.iter())
                .map(|p| ProbeReport::of(&p.series, p.kind()))
                .collect(),
            files: Files::default(),
        }
    }
}

impl PlanarBodyReport {
    /// Records the outcome of frame `frame`'s last coupling substep.
    fn record(&mut self, frame: usize, outcome: Result<PlanarStepReport, rapier_fvm::Error>) {
        match outcome {
            Ok(step) if step.implicit => self.implicit_frames += 1,
            Ok(step) => self.max_explicit_substeps = self.max_explicit_substeps.max(step.substeps),
            Err(error) => {
                self.failed_frames += 1;
                (self.first_failure).get_or_insert_with(|| format!("frame {frame}: {error}"));
            }
        }
    }
}

/// The soft bodies' reports before the first step.
fn body_reports(scene: &PlanarScene, sim: &PlanarSimulation) -> Vec<PlanarBodyReport> {
    (scene.soft_body.iter().zip(&sim.bodies))
        .map(|(spec, body)| PlanarBodyReport {
            name: spec.name.clone(),
            plane: match spec.plane {
                PlaneSpec::Stress => "stress",
                PlaneSpec::Strain => "strain",
            }
            .to_owned(),
            thickness: spec.thickness,
            triangles: body.mesh().triangles().len(),
            nodes: body.positions().len(),
            mass: body.total_mass(),
            max_explicit_substeps: 0,
            implicit_frames: 0,
            failed_frames: 0,
            first_failure: None,
        })
        .collect()
}

/// The rigid bodies' names, kinds and masses.
fn rigid_reports(scene: &PlanarScene, sim: &PlanarSimulation) -> Vec<(String, String, f64)> {
    (scene.rigid_body.iter().zip(&sim.rigid))
        .map(|(spec, entry)| {
            let kind = match spec.kind {
                PlanarRigidKind::Fixed => "fixed",
                PlanarRigidKind::Dynamic => "dynamic",
            };
            let mass = sim
                .physics
                .bodies
                .get(entry.handle)
                .map_or(0.0, |b| f64::from(b.mass()));
            (spec.name.clone(), kind.to_owned(), mass)
        })
        .collect()
}

/// The mechanical energy (J) of the soft bodies and the dynamic rigid bodies (see
/// [`PlanarReport::largest_energy_rise`]).
fn mechanical_energy(sim: &PlanarSimulation) -> f64 {
    let g = sim.gravity;
    let soft: f64 = (sim.bodies.iter())
        .map(|b| {
            let potential: f64 = (b.masses().iter().zip(b.positions()))
                .map(|(m, x)| -m * g.dot(*x))
                .sum();
            b.elastic_energy() + b.kinetic_energy() + potential
        })
        .sum();
    let rigid: f64 = (sim.physics.bodies.iter())
        .filter(|(_, b)| b.is_dynamic())
        .map(|(_, b)| {
            let m = f64::from(b.mass());
            let v: DVec2 = b.linvel().as_dvec2();
            let inertia = f64::from(b.mass_properties().effective_angular_inertia());
            let w = f64::from(b.angvel());
            0.5 * m * v.length_squared() + 0.5 * inertia * w * w
                - m * g.dot(b.center_of_mass().as_dvec2())
        })
        .sum();
    soft + rigid
}

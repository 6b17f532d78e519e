//! `report.json`: what a run did, for scripts to read. Times in s, lengths in m, forces in N,
//! energies in J.

use rapier_fvm::Error;
use rapier_fvm::body::DeformableBody;
use rapier_fvm::coupling::{BodyAudit, EnergyCheck};
use rapier_fvm::element::{ElementOrder, ElementShape};
use rapier_fvm::integrate::{AutomaticReport, IntegratorKind};
use serde::Serialize;

pub use super::cost::StepCost;
pub use super::frame_times::{FrameTimes, StepParts};

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The scene's name.
    pub scene: String,
    /// The scene file.
    pub scene_file: String,
    /// The settings the run used.
    pub settings: Settings,
    /// Per soft body: size, material and how it was stepped.
    pub soft_bodies: Vec<SoftBodyReport>,
    /// Per rigid body: its name and kind.
    pub rigid_bodies: Vec<RigidBodyReport>,
    /// Frames stepped.
    pub frames: usize,
    /// Simulated time reached (s).
    pub simulated_time: f64,
    /// Wall time of the whole run, output included (s).
    pub wall_time_s: f64,
    /// Wall time spent stepping the world (s).
    pub stepping_time_s: f64,
    /// Stepping wall time per frame (ms).
    pub ms_per_frame: f64,
    /// Simulated time over stepping wall time (above 1: faster than real time).
    pub speed_vs_real_time: f64,
    /// Each frame's stepping time and awake soft bodies, and where the time went.
    pub frame_times: FrameTimes,
    /// Whether anything went wrong numerically.
    pub stability: Stability,
    /// Every probe's samples and final value.
    pub probes: Vec<ProbeReport>,
    /// The files written, relative to the output folder.
    pub files: Files,
}

/// The settings a run used, defaults filled in.
#[derive(Debug, Clone, Serialize)]
pub struct Settings {
    /// Frame step (s).
    pub dt: f64,
    /// Simulated duration asked for (s).
    pub duration: f64,
    /// Gravity (m/s²).
    pub gravity: [f64; 3],
    /// Rapier steps per frame.
    pub coupling_substeps: u32,
    /// Speed (m/s) below which nodes count as still.
    pub sleep_speed: f64,
    /// Time (s) a body stays still before it sleeps (`null`: never).
    pub time_until_sleep: f64,
    /// `automatic`, `explicit` or `implicit`.
    pub integrator: String,
    /// Explicit safety factor.
    pub explicit_safety_factor: f64,
    /// Implicit substeps per frame.
    pub implicit_substeps: u32,
    /// Contact margin (m).
    pub contact_margin: f64,
    /// Contact velocity iterations.
    pub contact_velocity_iterations: u32,
    /// Frames between saved frames.
    pub save_every: usize,
}

/// A soft body's size, material and stepping record.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SoftBodyReport {
    /// Its name.
    pub name: String,
    /// Its material label.
    pub material: String,
    /// The elements it is simulated with: "linear tetrahedra", "quadratic tetrahedra" or
    /// "quadratic hexahedra".
    pub element_kind: String,
    /// How many of them.
    pub elements: usize,
    /// Nodes.
    pub nodes: usize,
    /// Tetrahedra of the fine mesh it carries for contact and output, if any.
    pub embedded_tets: Option<usize>,
    /// Mass (kg).
    pub mass: f64,
    /// Frames its last substep stepped explicitly.
    pub explicit_frames: usize,
    /// Frames its last substep stepped implicitly.
    pub implicit_frames: usize,
    /// Frames it ended asleep, not stepped.
    pub asleep_frames: usize,
    /// Frames it ended standing in as a rapier rigid body, not stepped.
    pub rigid_frames: usize,
    /// Frames chosen explicit but redone implicitly.
    pub fell_back_frames: usize,
    /// Mean explicit substeps per explicit coupling substep.
    pub mean_explicit_substeps: f64,
    /// Most explicit substeps in a coupling substep.
    pub max_explicit_substeps: u32,
    /// Implicit frames whose Newton solve missed the tolerance.
    pub unconverged_frames: usize,
    /// Frames whose step failed (the state before it kept).
    pub failed_frames: usize,
    /// The first failure's message.
    pub first_error: Option<String>,
    /// Most inverted elements at the end of a frame.
    pub max_inverted_elements: usize,
    /// What the per-frame audit (`rapier_fvm::coupling::Audit`) found for this body.
    pub stability_flags: BodyFlags,
    /// Whether no flag was raised and no step failed.
    pub stable: bool,
    /// What its steps cost: the automatic choice's predictions beside the measured time.
    pub cost: StepCost,
    /// What its motion asked of its model: peak strain and rotation, frames in contact.
    pub needs: super::needs::BodyNeeds,
    #[serde(skip)]
    explicit_substeps_sum: u64,
}

/// A rigid body's name and kind.
#[derive(Debug, Clone, Serialize)]
pub struct RigidBodyReport {
    /// Its name.
    pub name: String,
    /// `fixed`, `dynamic` or `kinematic`.
    pub kind: String,
    /// Mass (kg; 0 for fixed and kinematic bodies).
    pub mass: f64,
}

/// A check of the audit that failed at least once: the frame of its first failure, how many
/// frames it failed in, and the worst value it saw.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Flag {
    /// The first frame it was raised in (1 is the first frame stepped).
    pub first_frame: usize,
    /// Frames it was raised in.
    pub frames: usize,
    /// The worst value, in `unit`.
    pub worst: f64,
    /// The unit of `worst`.
    pub unit: &'static str,
}

impl Flag {
    /// Raises `flag` at `frame` with `value` (the larger value is the worse).
    fn raise(flag: &mut Option<Flag>, frame: usize, value: f64, unit: &'static str) {
        match flag {
            Some(flag) => {
                flag.frames += 1;
                flag.worst = flag.worst.max(value);
            }
            None => {
                *flag = Some(Flag {
                    first_frame: frame,
                    frames: 1,
                    worst: value,
                    unit,
                });
            }
        }
    }
}

/// The audit's flags for a soft body, each `null` when never raised (tolerances: see
/// `rapier_fvm::coupling::Audit`).
#[derive(Debug, Clone, Default, Serialize)]
pub struct BodyFlags {
    /// The body and the rigid and soft bodies it exchanges energy with gained energy (worst: the
    /// gain above the previous frame plus the work counted, J).
    pub energy_gained: Option<Flag>,
    /// Contact points deeper than the tolerance inside a collider or another soft body (worst:
    /// the deepest, m).
    pub penetration: Option<Flag>,
    /// Contact points that went through a collider or another soft body over a frame (worst:
    /// most in a frame).
    pub crossing: Option<Flag>,
    /// Elements of zero or negative volume left after a frame (worst: most in a frame).
    pub inverted_elements: Option<Flag>,
    /// Elements below 1 % of their rest volume left after a frame (worst: most in a frame).
    pub collapsed_elements: Option<Flag>,
}

impl BodyFlags {
    /// Whether any flag is raised.
    pub fn any(&self) -> bool {
        self.energy_gained.is_some()
            || self.penetration.is_some()
            || self.crossing.is_some()
            || self.inverted_elements.is_some()
            || self.collapsed_elements.is_some()
    }

    /// Raises the flags `audit` (frame `frame`) calls for.
    fn record(&mut self, frame: usize, audit: &BodyAudit) {
        if let Some(energy) = audit.energy.filter(EnergyCheck::gained) {
            Flag::raise(&mut self.energy_gained, frame, energy.gain, "J");
        }
        if audit.penetrates() {
            let deepest = audit.penetrations.deepest;
            Flag::raise(&mut self.penetration, frame, deepest, "m");
        }
        if audit.crossed() {
            let crossed = audit.penetrations.crossed as f64;
            Flag::raise(&mut self.crossing, frame, crossed, "points");
        }
        if audit.inverted_elements > 0 {
            let count = audit.inverted_elements as f64;
            Flag::raise(&mut self.inverted_elements, frame, count, "elements");
        }
        if audit.collapsed_elements > 0 {
            let count = audit.collapsed_elements as f64;
            Flag::raise(&mut self.collapsed_elements, frame, count, "elements");
        }
    }
}

/// Numerical trouble over the run.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Stability {
    /// The verdict: every soft body stable (no flag raised, no step failed), the whole system's
    /// energy never gained, and the final state finite.
    pub stable: bool,
    /// The soft bodies that are not stable.
    pub unstable_bodies: Vec<String>,
    /// The whole coupled system (every soft and dynamic rigid body) gained energy (worst: the
    /// gain, J).
    pub system_energy_gained: Option<Flag>,
    /// A step produced a NaN or infinite state (rejected, the state before it kept).
    pub non_finite: bool,
    /// A step failed for any reason.
    pub any_error: bool,
    /// A frame ended with inverted tetrahedra.
    pub inverted_elements: bool,
    /// The final state is finite everywhere.
    pub final_state_finite: bool,
}

/// A probe's samples.
#[derive(Debug, Clone, Serialize)]
pub struct ProbeReport {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: String,
    /// The unit of its values.
    pub unit: String,
    /// The last sample.
    pub final_value: f64,
    /// Sample times (s), one per frame from 0.
    pub times: Vec<f64>,
    /// Sample values.
    pub values: Vec<f64>,
}

impl ProbeReport {
    /// The report of the samples `series` of a probe of kind `kind` (its scene-file name).
    pub fn of(series: &crate::output::TimeSeries, kind: &str) -> Self {
        let (times, values): (Vec<f64>, Vec<f64>) = series.samples.iter().copied().unzip();
        Self {
            name: series.name.clone(),
            kind: kind.to_owned(),
            unit: series.unit.clone(),
            final_value: values.last().copied().unwrap_or(f64::NAN),
            times,
            values,
        }
    }
}

/// The files written, relative to the output folder.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Files {
    /// The ParaView index.
    pub pvd: String,
    /// `.vtu` files written.
    pub vtu_count: usize,
    /// OBJ surfaces, one per saved frame.
    pub obj: Vec<String>,
    /// Rendered views `(time (s), file)`.
    pub pictures: Vec<(f64, String)>,
    /// Probe plots.
    pub plots: Vec<String>,
}

impl Stability {
    /// Raises the system's energy flag if `system` (frame `frame`) gained.
    pub(crate) fn record_system(&mut self, frame: usize, system: Option<EnergyCheck>) {
        if let Some(system) = system.filter(EnergyCheck::gained) {
            Flag::raise(&mut self.system_energy_gained, frame, system.gain, "J");
        }
    }

    /// Sets the verdict from the bodies' records.
    pub(crate) fn conclude(&mut self, bodies: &mut [SoftBodyReport]) {
        for body in bodies.iter_mut() {
            body.stable = !body.stability_flags.any() && body.failed_frames == 0;
        }
        self.unstable_bodies = (bodies.iter())
            .filter(|b| !b.stable)
            .map(|b| b.name.clone())
            .collect();
        self.stable = self.unstable_bodies.is_empty()
            && self.system_energy_gained.is_none()
            && self.final_state_finite
            && !self.any_error;
    }
}

impl SoftBodyReport {
    /// Records what the audit found for the body at `frame`.
    pub(crate) fn record_audit(&mut self, frame: usize, audit: &BodyAudit) {
        self.stability_flags.record(frame, audit);
    }

    /// An empty record for a body.
    pub(crate) fn new(name: String, material: String, body: &DeformableBody) -> Self {
        let element_kind = match (body.element_order(), body.element_shape()) {
            (ElementOrder::Linear, _) => "linear tetrahedra",
            (ElementOrder::Quadratic, ElementShape::Tetrahedron) => "quadratic tetrahedra",
            (ElementOrder::Quadratic, ElementShape::Hexahedron) => "quadratic hexahedra",
        };
        Self {
            name,
            material,
            element_kind: element_kind.to_owned(),
            elements: body.element_count(),
            nodes: body.node_count(),
            embedded_tets: body.embedding().map(|e| e.mesh().tet_count()),
            mass: body.total_mass(),
            ..Self::default()
        }
    }

    /// Records a frame's outcome.
    pub(crate) fn record(
        &mut self,
        outcome: &Result<AutomaticReport, Error>,
        stability: &mut Stability,
    ) {
        match outcome {
            Ok(report) => {
                self.cost.record(report);
                match report.choice {
                    IntegratorKind::Explicit => self.explicit_frames += 1,
                    IntegratorKind::Implicit => self.implicit_frames += 1,
                }
                self.fell_back_frames += usize::from(report.fell_back);
                if let Some(explicit) = report.explicit {
                    self.explicit_substeps_sum += u64::from(explicit.substeps);
                    self.max_explicit_substeps = self.max_explicit_substeps.max(explicit.substeps);
                    self.max_inverted_elements =
                        self.max_inverted_elements.max(explicit.inverted_elements);
                }
                if let Some(implicit) = report.implicit {
                    self.unconverged_frames += usize::from(!implicit.converged);
                    self.max_inverted_elements =
                        self.max_inverted_elements.max(implicit.inverted_elements);
                }
                stability.inverted_elements |= self.max_inverted_elements > 0;
                if self.explicit_frames > 0 {
                    self.mean_explicit_substeps =
                        self.explicit_substeps_sum as f64 / self.explicit_frames as f64;
                }
            }
            Err(error) => {
                self.failed_frames += 1;
                if self.first_error.is_none() {
                    self.first_error = Some(error.to_string());
                }
                stability.any_error = true;
                stability.non_finite |= matches!(error, Error::NonFiniteState { .. });
            }
        }
    }
}

/// Writes `report` as pretty JSON into `report.json` of the folder `out`.
///
/// # Errors
/// [`OutputError::Io`] if it cannot be serialized or written.
pub(crate) fn write_report(
    out: &std::path::Path,
    report: &impl Serialize,
) -> Result<(), crate::output::OutputError> {
    use crate::output::OutputError;
    let path = out.join("report.json");
    let json = serde_json::to_string_pretty(report).map_err(|e| OutputError::Io {
        path: path.clone(),
        source: std::io::Error::other(e),
    })?;
    std::fs::write(&path, json).map_err(OutputError::io(&path))
}

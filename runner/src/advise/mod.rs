//! The advisor (`rapier-fvm advise`): a cheaper scene whose probes stay within a target
//! error of the scene as written.
//!
//! It runs the scene as written over a window (the reference: what each soft body needed, its
//! peak strain, rotation and contact frames, and the time per frame), then each alternative of
//! [`candidates`] alone (another model, linear elements, half the cells; another integrator, a
//! looser Newton tolerance, half the coupling substeps), measuring its error (the largest over
//! the probes of the L2 distance of their samples from the reference's, relative to the
//! reference's motion) and its time per frame (stopped past twice the reference's stepping
//! time and a second: it could not be chosen); then chooses greedily a cheap set of changes
//! whose errors add up to at most the target, runs that set, and keeps it only once its
//! measured error is within the target and it is faster than the scene. The reference runs
//! three times: first for its probes (a process's first run also pays for its thread pool's
//! start), then before and after the alternatives for its time; the spread of those two times
//! per frame (at least 3 %) is the smallest saving counted.
//!
//! The coarser mesh's error is also the estimate of the scene's own discretization error: with
//! errors `O(hᵖ)`, Richardson's `|q_h − q_rh| / (rᵖ − 1)` for the refinement ratio `r` from the
//! coarser mesh (the largest over the axes of the given cells over the coarser ones: 2 for even
//! counts, 1.5 from 3 to 2) and the lowest order, `p = 1`.
//!
//! Written into the output folder: `recommended.toml` (the scene's text with the chosen edits,
//! the files it names by absolute paths), `advice.json` (the [`Advice`]) and `trials/<n>/`,
//! each run's own output folder.

mod advisor;
mod candidates;
mod checked;
mod choose;
mod entries;
mod files;
mod trial;

pub use advisor::{advise, advise_text};
pub use candidates::{Candidate, Group, candidates};

use crate::scene::SceneError;
use crate::sim::BodyNeeds;
use serde::Serialize;
use std::path::PathBuf;

/// What to advise on.
#[derive(Debug, Clone, PartialEq)]
pub struct AdviseOptions {
    /// The largest probe error allowed (relative: 0.05 for 5 %).
    pub target: f64,
    /// The window each run covers (s); default the scene's duration.
    pub window: Option<f64>,
    /// The output folder.
    pub out: PathBuf,
}

/// Advice that could not be given.
#[derive(Debug, thiserror::Error)]
pub enum AdviseError {
    /// The scene as written is malformed (the file, line and key named).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene as written could not be read or run, or ran unstable (it is the reference
    /// every alternative is measured against).
    #[error("{0}")]
    Reference(String),
    /// The scene has no probe to hold within the target.
    #[error("{0}: the scene has no [[probe]] to hold within the target")]
    NoProbes(String),
    /// The scene is a 2D one.
    #[error("{0}: a 2D scene (dimension = 2); advise takes 3D scenes")]
    Planar(String),
    /// The window is not a positive, finite time.
    #[error("the duration must be positive and finite (s), got {0}")]
    Duration(f64),
    /// The target is not a positive fraction.
    #[error("the target must be a relative error in (0, 1), got {0}")]
    Target(f64),
    /// The output folder would overwrite the scene file, or empty a folder advise did not
    /// write; the message says which.
    #[error("{0}; choose another --out")]
    Overwrite(String),
    /// The recommended scene's text could not be edited.
    #[error("{0}")]
    Edit(String),
    /// A file or folder could not be written.
    #[error("{0}: {1}")]
    Write(PathBuf, std::io::Error),
}

/// The advice, also written as `advice.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Advice {
    /// The scene file.
    pub scene_file: String,
    /// The largest probe error allowed (relative).
    pub target: f64,
    /// The window every run covered (s): whole frames, at least one.
    pub window_s: f64,
    /// The scene as written: time per frame (ms), the mean of its timed runs (before and after
    /// the alternatives).
    pub reference_ms_per_frame: f64,
    /// The relative spread of the reference's two times per frame.
    pub reference_spread: f64,
    /// What the advice warns of (times too noisy to choose by).
    pub warnings: Vec<String>,
    /// Per soft body: what it needed, what it was given, its alternatives.
    pub soft_bodies: Vec<BodyAdvice>,
    /// The scene's alternatives: integrators, Newton tolerance, coupling substeps.
    pub scene_alternatives: Vec<Alternative>,
    /// The set of changes recommended, run.
    pub recommendation: Recommendation,
}

/// A soft body: what the scene needed of it, what it was given, what else was measured.
#[derive(Debug, Clone, Serialize)]
pub struct BodyAdvice {
    /// Its name.
    pub name: String,
    /// Peak strain, rotation and contact frames over the reference's window.
    pub needs: BodyNeeds,
    /// Its material model as given (the scene files' name).
    pub model: String,
    /// Its material's label (the scene's `label`, or the model and Young's modulus).
    pub material: String,
    /// Its elements as given (kind and count).
    pub elements: String,
    /// Its discretization error estimated from the coarser mesh, if that ran stable (relative;
    /// see the module).
    pub discretization_error: Option<f64>,
    /// The alternatives measured.
    pub alternatives: Vec<Alternative>,
}

/// An alternative, run alone.
#[derive(Debug, Clone, Serialize)]
pub struct Alternative {
    /// What it changes.
    pub label: String,
    /// Its edits, `key = value`.
    pub edits: Vec<String>,
    /// Its largest probe error against the reference (relative), if it ran and the error is
    /// finite (the verdict says when it is not).
    pub error: Option<f64>,
    /// The probe of that error.
    pub worst_probe: Option<String>,
    /// Its time per frame (ms), if it ran.
    pub ms_per_frame: Option<f64>,
    /// Whether it ran stable (the runner's verdict), if it ran.
    pub stable: Option<bool>,
    /// Chosen, or why not.
    pub verdict: String,
    /// Its run's folder.
    pub folder: String,
}

/// The changes recommended: predicted, then measured.
#[derive(Debug, Clone, Serialize)]
pub struct Recommendation {
    /// The changes (labels).
    pub changes: Vec<String>,
    /// The file written (the scene with the changes).
    pub file: String,
    /// The sum of the changes' errors alone (relative).
    pub predicted_error: f64,
    /// Its largest probe error, run (relative).
    pub measured_error: f64,
    /// The probe of that error.
    pub worst_probe: String,
    /// The predicted time per frame (ms).
    pub predicted_ms_per_frame: f64,
    /// Its time per frame, run (ms).
    pub measured_ms_per_frame: f64,
    /// The reference's time per frame over the recommendation's.
    pub speed_up: f64,
    /// Whether the measured error is within the target and the run stable.
    pub within_target: bool,
}

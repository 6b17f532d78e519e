//! `[world]`: gravity, the frame step and how long the scene runs.
//!
//! ```toml
//! [world]
//! dimension = 3               # default; 2 makes the file a 2D scene (`crate::planar`)
//! gravity = [0.0, -9.81, 0.0] # m/s², default
//! dt = 0.016666666666666666   # frame step (s), default 1/60
//! duration = 2.0              # simulated time (s), required
//! coupling_substeps = 4       # rapier steps per frame, soft bodies stepped between, default 4
//! sleep_speed = 1e-3          # nodes slower than this (m/s) count as still, default 1e-3
//! time_until_sleep = 0.5      # bodies still this long (s) fall asleep, default 0.5; inf: never
//! ```

use super::check::Checker;
use serde::Deserialize;

/// The most frames a scene may run (about 46 hours at 60 frames per second).
pub const MAX_FRAMES: f64 = 1e7;

/// The world's settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// 3 if given (a scene with `dimension = 2` is a 2D scene, read by
    /// [`crate::planar::PlanarScene`]).
    pub dimension: Option<u8>,
    /// Gravity (m/s²); default `[0, -9.81, 0]`.
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Frame step (s); default 1/60.
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Simulated time (s), required.
    pub duration: f64,
    /// Rapier steps per frame with the soft bodies stepped between them; default 4.
    #[serde(default = "default_coupling_substeps")]
    pub coupling_substeps: u32,
    /// Speed (m/s) below which a body's nodes count as still; default 1e-3
    /// ([`SleepSettings`](rapier_fvm::coupling::SleepSettings)).
    #[serde(default = "default_sleep_speed")]
    pub sleep_speed: f64,
    /// How long (s) a body stays still before it falls asleep; default 0.5, `inf` never.
    #[serde(default = "default_time_until_sleep")]
    pub time_until_sleep: f64,
}

fn default_sleep_speed() -> f64 {
    rapier_fvm::coupling::SleepSettings::default().speed_threshold
}

fn default_time_until_sleep() -> f64 {
    rapier_fvm::coupling::SleepSettings::default().time_until_sleep
}

fn default_gravity() -> [f64; 3] {
    [0.0, -9.81, 0.0]
}

fn default_dt() -> f64 {
    1.0 / 60.0
}

fn default_coupling_substeps() -> u32 {
    4
}

impl WorldSpec {
    /// The number of frames: the duration over the frame step, rounded to the nearest.
    pub fn frames(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }

    /// Checks the values.
    pub(crate) fn check(&self, c: &mut Checker<'_>) {
        // A 2D scene is refused before it is read as a 3D one (`Scene::parse`).
        if self.dimension.is_some_and(|d| d != 3) {
            c.fail("world.dimension", "must be 2 (a 2D scene) or 3");
        }
        c.finite_vector("world.gravity", self.gravity);
        c.positive("world.dt", self.dt, "s");
        // rapier steps in f32: a step that rounds to zero there would pause every frame.
        let substep = self.dt as f32 / self.coupling_substeps.max(1) as f32;
        if self.dt > 0.0 && !(substep > 0.0 && substep.is_finite()) {
            c.fail(
                "world.dt",
                format!(
                    "{} s split into {} coupling substeps is not a positive f32 step for rapier",
                    self.dt, self.coupling_substeps
                ),
            );
        }
        c.positive("world.duration", self.duration, "s");
        if self.dt > 0.0 && self.duration / self.dt > MAX_FRAMES {
            c.fail(
                "world.duration",
                format!(
                    "{} s at dt = {} s is more than {MAX_FRAMES:e} frames",
                    self.duration, self.dt
                ),
            );
        }
        if self.coupling_substeps == 0 {
            c.fail("world.coupling_substeps", "must be at least 1");
        }
        if !(self.sleep_speed >= 0.0 && self.sleep_speed.is_finite()) {
            c.fail(
                "world.sleep_speed",
                "must be a finite speed of at least 0 m/s",
            );
        }
        if self.time_until_sleep.is_nan() || self.time_until_sleep < 0.0 {
            c.fail(
                "world.time_until_sleep",
                "must be at least 0 s (inf: never)",
            );
        }
    }
}

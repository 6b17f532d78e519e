//! `loads = [...]` of a `[[soft_body]]`: what pushes or pulls it besides gravity, each load
//! constant or following keyframes (linear between them, held before the first and after the
//! last), set at the start of every frame to its value at the frame's end, as kinematic bodies
//! are driven.
//!
//! ```toml
//! loads = [
//!   { pressure = 5000.0, region = "chamber" },          # Pa, follower, on the boundary
//!                                                       # triangles of a file's region or a box
//!   { pressure = [{ time = 0.0, value = 0.0 }, { time = 0.5, value = 5e3 }], region = 4 },
//!   { traction = [0.0, -1e3, 0.0], min = [0.49, -1, -1], max = [0.51, 1, 1] },  # Pa, dead load
//!   { body_force = [0.0, 0.0, 50.0] },                  # N/m³ on every node
//!   { tension = 20.0, path = [[-0.5, 0.03, 0.0], [0.5, 0.03, 0.0]] },
//!                                                       # N: a cable through the nodes nearest
//!                                                       # the points, in order
//!   { volume_ratio = [{ time = 0.0, value = 1.0 }, { time = 1.0, value = 1.5 }],
//!     region = "chamber", bulk_modulus = 2.2e9 },       # a chamber: a cavity filled with a
//!                                                       # liquid (Pa, default water's) pumped
//!                                                       # to this many times its rest volume
//! ]
//! ```
//! A pressure or traction acts on the boundary triangles whose three corners the box or region
//! selects; a region's triangles pointing out of the body (a closed inner surface is a
//! cavity). A chamber's triangles must close its cavity
//! ([`Load::Chamber`](rapier_fvm::load::Load::Chamber)): it holds a volume where a pressure
//! holds a force. A cable's path is given as points in the mesh's rest coordinates; its eyelets are
//! the nearest nodes (consecutive repeats dropped).

use super::check::Checker;
use super::soft_body::RegionName;
use serde::Deserialize;

/// A load on a soft body: exactly one of `pressure`, `traction`, `body_force`, `tension`,
/// `volume_ratio`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// A follower pressure (Pa) on the selected boundary.
    pub pressure: Option<Schedule<f64>>,
    /// A dead traction (Pa, world frame) on the selected boundary's rest area.
    pub traction: Option<Schedule<[f64; 3]>>,
    /// A force per unit volume (N/m³, world frame) on every node.
    pub body_force: Option<Schedule<[f64; 3]>>,
    /// A cable's tension (N), with `path`.
    pub tension: Option<Schedule<f64>>,
    /// The cable's path: points (m, rest coordinates) whose nearest nodes are its eyelets.
    pub path: Option<Vec<[f64; 3]>>,
    /// A chamber's volume, as a multiple of its cavity's rest volume (positive).
    pub volume_ratio: Option<Schedule<f64>>,
    /// A chamber's liquid's bulk modulus (Pa, positive); default water's, 2.2e9.
    pub bulk_modulus: Option<f64>,
    /// Lower corner of the box (m, rest coordinates) selecting a pressure's, traction's or
    /// chamber's boundary.
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m, rest coordinates).
    pub max: Option<[f64; 3]>,
    /// The mesh file's region, in place of a box.
    pub region: Option<RegionName>,
}

/// A magnitude over time: a constant, or keyframes.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Schedule<T> {
    /// The same value at every time.
    Constant(T),
    /// Values at times (s), increasing.
    Keyframes(Vec<LoadKeyframe<T>>),
}

/// A load's value at a time.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadKeyframe<T> {
    /// Simulated time (s).
    pub time: f64,
    /// The value (Pa, N/m³, N, or a volume ratio).
    pub value: T,
}

/// A value keyframes interpolate: a number or a vector.
pub trait Interpolated: Copy {
    /// `self + s (other − self)`.
    fn towards(self, other: Self, s: f64) -> Self;
    /// Whether every component is finite.
    fn finite(self) -> bool;
}

impl Interpolated for f64 {
    fn towards(self, other: Self, s: f64) -> Self {
        self + s * (other - self)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Interpolated for [f64; 3] {
    fn towards(self, other: Self, s: f64) -> Self {
        std::array::from_fn(|i| self[i] + s * (other[i] - self[i]))
    }
    fn finite(self) -> bool {
        self.iter().all(|v| v.is_finite())
    }
}

impl<T: Interpolated> Schedule<T> {
    /// The value at time `t` (s): linear between keyframes, held outside them.
    pub fn at(&self, t: f64) -> T {
        let frames = match self {
            Self::Constant(value) => return *value,
            Self::Keyframes(frames) => frames,
        };
        let (first, last) = (&frames[0], &frames[frames.len() - 1]);
        if t <= first.time {
            return first.value;
        }
        for pair in frames.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            if t <= b.time {
                return a.value.towards(b.value, (t - a.time) / (b.time - a.time));
            }
        }
        last.value
    }

    /// Whether it changes over time.
    pub fn varies(&self) -> bool {
        matches!(self, Self::Keyframes(frames) if frames.len() > 1)
    }

    /// Checks the values (finite) and the keyframes (at least one, times finite and
    /// increasing).
    fn check(&self, key: &str, c: &mut Checker<'_>) {
        match self {
            Self::Constant(value) if !value.finite() => c.fail(key, "must be finite"),
            Self::Constant(_) => {}
            Self::Keyframes(frames) if frames.is_empty() => {
                c.fail(key, "give a value or at least one keyframe")
            }
            Self::Keyframes(frames) => {
                for (i, frame) in frames.iter().enumerate() {
                    let key = format!("{key}[{i}]");
                    let after_previous = i == 0 || frame.time > frames[i - 1].time;
                    if !(frame.time.is_finite() && after_previous) {
                        c.fail(
                            &format!("{key}.time"),
                            format!(
                                "keyframe times must be finite and increasing, got {}",
                                frame.time
                            ),
                        );
                    }
                    if !frame.value.finite() {
                        c.fail(&format!("{key}.value"), "must be finite");
                    }
                }
            }
        }
    }
}

/// What a load must name, one of.
pub(crate) const KINDS: &str =
    "give one of `pressure`, `traction`, `body_force`, `tension` or `volume_ratio`";

impl LoadSpec {
    /// Checks a chamber's volume ratio (positive) and bulk modulus (positive, with a volume
    /// ratio only); `key` is the load's key path.
    fn check_chamber(&self, key: &str, c: &mut Checker<'_>) {
        if let Some(s) = &self.volume_ratio {
            s.check(&format!("{key}.volume_ratio"), c);
            let positive = match s {
                Schedule::Constant(r) => *r > 0.0,
                Schedule::Keyframes(frames) => frames.iter().all(|f| f.value > 0.0),
            };
            if !positive {
                c.fail(
                    &format!("{key}.volume_ratio"),
                    "a chamber's volume must be positive",
                );
            }
        }
        match (self.bulk_modulus, self.volume_ratio.is_some()) {
            (Some(_), false) => c.fail(
                &format!("{key}.bulk_modulus"),
                "a bulk modulus is a chamber's (with `volume_ratio`)",
            ),
            (Some(k), true) if !(k.is_finite() && k > 0.0) => c.fail(
                &format!("{key}.bulk_modulus"),
                "a liquid's bulk modulus must be positive and finite",
            ),
            _ => {}
        }
    }

    /// Checks that it names one kind of load with what that kind needs, and the values;
    /// `key` is its key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        let kinds = [
            self.pressure.is_some(),
            self.traction.is_some(),
            self.body_force.is_some(),
            self.tension.is_some(),
            self.volume_ratio.is_some(),
        ];
        if kinds.iter().filter(|&&k| k).count() != 1 {
            c.fail(key, KINDS);
            return;
        }
        let on_surface =
            self.pressure.is_some() || self.traction.is_some() || self.volume_ratio.is_some();
        if on_surface {
            self.selection().check(key, c);
        } else if self.min.is_some() || self.max.is_some() || self.region.is_some() {
            c.fail(
                key,
                "only a `pressure`, a `traction` or a `volume_ratio` acts on a box or region",
            );
        }
        self.check_chamber(key, c);
        if self.tension.is_some() != self.path.is_some() {
            c.fail(
                &format!("{key}.path"),
                "a cable takes a `tension` and a `path`, both",
            );
        }
        if let Some(path) = &self.path {
            if path.len() < 2 {
                c.fail(
                    &format!("{key}.path"),
                    "a cable's path needs at least two points",
                );
            }
            for (i, point) in path.iter().enumerate() {
                c.finite_vector(&format!("{key}.path[{i}]"), *point);
            }
        }
        if let Some(s) = &self.pressure {
            s.check(&format!("{key}.pressure"), c);
        }
        if let Some(s) = &self.traction {
            s.check(&format!("{key}.traction"), c);
        }
        if let Some(s) = &self.body_force {
            s.check(&format!("{key}.body_force"), c);
        }
        if let Some(s) = &self.tension {
            s.check(&format!("{key}.tension"), c);
            let negative = match s {
                Schedule::Constant(t) => *t < 0.0,
                Schedule::Keyframes(frames) => frames.iter().any(|f| f.value < 0.0),
            };
            if negative {
                c.fail(
                    &format!("{key}.tension"),
                    "a cable's tension cannot be negative (it only pulls)",
                );
            }
        }
    }
}

//! `[[rigid_body]]`: a rapier rigid body with one collider: its shape, pose, mass, initial
//! velocity, contact properties, and whether it is fixed, dynamic, or kinematic along
//! keyframes.
//!
//! ```toml
//! [[rigid_body]]
//! name = "ground"
//! kind = "fixed"                                # "fixed", "dynamic" (default) or "kinematic"
//! shape = { half_space = { normal = [0.0, 1.0, 0.0] } }
//! friction = 0.5                                # default 0.5
//!
//! [[rigid_body]]
//! name = "box"
//! shape = { cuboid = { half_extents = [0.05, 0.05, 0.05] } }
//! translation = [0.0, 0.3, 0.0]                 # m, default 0
//! rotation = [0.0, 0.0, 0.0]                    # scaled axis (rad), default 0
//! density = 2000.0                              # kg/m³, or `mass` (kg); default 1000 kg/m³
//! linvel = [0.0, 0.0, 0.0]                      # m/s, default 0
//! angvel = [0.0, 0.0, 0.0]                      # rad/s, default 0
//!
//! [[rigid_body]]
//! name = "finger"
//! kind = "kinematic"
//! shape = { cuboid = { half_extents = [0.005, 0.02, 0.02] } }
//! keyframes = [{ time = 0.0, translation = [0.03, 0.025, 0.0] },
//!              { time = 0.5, translation = [0.03, 0.125, 0.0] }]
//! ```
//! Shapes: `ball = { radius }`, `cuboid = { half_extents }`, `capsule = { half_height, radius }`
//! and `cylinder = { half_height, radius }` (along y), `half_space = { normal }` (fixed bodies
//! only; the plane passes through the translation), `trimesh = { file, scale }` (an `.obj` or
//! `.stl` surface relative to the scene file, `scale` in m per file unit, default 1; fixed or
//! kinematic bodies only). A kinematic body's translation is interpolated linearly between
//! its keyframes (times in s, increasing) and held before the first and after the last (so it
//! starts at the first keyframe's translation); its rotation stays as given.

use super::check::Checker;
use serde::Deserialize;

/// A rigid body and its collider.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBodySpec {
    /// Its name, unique among all bodies.
    pub name: String,
    /// The collider's shape.
    pub shape: ShapeSpec,
    /// How it moves; default dynamic.
    #[serde(default)]
    pub kind: RigidKind,
    /// Position (m); default 0.
    #[serde(default)]
    pub translation: [f64; 3],
    /// Orientation as a scaled axis (rad); default 0.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Density (kg/m³); default 1000 unless `mass` is given.
    pub density: Option<f64>,
    /// Mass (kg), instead of `density`.
    pub mass: Option<f64>,
    /// Initial linear velocity (m/s); default 0.
    #[serde(default)]
    pub linvel: [f64; 3],
    /// Initial angular velocity (rad/s); default 0.
    #[serde(default)]
    pub angvel: [f64; 3],
    /// Coulomb friction coefficient; default 0.5.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Restitution coefficient (against other rigid bodies), 0 to 1; default 0.
    #[serde(default)]
    pub restitution: f64,
    /// A kinematic body's prescribed translation over time.
    #[serde(default)]
    pub keyframes: Vec<KeyframeSpec>,
}

fn default_friction() -> f64 {
    0.5
}

/// How a rigid body moves.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RigidKind {
    /// Never moves.
    Fixed,
    /// Moves under forces and contacts.
    #[default]
    Dynamic,
    /// Follows its keyframes, pushing what it meets.
    Kinematic,
}

/// A collider shape; lengths in m.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// A ball.
    Ball {
        /// Radius (m).
        radius: f64,
    },
    /// A box.
    Cuboid {
        /// Half extents (m).
        half_extents: [f64; 3],
    },
    /// A capsule along y.
    Capsule {
        /// Half height of the segment (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
    /// A cylinder along y.
    Cylinder {
        /// Half height (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
    /// The half-space below a plane through the body's translation.
    HalfSpace {
        /// The plane's outward normal (any length, not zero).
        normal: [f64; 3],
    },
    /// A triangle mesh from an `.obj` or `.stl` file.
    Trimesh {
        /// The file, relative to the scene file.
        file: String,
        /// Metres per file unit; default 1.
        #[serde(default = "unit_scale")]
        scale: f64,
    },
}

fn unit_scale() -> f64 {
    1.0
}

/// A kinematic body's translation at a time.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeSpec {
    /// Simulated time (s).
    pub time: f64,
    /// Translation (m).
    pub translation: [f64; 3],
}

impl RigidBodySpec {
    /// Checks the values; `key` is the body's key path.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        self.check_shape(&format!("{key}.shape"), c);
        for (name, value) in [
            ("translation", self.translation),
            ("rotation", self.rotation),
            ("linvel", self.linvel),
            ("angvel", self.angvel),
        ] {
            c.finite_vector(&format!("{key}.{name}"), value);
        }
        match (self.density, self.mass) {
            (Some(_), Some(_)) => {
                c.fail(&format!("{key}.mass"), "give `density` or `mass`, not both")
            }
            (Some(density), None) => c.positive(&format!("{key}.density"), density, "kg/m³"),
            (None, Some(mass)) => c.positive(&format!("{key}.mass"), mass, "kg"),
            (None, None) => {}
        }
        c.non_negative(&format!("{key}.friction"), self.friction, "dimensionless");
        if !(0.0..=1.0).contains(&self.restitution) {
            c.fail(
                &format!("{key}.restitution"),
                format!("must lie in [0, 1], got {}", self.restitution),
            );
        }
        if self.kind != RigidKind::Kinematic && !self.keyframes.is_empty() {
            c.fail(
                &format!("{key}.keyframes"),
                "only a `kinematic` body follows keyframes",
            );
        }
        if self.kind != RigidKind::Dynamic && (self.linvel != [0.0; 3] || self.angvel != [0.0; 3]) {
            c.fail(
                &format!("{key}.linvel"),
                "only a `dynamic` body starts with a velocity (a kinematic one follows its keyframes)",
            );
        }
        if !self.keyframes.is_empty() && self.translation != [0.0; 3] {
            c.fail(
                &format!("{key}.translation"),
                "a keyframed body takes its translation from its keyframes: leave it out",
            );
        }
        let mut previous = f64::NEG_INFINITY;
        for (i, frame) in self.keyframes.iter().enumerate() {
            let key = format!("{key}.keyframes[{i}]");
            if !frame.time.is_finite() || frame.time <= previous {
                c.fail(
                    &format!("{key}.time"),
                    format!(
                        "keyframe times must be finite and increasing, got {}",
                        frame.time
                    ),
                );
            }
            previous = frame.time;
            c.finite_vector(&format!("{key}.translation"), frame.translation);
        }
    }

    fn check_shape(&self, key: &str, c: &mut Checker<'_>) {
        match &self.shape {
            ShapeSpec::Ball { radius } => c.positive(&format!("{key}.ball.radius"), *radius, "m"),
            ShapeSpec::Cuboid { half_extents } => {
                for (i, h) in half_extents.iter().enumerate() {
                    c.positive(&format!("{key}.cuboid.half_extents[{i}]"), *h, "m");
                }
            }
            ShapeSpec::Capsule {
                half_height,
                radius,
            } => {
                c.positive(&format!("{key}.capsule.half_height"), *half_height, "m");
                c.positive(&format!("{key}.capsule.radius"), *radius, "m");
            }
            ShapeSpec::Cylinder {
                half_height,
                radius,
            } => {
                c.positive(&format!("{key}.cylinder.half_height"), *half_height, "m");
                c.positive(&format!("{key}.cylinder.radius"), *radius, "m");
            }
            ShapeSpec::HalfSpace { normal } => {
                let length = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
                if !(length.is_finite() && length > 0.0) {
                    c.fail(
                        &format!("{key}.half_space.normal"),
                        format!("must be finite and not zero, got {normal:?}"),
                    );
                }
                if self.kind != RigidKind::Fixed {
                    c.fail(key, "a half-space must belong to a `fixed` body");
                }
            }
            ShapeSpec::Trimesh { scale, .. } => {
                c.positive(&format!("{key}.trimesh.scale"), *scale, "m per file unit");
                if self.kind == RigidKind::Dynamic {
                    c.fail(
                        key,
                        "a triangle mesh must belong to a `fixed` or `kinematic` body",
                    );
                }
            }
        }
    }

    /// The keyframed translation (m) at time `t` (s): linear between keyframes, held outside
    /// them; `None` without keyframes.
    pub fn keyframe_translation(&self, t: f64) -> Option<[f64; 3]> {
        let frames = &self.keyframes;
        let first = frames.first()?;
        if t <= first.time {
            return Some(first.translation);
        }
        for pair in frames.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            if t <= b.time {
                let s = (t - a.time) / (b.time - a.time);
                return Some(std::array::from_fn(|i| {
                    a.translation[i] + s * (b.translation[i] - a.translation[i])
                }));
            }
        }
        frames.last().map(|last| last.translation)
    }
}

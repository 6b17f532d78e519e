//! 2D scene files: soft bodies on triangles and rapier2d rigid bodies in the plane (x right,
//! y up), in SI units, read and checked with the same errors as 3D scenes (file, line, key).
//!
//! ```toml
//! [world]
//! dimension = 2               # required: this is a 2D scene
//! gravity = [0.0, -9.81]      # m/s², default
//! dt = 0.016666666666666666   # frame step (s), default 1/60
//! duration = 3.0              # simulated time (s), required
//! coupling_substeps = 4       # the fewest rapier steps per frame, default 4 (more are taken
//!                             # when contacts with light rigid bodies need them)
//! friction = 0.5              # between soft bodies and colliders, default 0.5
//! integrator = "automatic"    # default; "implicit": backward Euler, one step per coupling
//!                             # substep, for bodies within reach of no dynamic rigid body
//!                             # or collider corner and attached to no dynamic rigid body
//!                             # (the others step explicitly);
//!                             # "automatic": implicit there when the explicit step would
//!                             # need more than 400 substeps; "explicit"
//!
//! [[soft_body]]
//! name = "block"
//! mesh = { rectangle = { size = [0.2, 0.1], cells = [10, 5] } }  # lower left corner at the origin
//! # mesh = { disk = { radius = 0.05, rings = 4 } }                # centred at the origin
//! # mesh = { polygon = { outline = [[0, 0], [1, 0], [0, 1]], edge_length = 0.05 } }
//! plane = "strain"            # required: "strain" (a thick body) or "stress" (a thin sheet)
//! thickness = 0.1             # m, required: masses and forces are per this thickness
//! material = { model = "stable_neo_hookean", young = 1e5, poisson = 0.3, density = 1000.0 }
//! damping = { stiffness_time = 1e-3 }  # as 3D scenes' (optional)
//! elements = "linear"         # or "quadratic" (6-node triangles), default linear
//! volumetric = "per_element"  # or "nodal_average", "element_average" (quadratic), as in 3D
//! translation = [-0.1, 0.0]   # m, added to the mesh's coordinates, default 0
//! velocity = [0.0, 0.0]       # m/s, default 0
//! pinned = [{ min = [-1.0, -1.0], max = [1.0, 0.001] }]  # nodes held where they start: those
//!                             # whose rest position (m, mesh coordinates) lies in a box
//! attach = [{ min = [0.19, 0.0], max = [0.2, 0.1], rigid = "handle" }]  # nodes in a box glued
//!                             # where they start to a rigid body (damped springs of the body's
//!                             # contact stiffness, `PlanarCoupling::glue`)
//!
//! [[rigid_body]]
//! name = "ground"
//! kind = "fixed"              # or "dynamic" (default)
//! shape = { cuboid = { half_extents = [2.0, 0.5] } }  # or { ball = { radius = 0.05 } }
//! translation = [0.0, -0.5]   # m
//! rotation = 0.0              # rad, counter-clockwise, default 0
//! velocity = [0.0, 0.0]       # m/s, default 0
//! angular_velocity = 0.0      # rad/s, default 0
//! density = 1000.0            # kg/m² of the shape's area (rapier2d's), default 1000
//! ```
//! `[output]` is as in 3D scenes; `[[probe]]` entries are in [`super::probe`].

use super::probe::PlanarProbeSpec;
use crate::scene::check::{Checker, check_body_names, check_probe_names};
use crate::scene::material::{DampingSpec, MaterialSpec};
use crate::scene::settings::OutputSpec;
use crate::scene::soft_body::VolumetricSpec;
use crate::scene::{SceneError, SceneSource};
use serde::Deserialize;
use std::path::Path;

/// A 2D scene as written in its file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarScene {
    /// The scene's name (report and file names); default the file's stem.
    pub name: Option<String>,
    /// World settings.
    pub world: PlanarWorldSpec,
    /// The soft bodies.
    #[serde(default)]
    pub soft_body: Vec<PlanarSoftBodySpec>,
    /// The rigid bodies.
    #[serde(default)]
    pub rigid_body: Vec<PlanarRigidBodySpec>,
    /// Output settings (those of 3D scenes).
    #[serde(default)]
    pub output: OutputSpec,
    /// The probes.
    #[serde(default)]
    pub probe: Vec<PlanarProbeSpec>,
    /// The file and its text, to place later errors.
    #[serde(skip)]
    pub source: SceneSource,
}

/// `[world]` of a 2D scene.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarWorldSpec {
    /// Must be 2.
    pub dimension: u8,
    /// Gravity (m/s²); default `[0, -9.81]`.
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 2],
    /// Frame step (s); default 1/60.
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Simulated time (s), required.
    pub duration: f64,
    /// The fewest rapier steps per frame; default 4.
    #[serde(default = "default_substeps")]
    pub coupling_substeps: u32,
    /// Friction coefficient between soft bodies and colliders; default 0.5.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// How the soft bodies step; default automatic.
    #[serde(default)]
    pub integrator: PlanarIntegratorSpec,
}

/// How a 2D scene's soft bodies step, by its scene-file name.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanarIntegratorSpec {
    /// Symplectic Euler substeps.
    Explicit,
    /// Backward Euler, one step per coupling substep, where no dynamic rigid body or collider
    /// corner is within reach and no attachment to a dynamic rigid body holds the body
    /// (explicit there).
    Implicit,
    /// Implicit where it may be and the explicit step would need more than 400 substeps.
    #[default]
    Automatic,
}

fn default_gravity() -> [f64; 2] {
    [0.0, -9.81]
}

fn default_dt() -> f64 {
    1.0 / 60.0
}

fn default_substeps() -> u32 {
    4
}

fn default_friction() -> f64 {
    0.5
}

/// A 2D soft body.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarSoftBodySpec {
    /// Its name, unique among bodies.
    pub name: String,
    /// Its triangle mesh.
    pub mesh: PlanarMeshSpec,
    /// Why it is flat.
    pub plane: PlaneSpec,
    /// Its thickness (m).
    pub thickness: f64,
    /// Its material.
    pub material: MaterialSpec,
    /// Rayleigh damping; default none.
    pub damping: Option<DampingSpec>,
    /// Added to the mesh's coordinates (m); default 0.
    #[serde(default)]
    pub translation: [f64; 2],
    /// Initial velocity (m/s); default 0.
    #[serde(default)]
    pub velocity: [f64; 2],
    /// Boxes of rest positions (m, mesh coordinates) whose nodes are pinned.
    #[serde(default)]
    pub pinned: Vec<PlanarBoxSpec>,
    /// Linear (3-node) or quadratic (6-node) triangles; default linear.
    #[serde(default)]
    pub elements: PlanarElementsSpec,
    /// How the volumetric energy is evaluated (as in 3D scenes); default per element.
    #[serde(default)]
    pub volumetric: VolumetricSpec,
    /// Nodes glued to rigid bodies.
    #[serde(default)]
    pub attach: Vec<PlanarAttachSpec>,
}

/// The nodes whose rest position (m, mesh coordinates) lies in the box `min`..`max`, glued
/// where they start to the rigid body `rigid`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarAttachSpec {
    /// Lower corner (m).
    pub min: [f64; 2],
    /// Upper corner (m).
    pub max: [f64; 2],
    /// The rigid body's name.
    pub rigid: String,
}

impl PlanarBoxSpec {
    /// Whether `p` (m) lies in the box, bounds included.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| (self.min[k]..=self.max[k]).contains(&p[k]))
    }

    fn check(&self, key: &str, c: &mut Checker<'_>) {
        let ordered = (0..2).all(|k| self.min[k] <= self.max[k]);
        let finite = self.min.iter().chain(&self.max).all(|v| v.is_finite());
        if !(ordered && finite) {
            c.fail(key, "`min` must be finite and below `max` on each axis (m)");
        }
    }
}

/// A triangle mesh generator.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum PlanarMeshSpec {
    /// A rectangle of `size` (m) from the origin, `cells` along x and y.
    Rectangle {
        /// Width and height (m).
        size: [f64; 2],
        /// Cells along x and y (two triangles each).
        cells: [usize; 2],
    },
    /// A disk of `radius` (m) centred at the origin, in `rings` rings of triangles.
    Disk {
        /// Radius (m).
        radius: f64,
        /// Rings of triangles.
        rings: usize,
    },
    /// A polygon's inside, triangulated with edges of about `edge_length` (m).
    Polygon {
        /// The vertices (m), in order, either winding.
        outline: Vec<[f64; 2]>,
        /// The triangles' longest edge (m), about.
        edge_length: f64,
    },
}

/// The triangles of a 2D body.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanarElementsSpec {
    /// 3-node triangles.
    #[default]
    Linear,
    /// 6-node triangles: mid-edge nodes added to the mesh.
    Quadratic,
}

/// The plane model, by its scene-file name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlaneSpec {
    /// Plane stress (a thin sheet, `σ₃ⱼ = 0`).
    Stress,
    /// Plane strain (a thick body, `ε₃ⱼ = 0`).
    Strain,
}

/// A box `min`..`max` (m).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarBoxSpec {
    /// Lower corner (m).
    pub min: [f64; 2],
    /// Upper corner (m).
    pub max: [f64; 2],
}

/// A rigid body of rapier2d.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarRigidBodySpec {
    /// Its name, unique among bodies.
    pub name: String,
    /// Fixed or dynamic; default dynamic.
    #[serde(default)]
    pub kind: PlanarRigidKind,
    /// Its collider's shape.
    pub shape: PlanarShapeSpec,
    /// Position of its centre (m).
    #[serde(default)]
    pub translation: [f64; 2],
    /// Rotation (rad, counter-clockwise); default 0.
    #[serde(default)]
    pub rotation: f64,
    /// Initial velocity (m/s); default 0.
    #[serde(default)]
    pub velocity: [f64; 2],
    /// Initial angular velocity (rad/s); default 0.
    #[serde(default)]
    pub angular_velocity: f64,
    /// Density (kg/m² of the shape's area); default 1000.
    #[serde(default = "default_density")]
    pub density: f64,
}

fn default_density() -> f64 {
    1000.0
}

/// How a rigid body moves.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanarRigidKind {
    /// Never moves.
    Fixed,
    /// Moves under gravity and contacts.
    #[default]
    Dynamic,
}

/// A collider shape.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum PlanarShapeSpec {
    /// A rectangle of half extents (m).
    Cuboid {
        /// Half width and half height (m).
        half_extents: [f64; 2],
    },
    /// A disk of `radius` (m).
    Ball {
        /// Radius (m).
        radius: f64,
    },
}

impl PlanarScene {
    /// Parses and checks `text`, the content of the 2D scene file `path`.
    ///
    /// # Errors
    /// A [`SceneError`] naming the file, line and key of what is malformed.
    pub fn parse(path: impl AsRef<Path>, text: String) -> Result<Self, SceneError> {
        let source = SceneSource {
            path: path.as_ref().to_path_buf(),
            text,
        };
        let mut scene: Self = crate::scene::deserialize(&source)?;
        scene.source = source;
        scene.check()?;
        Ok(scene)
    }

    /// The scene's name: `name`, or the file's stem.
    pub fn display_name(&self) -> String {
        self.source.name_or_stem(self.name.as_deref())
    }

    /// The values and references a type cannot check.
    fn check(&self) -> Result<(), SceneError> {
        let mut c = Checker::new(&self.source);
        let w = &self.world;
        if w.dimension != 2 {
            c.fail("world.dimension", "a 2D scene has dimension 2");
        }
        c.finite_vector("world.gravity", [w.gravity[0], w.gravity[1], 0.0]);
        c.positive("world.dt", w.dt, "s");
        c.positive("world.duration", w.duration, "s");
        if w.duration / w.dt > crate::scene::world::MAX_FRAMES {
            c.fail("world.duration", "needs more than ten million frames");
        }
        if !(1..=256).contains(&w.coupling_substeps) {
            c.fail("world.coupling_substeps", "must lie in 1 to 256");
        }
        c.non_negative("world.friction", w.friction, "dimensionless");
        let soft: Vec<&str> = self.soft_body.iter().map(|b| b.name.as_str()).collect();
        let rigid: Vec<&str> = self.rigid_body.iter().map(|b| b.name.as_str()).collect();
        check_body_names(&soft, &rigid, &mut c);
        for (i, body) in self.soft_body.iter().enumerate() {
            body.check(&format!("soft_body[{i}]"), &rigid, &mut c);
        }
        for (i, body) in self.rigid_body.iter().enumerate() {
            body.check(&format!("rigid_body[{i}]"), &mut c);
        }
        self.output.check(w.duration, &mut c);
        check_probe_names(self.probe.iter().map(|p| p.name.as_str()), &mut c);
        for (i, probe) in self.probe.iter().enumerate() {
            probe.check(&format!("probe[{i}]"), &soft, &rigid, &mut c);
        }
        c.finish()
    }
}

impl PlanarSoftBodySpec {
    fn check(&self, key: &str, rigid: &[&str], c: &mut Checker<'_>) {
        c.positive(&format!("{key}.thickness"), self.thickness, "m");
        self.material.check(&format!("{key}.material"), c);
        if let Some(damping) = &self.damping {
            damping.check(&format!("{key}.damping"), c);
        }
        let [tx, ty] = self.translation;
        c.finite_vector(&format!("{key}.translation"), [tx, ty, 0.0]);
        let [vx, vy] = self.velocity;
        c.speed(&format!("{key}.velocity"), [vx, vy, 0.0]);
        for (i, pinned) in self.pinned.iter().enumerate() {
            pinned.check(&format!("{key}.pinned[{i}]"), c);
        }
        for (i, glue) in self.attach.iter().enumerate() {
            let key = format!("{key}.attach[{i}]");
            let region = PlanarBoxSpec {
                min: glue.min,
                max: glue.max,
            };
            region.check(&key, c);
            if !rigid.contains(&glue.rigid.as_str()) {
                c.fail(
                    &format!("{key}.rigid"),
                    format!("no rigid body is named {:?}", glue.rigid),
                );
            }
        }
    }
}

impl PlanarRigidBodySpec {
    fn check(&self, key: &str, c: &mut Checker<'_>) {
        match self.shape {
            PlanarShapeSpec::Cuboid { half_extents } => {
                for (k, half) in half_extents.iter().enumerate() {
                    c.positive(&format!("{key}.shape.cuboid.half_extents[{k}]"), *half, "m");
                }
            }
            PlanarShapeSpec::Ball { radius } => {
                c.positive(&format!("{key}.shape.ball.radius"), radius, "m");
            }
        }
        let [tx, ty] = self.translation;
        c.finite_vector(&format!("{key}.translation"), [tx, ty, 0.0]);
        if !self.rotation.is_finite() {
            c.fail(&format!("{key}.rotation"), "must be finite (rad)");
        }
        let [vx, vy] = self.velocity;
        c.speed(&format!("{key}.velocity"), [vx, vy, 0.0]);
        if !self.angular_velocity.is_finite() {
            c.fail(&format!("{key}.angular_velocity"), "must be finite (rad/s)");
        }
        c.positive(&format!("{key}.density"), self.density, "kg/m²");
    }
}

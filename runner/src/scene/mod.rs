//! Scene files: a mixed rigid/soft world described in TOML, in SI units.
//!
//! A scene has a `name` (default: the file's stem) and these tables, each in its own module:
//! - [`world`]: `[world]` gravity (m/s²), frame step `dt` (s), `duration` (s), coupling
//!   substeps;
//! - [`soft_body`]: `[[soft_body]]` entries, with their [`mesh`] (generator or file) and
//!   [`material`] (model, E in Pa, ν, ρ in kg/m³, Rayleigh damping), placement, initial
//!   velocity (m/s; angular, rad/s; per region), friction, pinned regions and attachments;
//! - [`rigid_body`]: `[[rigid_body]]` entries: shape, pose, density or mass, velocity, and
//!   fixed / dynamic / kinematic (keyframed) motion;
//! - [`settings`]: `[contact]`, `[integrator]` and `[output]`;
//! - [`probe`]: `[[probe]]` entries sampled every frame.
//!
//! [`edit`] sets values at key paths in a scene's text before it is read (overrides,
//! the advisor's alternatives).
//!
//! Its soft bodies must fit in memory: [`budget`] estimates what their meshes need from their
//! cell counts and refuses a scene that would need more than there is.
//!
//! `assets/scenes/README.md` lists every key with its unit and default.
//!
//! Reading a scene ([`Scene::load`]) fails with a [`SceneError`] naming the file, the line and
//! the key path for TOML syntax errors, unknown keys, missing keys, wrong types, non-physical
//! values and references to bodies that do not exist. Keys left out take the documented
//! defaults; a key given a wrong value is never replaced by one.

pub mod budget;
pub(crate) mod check;
pub mod edit;
mod error;
pub mod load;
pub mod material;
pub mod mesh;
pub mod probe;
pub mod rigid_body;
pub mod settings;
pub mod soft_body;
pub mod world;

pub use budget::MemoryBudget;
pub use error::{SceneError, SceneSource};

use check::Checker;
use probe::ProbeSpec;
use rigid_body::RigidBodySpec;
use serde::Deserialize;
use settings::{ContactSpec, IntegratorSpec, OutputSpec};
use soft_body::SoftBodySpec;
use std::path::Path;
use world::WorldSpec;

/// A scene as written in its file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The scene's name (report and file names); default the file's stem.
    pub name: Option<String>,
    /// World settings.
    pub world: WorldSpec,
    /// The soft bodies.
    #[serde(default)]
    pub soft_body: Vec<SoftBodySpec>,
    /// The rigid bodies.
    #[serde(default)]
    pub rigid_body: Vec<RigidBodySpec>,
    /// Contact settings.
    #[serde(default)]
    pub contact: ContactSpec,
    /// Integrator settings.
    #[serde(default)]
    pub integrator: IntegratorSpec,
    /// Output settings.
    #[serde(default)]
    pub output: OutputSpec,
    /// The probes.
    #[serde(default)]
    pub probe: Vec<ProbeSpec>,
    /// The file and its text, to place later errors (a mesh file that cannot be read).
    #[serde(skip)]
    pub source: SceneSource,
    /// The memory the soft bodies may take, checked when the scene is read and as its mesh files
    /// are read (see [`budget`]).
    #[serde(skip)]
    pub budget: MemoryBudget,
}

impl Scene {
    /// Reads, parses and checks the scene file at `path`, its soft bodies against the memory
    /// available ([`MemoryBudget::available`]).
    ///
    /// # Errors
    /// A [`SceneError`] if the file cannot be read, the scene is malformed or its soft bodies
    /// would need more memory than there is.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, SceneError> {
        Self::load_within(path, MemoryBudget::available())
    }

    /// [`Scene::load`] with the soft bodies checked against `budget`.
    ///
    /// # Errors
    /// Those of [`Scene::load`].
    pub fn load_within(path: impl AsRef<Path>, budget: MemoryBudget) -> Result<Self, SceneError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            file: path.to_path_buf(),
            line: None,
            key: None,
            message: format!("cannot read the scene: {e}"),
        })?;
        Self::parse_within(path, text, budget)
    }

    /// Parses and checks `text`, the content of the scene file `path` (used for messages and to
    /// resolve the mesh files it names), its soft bodies against the memory available.
    ///
    /// # Errors
    /// A [`SceneError`] if the scene is malformed or its soft bodies would need more memory
    /// than there is.
    pub fn parse(path: impl AsRef<Path>, text: String) -> Result<Self, SceneError> {
        Self::parse_within(path, text, MemoryBudget::available())
    }

    /// [`Scene::parse`] with the soft bodies checked against `budget`.
    ///
    /// # Errors
    /// Those of [`Scene::parse`].
    pub fn parse_within(
        path: impl AsRef<Path>,
        text: String,
        budget: MemoryBudget,
    ) -> Result<Self, SceneError> {
        let source = SceneSource {
            path: path.as_ref().to_path_buf(),
            text,
        };
        if dimension_of(&source.text) == Some(2) {
            return Err(source.error(
                "world.dimension",
                "a 2D scene: read it as one (`planar::PlanarScene`; `rapier-fvm run` does)",
            ));
        }
        let mut scene: Self = deserialize(&source)?;
        scene.source = source;
        scene.budget = budget;
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
        self.world.check(&mut c);
        let soft: Vec<&str> = self.soft_body.iter().map(|b| b.name.as_str()).collect();
        let rigid: Vec<&str> = self.rigid_body.iter().map(|b| b.name.as_str()).collect();
        check::check_body_names(&soft, &rigid, &mut c);
        for (i, body) in self.soft_body.iter().enumerate() {
            body.check(&format!("soft_body[{i}]"), &rigid, &mut c);
        }
        for (i, body) in self.rigid_body.iter().enumerate() {
            body.check(&format!("rigid_body[{i}]"), &mut c);
        }
        self.contact.check(&mut c);
        self.integrator.check(&mut c);
        self.output.check(self.world.duration, &mut c);
        check::check_probe_names(self.probe.iter().map(|p| p.name.as_str()), &mut c);
        for (i, probe) in self.probe.iter().enumerate() {
            probe.check(&format!("probe[{i}]"), &soft, &rigid, &mut c);
        }
        budget::check(&self.soft_body, &self.budget, &mut c);
        c.finish()
    }
}

/// The scene file `source` parsed as `T`, or a [`SceneError`] naming the file, the line and the
/// key path of a syntax error, an unknown or missing key, a wrong type or an array longer than
/// its key takes.
///
/// The text is read twice: through toml's spanned document, whose errors carry their line, then
/// as a `toml::Value`, which (unlike the first) refuses arrays with more elements than a
/// fixed-size array takes (`gravity = [0, -9.81, 0, 7]`), where the first reader drops the extra
/// ones; its errors are placed by their key path.
pub(crate) fn deserialize<T: serde::de::DeserializeOwned>(
    source: &SceneSource,
) -> Result<T, SceneError> {
    let scene = deserialize_spanned(source)?;
    let value: toml::Value = toml::from_str(&source.text)
        .map_err(|e| source.error("", e.message().trim().to_owned()))?;
    serde_path_to_error::deserialize::<_, T>(value).map_err(|error| {
        let key = error.path().to_string();
        let message = error.into_inner().message().trim().to_owned();
        // toml's "invalid length 4, expected fewer elements in array".
        let message = match message.strip_suffix(", expected fewer elements in array") {
            Some(length) => format!(
                "an array of {} elements, more than the key takes",
                length.trim_start_matches("invalid length ")
            ),
            None => message,
        };
        source.error(&key, message)
    })?;
    Ok(scene)
}

/// The first reading of [`deserialize`], whose errors carry their line.
fn deserialize_spanned<T: serde::de::DeserializeOwned>(
    source: &SceneSource,
) -> Result<T, SceneError> {
    let syntax_error = |error: toml::de::Error| SceneError {
        file: source.path.clone(),
        line: error.span().map(|span| source.line_of(span.start)),
        key: None,
        message: error.message().trim().to_owned(),
    };
    let table = toml::de::DeTable::parse(&source.text).map_err(syntax_error)?;
    let deserializer = toml::de::Deserializer::from(table);
    serde_path_to_error::deserialize(deserializer).map_err(|error| {
        let key = error.path().to_string();
        let inner = error.into_inner();
        let line = inner.span().map(|span| source.line_of(span.start));
        SceneError {
            file: source.path.clone(),
            line,
            key: (key != ".").then_some(key),
            message: inner.message().trim().to_owned(),
        }
    })
}

/// The `dimension` of `[world]` in the scene text `text` (2 for a 2D scene), or `None` when it
/// is not given or the text does not parse (the 3D reader then reports what is wrong).
pub fn dimension_of(text: &str) -> Option<i64> {
    let table: toml::Table = toml::from_str(text).ok()?;
    table.get("world")?.get("dimension")?.as_integer()
}

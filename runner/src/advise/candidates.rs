//! The alternatives the advisor measures, each one change to the scene as written: per soft
//! body another material model, linear elements in place of quadratic ones, a mesh of half
//! the cells along each axis, and a rigid stand-in below a strain of a tenth of the target (for
//! a body free of pins, attachments, loads and embedded meshes, which could not stand in); for the scene, another integrator, a Newton tolerance a hundred
//! times looser (to one significant digit, at most 1e-2), and half the coupling substeps. Each is a list of key-path edits of the
//! scene's text ([`crate::scene::edit`]).

use crate::scene::Scene;
use crate::scene::material::ModelSpec;
use crate::scene::mesh::MeshSpec;
use crate::scene::settings::IntegratorChoice;
use crate::scene::soft_body::ElementsSpec;
use serde::Serialize;
use toml_edit::{Array, Value};

/// What an alternative changes; two changes of one group cannot be combined.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
pub enum Group {
    /// A soft body's material model (its index in the scene).
    Model(usize),
    /// A soft body's element kind.
    Elements(usize),
    /// A soft body's mesh resolution.
    Resolution(usize),
    /// A soft body's rigid stand-in.
    StandIn(usize),
    /// The scene's integrator.
    Integrator,
    /// The implicit integrator's Newton tolerance.
    Tolerance,
    /// The world's coupling substeps.
    CouplingSubsteps,
}

impl Group {
    /// The soft body the change is to, if to one.
    pub fn body(&self) -> Option<usize> {
        match self {
            Self::Model(i) | Self::Elements(i) | Self::Resolution(i) | Self::StandIn(i) => Some(*i),
            _ => None,
        }
    }

    /// Whether the change is to the whole scene rather than to one soft body.
    pub fn is_scene_wide(&self) -> bool {
        matches!(
            self,
            Self::Integrator | Self::Tolerance | Self::CouplingSubsteps
        )
    }
}

/// One change to the scene.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// What it changes.
    pub group: Group,
    /// A line for people: `"gel ball: model linear"`.
    pub label: String,
    /// Its edits of the scene's text: key path and value.
    pub edits: Vec<(String, Value)>,
    /// For a coarser mesh, the refinement ratio from it to the given one (the largest over the
    /// axes of the given cells over the coarser ones).
    pub refinement: Option<f64>,
}

/// The models in the scene files' names, cheapest first.
const MODELS: [(ModelSpec, &str); 4] = [
    (ModelSpec::Linear, "linear"),
    (ModelSpec::Corotated, "corotated"),
    (ModelSpec::StVenantKirchhoff, "st_venant_kirchhoff"),
    (ModelSpec::StableNeoHookean, "stable_neo_hookean"),
];

/// An edit as `key = value`.
pub fn edit_text((key, value): &(String, Value)) -> String {
    format!("{key} = {}", value.to_string().trim())
}

/// The scene files' name of `model`.
pub fn model_name(model: ModelSpec) -> &'static str {
    (MODELS.iter())
        .find(|(m, _)| *m == model)
        .map_or("", |(_, name)| name)
}

/// Every alternative to `scene` for a probe error of `target` (relative): per soft body, the
/// other models, linear elements (for quadratic ones), half the cells and a rigid stand-in;
/// then the other integrators, the looser tolerance and half the coupling substeps.
pub fn candidates(scene: &Scene, target: f64) -> Vec<Candidate> {
    let mut all = Vec::new();
    for (i, body) in scene.soft_body.iter().enumerate() {
        let key = |rest: &str| format!("soft_body[{i}].{rest}");
        for (model, name) in MODELS {
            if model != body.material.model {
                all.push(Candidate {
                    group: Group::Model(i),
                    label: format!("{}: model {name}", body.name),
                    edits: vec![(key("material.model"), Value::from(name))],
                    refinement: None,
                });
            }
        }
        if body.elements != ElementsSpec::Linear {
            all.push(Candidate {
                group: Group::Elements(i),
                label: format!("{}: linear elements", body.name),
                edits: vec![(key("elements"), Value::from("linear"))],
                refinement: None,
            });
        }
        if let Some((what, edits, ratio)) = coarser(&body.mesh, &key("mesh")) {
            all.push(Candidate {
                group: Group::Resolution(i),
                label: format!("{}: {what}", body.name),
                edits,
                refinement: Some(ratio),
            });
        }
        let free = body.pinned.is_empty()
            && body.attach.is_empty()
            && body.loads.is_empty()
            && body.embedded.is_none();
        if free && body.rigid_stand_in.is_none() {
            let strain = one_digit(target / 10.0);
            all.push(Candidate {
                group: Group::StandIn(i),
                label: format!("{}: rigid stand-in below strain {strain:e}", body.name),
                edits: vec![(key("rigid_stand_in"), Value::from(strain))],
                refinement: None,
            });
        }
    }
    for (kind, name) in [
        (IntegratorChoice::Automatic, "automatic"),
        (IntegratorChoice::Explicit, "explicit"),
        (IntegratorChoice::Implicit, "implicit"),
    ] {
        if kind != scene.integrator.kind {
            all.push(Candidate {
                group: Group::Integrator,
                label: format!("integrator {name}"),
                edits: vec![("integrator.kind".to_owned(), Value::from(name))],
                refinement: None,
            });
        }
    }
    all.extend(scene_settings(scene));
    all
}

/// The scene's Newton tolerance a hundred times looser (at most 1e-2), and half its coupling
/// substeps (rounded up) where it has more than one.
fn scene_settings(scene: &Scene) -> Vec<Candidate> {
    let mut all = Vec::new();
    let tolerance = scene.integrator.integrator().implicit.tolerance;
    let looser = one_digit((tolerance * 100.0).min(1e-2));
    if looser > tolerance {
        all.push(Candidate {
            group: Group::Tolerance,
            label: format!("Newton tolerance {looser:e}"),
            edits: vec![("integrator.tolerance".to_owned(), Value::from(looser))],
            refinement: None,
        });
    }
    let substeps = scene.world.coupling_substeps;
    if substeps > 1 {
        let half = substeps.div_ceil(2);
        all.push(Candidate {
            group: Group::CouplingSubsteps,
            label: format!("coupling substeps {half}"),
            edits: vec![(
                "world.coupling_substeps".to_owned(),
                Value::from(i64::from(half)),
            )],
            refinement: None,
        });
    }
    all
}

/// `value` to one significant digit: 1e-6 × 100 gives 1e-4, not 9.999999999999999e-5.
fn one_digit(value: f64) -> f64 {
    format!("{value:.0e}").parse().unwrap_or(value)
}

/// A coarser mesh: its description, its edits and the refinement ratio from it to the given
/// mesh.
type Coarser = (String, Vec<(String, Value)>, f64);

/// Half the cells (rounded up) of a generated mesh or a filled surface along each axis, as a
/// description, the edits under `key` (the mesh's key path) and the refinement ratio from it
/// to the given mesh; `None` when the mesh is a file of elements or already one cell across.
fn coarser(mesh: &MeshSpec, key: &str) -> Option<Coarser> {
    let half = |n: usize| n.div_ceil(2);
    let int = |n: usize| Value::from(i64::try_from(n).unwrap_or(i64::MAX));
    let ratio = |pairs: &[(usize, usize)]| {
        (pairs.iter())
            .map(|(given, coarse)| *given as f64 / *coarse as f64)
            .fold(1.0, f64::max)
    };
    if let Some(cuboid) = &mesh.cuboid {
        let cells = cuboid.cells.map(half);
        (cells != cuboid.cells).then(|| {
            let array: Array = cells.iter().map(|n| int(*n)).collect();
            let edit = (format!("{key}.cuboid.cells"), Value::Array(array));
            let pairs: Vec<_> = cuboid.cells.into_iter().zip(cells).collect();
            (format!("cells {cells:?}"), vec![edit], ratio(&pairs))
        })
    } else if let Some(sphere) = &mesh.sphere {
        let across = half(sphere.cells_across).max(2);
        (across != sphere.cells_across).then(|| {
            let edit = (format!("{key}.sphere.cells_across"), int(across));
            let r = ratio(&[(sphere.cells_across, across)]);
            (format!("{across} cells across"), vec![edit], r)
        })
    } else if let Some(cylinder) = &mesh.cylinder {
        let (across, along) = (
            half(cylinder.cells_across).max(2),
            half(cylinder.cells_along),
        );
        ((across, along) != (cylinder.cells_across, cylinder.cells_along)).then(|| {
            let edits = vec![
                (format!("{key}.cylinder.cells_across"), int(across)),
                (format!("{key}.cylinder.cells_along"), int(along)),
            ];
            let r = ratio(&[
                (cylinder.cells_across, across),
                (cylinder.cells_along, along),
            ]);
            (format!("{across} cells across, {along} along"), edits, r)
        })
    } else {
        let file = mesh.file.as_deref()?;
        let surface = [".obj", ".stl"]
            .iter()
            .any(|ext| file.to_ascii_lowercase().ends_with(ext));
        let given = mesh.surface_options().cells_across;
        let across = half(given).max(2);
        (surface && across != given).then(|| {
            let edit = (format!("{key}.cells_across"), int(across));
            (
                format!("{across} cells across"),
                vec![edit],
                ratio(&[(given, across)]),
            )
        })
    }
}

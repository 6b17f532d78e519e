//! The alternatives the advisor measures, each one change to the scene as written: per soft
//! body another material model, linear elements in place of quadratic ones, and a mesh of half
//! the cells along each axis; for the scene, another integrator. Each is a list of key-path
//! edits of the scene's text ([`crate::scene::edit`]).

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
    /// The scene's integrator.
    Integrator,
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
}

/// The models in the scene files' names, cheapest first.
const MODELS: [(ModelSpec, &str); 4] = [
    (ModelSpec::Linear, "linear"),
    (ModelSpec::Corotated, "corotated"),
    (ModelSpec::StVenantKirchhoff, "st_venant_kirchhoff"),
    (ModelSpec::StableNeoHookean, "stable_neo_hookean"),
];

/// Every alternative to `scene`: per soft body, the other models, linear elements (for
/// quadratic ones) and half the cells; then the other integrators.
pub fn candidates(scene: &Scene) -> Vec<Candidate> {
    let mut all = Vec::new();
    for (i, body) in scene.soft_body.iter().enumerate() {
        let key = |rest: &str| format!("soft_body[{i}].{rest}");
        for (model, name) in MODELS {
            if model != body.material.model {
                all.push(Candidate {
                    group: Group::Model(i),
                    label: format!("{}: model {name}", body.name),
                    edits: vec![(key("material.model"), Value::from(name))],
                });
            }
        }
        if body.elements != ElementsSpec::Linear {
            all.push(Candidate {
                group: Group::Elements(i),
                label: format!("{}: linear elements", body.name),
                edits: vec![(key("elements"), Value::from("linear"))],
            });
        }
        if let Some((what, edits)) = coarser(&body.mesh, &key("mesh")) {
            all.push(Candidate {
                group: Group::Resolution(i),
                label: format!("{}: {what}", body.name),
                edits,
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
            });
        }
    }
    all
}

/// Half the cells (rounded up) of a generated mesh or a filled surface along each axis, as a
/// description and the edits under `key` (the mesh's key path); `None` when the mesh is a file
/// of elements or already one cell across.
fn coarser(mesh: &MeshSpec, key: &str) -> Option<(String, Vec<(String, Value)>)> {
    let half = |n: usize| n.div_ceil(2);
    let int = |n: usize| Value::from(i64::try_from(n).unwrap_or(i64::MAX));
    if let Some(cuboid) = &mesh.cuboid {
        let cells = cuboid.cells.map(half);
        (cells != cuboid.cells).then(|| {
            let array: Array = cells.iter().map(|n| int(*n)).collect();
            (
                format!("cells {cells:?}"),
                vec![(format!("{key}.cuboid.cells"), Value::Array(array))],
            )
        })
    } else if let Some(sphere) = &mesh.sphere {
        let across = half(sphere.cells_across).max(2);
        (across != sphere.cells_across).then(|| {
            let edit = (format!("{key}.sphere.cells_across"), int(across));
            (format!("{across} cells across"), vec![edit])
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
            (format!("{across} cells across, {along} along"), edits)
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
            (format!("{across} cells across"), vec![edit])
        })
    }
}

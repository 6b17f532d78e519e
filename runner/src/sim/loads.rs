//! A soft body's loads made from its description: the boundary triangles a box or a file's
//! region selects, a cable's eyelets, each load's value at the start, and what drives it over
//! time.

use crate::scene::load::{KINDS, LoadSpec, Schedule};
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::body::DeformableBody;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::load::{Load, LoadHandle, LoadValue, WATER_BULK_MODULUS};
use rapier_fvm::mesh::TetMesh;
use rapier_fvm::mesh::import::MeshRegion;

/// How a load's value changes over time.
#[derive(Debug, Clone)]
pub enum LoadSchedule {
    /// A pressure (Pa) or tension (N).
    Scalar(Schedule<f64>),
    /// A traction (Pa) or force density (N/m³).
    Vector(Schedule<[f64; 3]>),
    /// A chamber's volume: ratios to its cavity's rest volume `rest` (m³).
    Volume {
        /// The ratios over time.
        ratio: Schedule<f64>,
        /// The cavity's rest volume (m³).
        rest: f64,
    },
}

impl LoadSchedule {
    /// The value at time `t` (s).
    pub fn at(&self, t: f64) -> LoadValue {
        match self {
            Self::Scalar(s) => LoadValue::Scalar(s.at(t)),
            Self::Vector(s) => LoadValue::Vector(DVec3::from_array(s.at(t))),
            Self::Volume { ratio, rest } => LoadValue::Scalar(ratio.at(t) * rest),
        }
    }

    /// Whether the value changes over time.
    fn varies(&self) -> bool {
        match self {
            Self::Scalar(s) | Self::Volume { ratio: s, .. } => s.varies(),
            Self::Vector(s) => s.varies(),
        }
    }
}

/// A load on a body of the world that keyframes drive.
#[derive(Debug, Clone)]
pub struct DrivenLoad {
    /// The load on its body.
    pub handle: LoadHandle,
    /// Its values over time.
    pub schedule: LoadSchedule,
    /// Its key path in the scene, for the library's refusals.
    pub key: String,
}

/// The loads `specs` of a body meshed as `mesh` (rest coordinates), whose file `path` had the
/// `regions`, `key` in the scene of `source`, each at its value at time 0 with its schedule.
///
/// # Errors
/// A [`SceneError`] at a load whose box or region selects no boundary triangle, whose region
/// is not in the file, or whose cable's points all fall on one node.
pub(super) fn build_loads(
    specs: &[LoadSpec],
    (mesh, regions, path): (&TetMesh, &[MeshRegion], &str),
    (key, source): (&str, &SceneSource),
) -> Result<Vec<(Load, LoadSchedule, String)>, SceneError> {
    let mut boundary: Option<Vec<[u32; 3]>> = None;
    let mut loads = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let key = format!("{key}.loads[{i}]");
        let mut triangles = || -> Result<Vec<[u32; 3]>, SceneError> {
            let nodes = (spec.selection())
                .nodes(mesh, regions, path)
                .map_err(|e| source.error(&format!("{key}.region"), e.to_string()))?;
            let mut selected = vec![false; mesh.node_count()];
            for n in nodes {
                selected[n as usize] = true;
            }
            let boundary = boundary.get_or_insert_with(|| mesh.surface_triangles());
            let triangles: Vec<[u32; 3]> = (boundary.iter())
                .filter(|t| t.iter().all(|&n| selected[n as usize]))
                .copied()
                .collect();
            if triangles.is_empty() {
                return Err(source.error(&key, "it selects no boundary triangle of the body"));
            }
            Ok(triangles)
        };
        let (load, schedule) = match spec {
            LoadSpec {
                pressure: Some(s), ..
            } => {
                let load = Load::Pressure {
                    triangles: triangles()?,
                    pressure: s.at(0.0),
                };
                (load, LoadSchedule::Scalar(s.clone()))
            }
            LoadSpec {
                traction: Some(s), ..
            } => {
                let traction = DVec3::from_array(s.at(0.0));
                (
                    Load::Traction {
                        triangles: triangles()?,
                        traction,
                    },
                    LoadSchedule::Vector(s.clone()),
                )
            }
            LoadSpec {
                body_force: Some(s),
                ..
            } => {
                let density = DVec3::from_array(s.at(0.0));
                (Load::BodyForce { density }, LoadSchedule::Vector(s.clone()))
            }
            LoadSpec {
                tension: Some(s),
                path: Some(points),
                ..
            } => cable(mesh, points, s, (&key, source))?,
            LoadSpec {
                volume_ratio: Some(s),
                bulk_modulus,
                ..
            } => chamber(triangles()?, mesh, (s, *bulk_modulus), (&key, source))?,
            // The scene's check asks for exactly one kind, a cable with its path.
            _ => return Err(source.error(&key, KINDS)),
        };
        loads.push((load, schedule, key));
    }
    Ok(loads)
}

/// A cable through the nodes nearest `points` (m, rest coordinates) pulled by the tension
/// schedule `tension` (N), or an error at `key` if the points all fall on one node.
fn cable(
    mesh: &TetMesh,
    points: &[[f64; 3]],
    tension: &Schedule<f64>,
    (key, source): (&str, &SceneSource),
) -> Result<(Load, LoadSchedule), SceneError> {
    let mut eyelets: Vec<u32> = (points.iter())
        .map(|p| mesh.nearest_node(DVec3::from_array(*p)))
        .collect();
    eyelets.dedup();
    if eyelets.len() < 2 {
        return Err(source.error(&format!("{key}.path"), "its points all fall on one node"));
    }
    let load = Load::Cable {
        path: eyelets,
        tension: tension.at(0.0),
    };
    Ok((load, LoadSchedule::Scalar(tension.clone())))
}

/// A chamber whose walls are `triangles`, pumped to the volume ratios `ratio` of the volume it
/// encloses at rest, of a liquid of bulk modulus `bulk_modulus` (Pa, default water's), or an
/// error at `key` if the triangles enclose no cavity.
fn chamber(
    triangles: Vec<[u32; 3]>,
    mesh: &TetMesh,
    (ratio, bulk_modulus): (&Schedule<f64>, Option<f64>),
    (key, source): (&str, &SceneSource),
) -> Result<(Load, LoadSchedule), SceneError> {
    let rest = match Load::enclosed_volume_of(&triangles, mesh.positions()) {
        Some(rest) if rest > 0.0 => rest,
        Some(_) => {
            return Err(source.error(
                key,
                "its boundary triangles enclose no cavity (a chamber's face into \
                 its cavity: select an inner surface, not the body's outside)",
            ));
        }
        None => {
            return Err(source.error(
                key,
                "a chamber's walls must be a closed surface: its boundary \
                 triangles leave holes",
            ));
        }
    };
    let load = Load::Chamber {
        triangles,
        volume: ratio.at(0.0) * rest,
        bulk_modulus: bulk_modulus.unwrap_or(WATER_BULK_MODULUS),
    };
    let schedule = LoadSchedule::Volume {
        ratio: ratio.clone(),
        rest,
    };
    Ok((load, schedule))
}

/// Adds `loads` to `body`; returns those whose value changes over time.
///
/// # Errors
/// A [`SceneError`] at a load the library refuses.
pub(super) fn add_loads(
    body: &mut DeformableBody,
    loads: Vec<(Load, LoadSchedule, String)>,
    source: &SceneSource,
) -> Result<Vec<DrivenLoad>, SceneError> {
    let mut driven = Vec::new();
    for (load, schedule, key) in loads {
        let handle = body
            .add_load(load)
            .map_err(|e| source.error(&key, e.to_string()))?;
        if schedule.varies() {
            driven.push(DrivenLoad {
                handle,
                schedule,
                key,
            });
        }
    }
    Ok(driven)
}

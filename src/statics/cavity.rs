//! A cavity inflated to a volume: the pressure `p` of a pressure load on a closed surface at
//! which the body's static equilibrium encloses a target volume `V*`, as a syringe pump fills a
//! pneumatic or hydraulic chamber (`SurfacePressureConstraint` of SOFA's `SoftRobots` with a volume
//! growth).
//!
//! Newton's method on `p`: each iterate is a static equilibrium ([`solve_equilibrium`],
//! started from the last), where the enclosed volume `V(p)` changes with the pressure at
//! `dV/dp = gᵀ K⁻¹ g`, with `g = ∂V/∂x` (zero on pinned nodes) and `K` the tangent stiffness
//! including the pressure's own; so `p ← p + (V* − V)/(dV/dp)`, quadratically convergent. A
//! step whose equilibrium cannot be found is halved.

use super::{StaticReport, StaticSettings, assemble_elastic, solve_equilibrium};
use crate::Error;
use crate::assembly::{Stiffness, factorize, solve};
use crate::body::DeformableBody;
use crate::load::ChamberSolve;
use crate::load::{LoadHandle, LoadValue};
use rapier3d::glamx::DVec3;

/// Newton iterations on the pressure before giving up.
const MAX_PRESSURE_ITERATIONS: usize = 30;

/// Halvings of a pressure step whose equilibrium fails before giving up.
const MAX_HALVINGS: usize = 8;

/// What [`inflate_to_volume`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CavityReport {
    /// The pressure (Pa) the load was left at.
    pub pressure: f64,
    /// The volume the cavity encloses at equilibrium (m³).
    pub volume: f64,
    /// Newton iterations on the pressure (each a static solve).
    pub iterations: usize,
    /// The last static solve's report.
    pub equilibrium: StaticReport,
}

/// Moves `body` to the static equilibrium under `gravity` (m/s²) and its loads at which the
/// pressure load `cavity` (on a closed surface) encloses `volume` (m³), setting the load's
/// pressure (Pa) to the value that does so. The volume is met to `settings.tolerance` of itself
/// (relative), each equilibrium as [`solve_equilibrium`] meets it.
///
/// # Errors
/// [`Error::InvalidLoad`] if `cavity` is not a pressure on a closed, consistently oriented
/// surface of the body; [`Error::InvalidSetting`] for a volume that is not positive and
/// finite; the errors of [`solve_equilibrium`]; [`Error::IndefiniteStiffness`] where the
/// equilibrium is unstable (its tangent not positive definite: the volume could fall as the
/// pressure rises); [`Error::StaticSolveDidNotConverge`] if the pressure does not converge in
/// 30 iterations. On error the body is left as it was, its load at its former pressure.
///
/// # Example
/// ```
/// # #[cfg(feature = "import")] {
/// use rapier_fvm::mesh::import::{self, SurfaceOptions};
/// use rapier_fvm::prelude::*;
/// use rapier_fvm::statics::{self, StaticSettings};
///
/// // gmsh's hollow sphere (radii 50 and 25 mm), pinned at its bottom, its cavity filled 10 %
/// // beyond its rest volume.
/// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/meshes/hollow_sphere_v41.msh");
/// let raw = import::load_raw(file, 0.001, &SurfaceOptions::default())?;
/// let cavity_nodes = raw.regions_in_mesh().into_iter().find(|r| r.name == "cavity").unwrap();
/// let shell = raw.into_mesh()?;
/// let walls = shell.surface_triangles_where(|p| p.length() < 0.026);
/// assert!(cavity_nodes.nodes.len() > 100);
/// let bottom = shell.nodes_where(|p| p.y < -0.049);
/// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
/// let mut body = DeformableBodyBuilder::new(shell, rubber).pinned_nodes(bottom).build()?;
/// let cavity = body.add_load(Load::Pressure { triangles: walls, pressure: 0.0 })?;
/// let rest = body.load(cavity).unwrap().enclosed_volume(body.positions()).unwrap();
/// let target = 1.1 * rest;
/// let report =
///     statics::inflate_to_volume(&mut body, cavity, target, DVec3::ZERO, &StaticSettings::default())?;
/// assert!((report.volume / target - 1.0).abs() < 1e-8);
/// assert!(report.pressure > 0.0);
/// # }
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
pub fn inflate_to_volume(
    body: &mut DeformableBody,
    cavity: LoadHandle,
    volume: f64,
    gravity: DVec3,
    settings: &StaticSettings,
) -> Result<CavityReport, Error> {
    if !(volume.is_finite() && volume > 0.0) {
        return Err(Error::InvalidSetting {
            parameter: "volume",
            value: volume,
            reason: "must be positive and finite",
        });
    }
    cavity_gradient(body, cavity)?;
    let Some(LoadValue::Scalar(start_pressure)) = body.load(cavity).map(|load| load.value()) else {
        return Err(not_a_cavity());
    };
    let saved = (body.positions().to_vec(), body.velocities().to_vec());
    let result = newton_on_pressure(body, (cavity, start_pressure), volume, gravity, settings);
    if result.is_err() {
        body.positions.copy_from_slice(&saved.0);
        body.velocities.copy_from_slice(&saved.1);
        body.set_load(cavity, LoadValue::Scalar(start_pressure))?;
    }
    result
}

/// Newton's iterations on the pressure of [`inflate_to_volume`], from `pressure` (Pa).
fn newton_on_pressure(
    body: &mut DeformableBody,
    (cavity, mut pressure): (LoadHandle, f64),
    target: f64,
    gravity: DVec3,
    settings: &StaticSettings,
) -> Result<CavityReport, Error> {
    let mut equilibrium = at_pressure(body, cavity, pressure, gravity, settings)?;
    for iteration in 0..MAX_PRESSURE_ITERATIONS {
        let volume = enclosed_volume(body, cavity);
        if (volume - target).abs() <= settings.tolerance * target {
            return Ok(CavityReport {
                pressure,
                volume,
                iterations: iteration,
                equilibrium,
            });
        }
        let compliance = volume_compliance(body, cavity)?;
        if compliance.is_nan() || compliance <= 0.0 {
            // Round-off on a tangent barely positive definite: no direction to go.
            return Err(Error::StaticSolveDidNotConverge {
                iterations: iteration,
                residual: (volume - target).abs() / target,
            });
        }
        let mut step = (target - volume) / compliance;
        let mut halvings = 0;
        loop {
            match at_pressure(body, cavity, pressure + step, gravity, settings) {
                Ok(report) => {
                    equilibrium = report;
                    pressure += step;
                    break;
                }
                Err(_) if halvings < MAX_HALVINGS => {
                    step *= 0.5;
                    halvings += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }
    Err(Error::StaticSolveDidNotConverge {
        iterations: MAX_PRESSURE_ITERATIONS,
        residual: (enclosed_volume(body, cavity) - target).abs() / target,
    })
}

/// The static equilibrium with the cavity's pressure at `pressure` (Pa).
fn at_pressure(
    body: &mut DeformableBody,
    cavity: LoadHandle,
    pressure: f64,
    gravity: DVec3,
    settings: &StaticSettings,
) -> Result<StaticReport, Error> {
    body.set_load(cavity, LoadValue::Scalar(pressure))?;
    solve_equilibrium(body, gravity, settings)
}

/// `∂V/∂x` (m² per node) of the cavity's enclosed volume, or [`Error::InvalidLoad`] if the
/// load `cavity` is not a pressure on a closed surface of the body.
fn cavity_gradient(body: &DeformableBody, cavity: LoadHandle) -> Result<Vec<DVec3>, Error> {
    (body.load(cavity))
        .and_then(|load| load.cavity_volume_gradient(body.positions()))
        .ok_or_else(not_a_cavity)
}

fn not_a_cavity() -> Error {
    Error::InvalidLoad {
        load: "pressure",
        reason: "a volume needs a pressure load on a closed, consistently oriented surface".into(),
    }
}

/// The volume (m³) the cavity encloses now.
fn enclosed_volume(body: &DeformableBody, cavity: LoadHandle) -> f64 {
    (body.load(cavity))
        .and_then(|load| load.enclosed_volume(body.positions()))
        .unwrap_or(f64::NAN)
}

/// `dV/dp = gᵀ K⁻¹ g` (m³/Pa) at the current equilibrium: how much the enclosed volume grows
/// per pascal, through the tangent stiffness with the pressure's own (and any chamber's).
fn volume_compliance(body: &DeformableBody, cavity: LoadHandle) -> Result<f64, Error> {
    let mut gradient = cavity_gradient(body, cavity)?;
    for (g, &pinned) in gradient.iter_mut().zip(&body.pinned) {
        if pinned {
            *g = DVec3::ZERO;
        }
    }
    let mut stiffness = Stiffness::new(body);
    assemble_elastic(&mut stiffness, body, false);
    let factor = factorize(&mut stiffness, 0)?;
    let response = solve(&factor, &gradient);
    let chambers = body.chamber_terms();
    let response = ChamberSolve::new(&factor, &chambers).take_in(&gradient, response);
    Ok(gradient.iter().zip(&response).map(|(g, u)| g.dot(*u)).sum())
}

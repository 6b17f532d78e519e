//! Two-dimensional soft bodies: the finite-volume method on triangles, with plane stress (a thin
//! sheet, `σ₃ⱼ = 0`) or plane strain (a thick body, `ε₃ⱼ = 0`).
//!
//! The method is the 3D one in the plane: mass lumped on nodes from control areas
//! ([`ControlVolumes`]), a deformation gradient constant per triangle ([`TriangleRest`]), the
//! stress of the same 3D material models reduced to the plane ([`PlanarLaw`]), and the force on
//! a node the traction integrated over its control-volume boundary, `f_i = t P b_i`. Everything
//! is per unit of the body's rest thickness `t` (m), so forces are in N and masses in kg.
//!
//! # Example: uniaxial tension in plane stress
//! ```
//! use rapier_fvm::glamx::DVec2;
//! use rapier_fvm::material::{Material, MaterialModel};
//! use rapier_fvm::planar::{PlanarBodyBuilder, PlaneModel, TriangleMesh, edge_loads, solve_planar_equilibrium};
//! use rapier_fvm::statics::StaticSettings;
//!
//! let mesh = TriangleMesh::rectangle(DVec2::new(2.0, 1.0), [4, 2])?;
//! let left = mesh.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9);
//! let right = mesh.nodes_on_line(DVec2::new(2.0, 0.0), DVec2::Y, 1e-9);
//! let steel = Material::new(MaterialModel::Linear, 200e9, 0.3, 7850.0)?;
//! let mut sheet = PlanarBodyBuilder::new(mesh, steel)
//!     .plane(PlaneModel::PlaneStress)
//!     .thickness(0.01)
//!     .pinned_along(left, 0) // rollers: the left edge slides along y
//!     .pinned_along([0], 1) // and one node holds it in place
//!     .build()?;
//! // 1 kN pulling the right edge: stress 1e5 Pa over 1 m × 1 cm, strain 5e-7.
//! let loads = edge_loads(&sheet, &right, DVec2::new(1e3, 0.0), true);
//! solve_planar_equilibrium(&mut sheet, &loads, &StaticSettings::default())?;
//! let stretch = sheet.deformation_gradient(0).x_axis.x - 1.0;
//! assert!((stretch - 5e-7).abs() < 1e-15);
//! # Ok::<(), rapier_fvm::Error>(())
//! ```

mod body;
#[cfg(feature = "dim2")]
mod colliders;
mod control_volume;
#[cfg(feature = "dim2")]
mod corners;
#[cfg(feature = "dim2")]
pub mod coupling;
mod dynamics;
mod element;
mod evaluate;
#[cfg(feature = "dim2")]
mod glue;
mod implicit;
#[cfg(feature = "dim2")]
mod implicit_contact;
mod mesh;
mod outline;
mod plane;
mod points;
mod statics;
mod unknowns;
mod volumetric;

pub use body::{PlanarBody, PlanarBodyBuilder};
pub use control_volume::{ControlVolumes, traction_along};
pub use dynamics::{PlanarStepReport, SAFETY_FACTOR, step_explicit};
pub use element::TriangleRest;
pub use implicit::{PlanarImplicitReport, step_implicit};
pub use mesh::{Diagonals, TriangleMesh};
pub use plane::{PlanarLaw, PlanarStress, PlaneModel, apply_tangent};
pub use statics::{edge_loads, solve_planar_equilibrium};

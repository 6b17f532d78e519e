//! The finite-volume discretization: per-tetrahedron rest data and the nodal force kernel.
//!
//! Each node owns the median-dual control volume around it (a quarter of every tetrahedron it
//! belongs to). With the deformation gradient `F` and so the first Piola–Kirchhoff stress `P`
//! constant in a tetrahedron, the traction integrated over the part of node `i`'s control-volume
//! boundary inside that tetrahedron is `f_i = P b_i`, where `b_i` is the rest area-weighted normal
//! of that boundary piece: one third of the area-weighted outward normal of the face opposite `i`.

mod kernel;
mod nodal_averaging;
mod rest;

pub(crate) use kernel::gather;
pub use kernel::{FvmMesh, stress_forces, tet_forces};
pub(crate) use nodal_averaging::NodalAveraging;
pub use nodal_averaging::VolumetricTreatment;
pub use rest::TetRest;

//! The explicit time steps a mesh allows for a material, before any body is made of it: for a
//! mesh checker to print next to the mesh's quality.
//!
//! Builds the undamped body of the mesh and material with [`DeformableBodyBuilder`]'s defaults
//! and asks [`SymplecticEuler`] for its limits, so the numbers are those a simulation of that
//! body would use; a mesh the builder refuses (a sliver below the default minimum quality) is an
//! error.

use super::SymplecticEuler;
use crate::Error;
use crate::body::DeformableBodyBuilder;
use crate::material::Material;
use crate::mesh::TetMesh;

/// The explicit integrator's time steps for a mesh and material, at rest and undamped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshTimeSteps {
    /// The critical time step (s), [`SymplecticEuler::critical_time_step`]: steps above it make
    /// the highest modes grow.
    pub critical: f64,
    /// The substep (s) [`SymplecticEuler::default`] takes automatically,
    /// [`SymplecticEuler::stable_time_step`]: the critical step times its safety factor.
    pub stable: f64,
}

impl SymplecticEuler {
    /// The critical and stable time steps (s) of the undamped body of `mesh` (m) and
    /// `material`, built with [`DeformableBodyBuilder::new`]'s defaults, as
    /// [`SymplecticEuler::critical_time_step`] and [`SymplecticEuler::default`]'s
    /// [`SymplecticEuler::stable_time_step`] give them.
    ///
    /// # Errors
    /// Those of [`DeformableBodyBuilder::build`] for that body, in practice
    /// [`Error::SliverTet`] for a tetrahedron below the default minimum element quality.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// let cube = mesh::cuboid(DVec3::splat(0.5), [2, 2, 2])?;
    /// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
    /// let steps = SymplecticEuler::mesh_time_steps(cube, &rubber)?;
    /// assert!(steps.critical > 0.0 && steps.critical < 1e-2);
    /// assert_eq!(steps.stable, SymplecticEuler::default().safety_factor * steps.critical);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn mesh_time_steps(mesh: TetMesh, material: &Material) -> Result<MeshTimeSteps, Error> {
        let body = DeformableBodyBuilder::new(mesh, *material).build()?;
        Ok(MeshTimeSteps {
            critical: Self::critical_time_step(&body),
            stable: Self::default().stable_time_step(&body),
        })
    }
}

//! [`PlanarBody`]: a 2D soft body on a triangle mesh, and its builder.
//!
//! Contract: nodal masses are `ρ t A_i` (density, rest thickness, the node's control area of the
//! chosen [`ControlVolumes`]), summing to `ρ t A`; internal forces are the finite-volume forces
//! of [`TriangleRest::forces`] under the [`PlanarLaw`] of the body's material and
//! [`PlaneModel`], and are minus the gradient of [`PlanarBody::elastic_energy`].

use super::ControlVolumes;
use super::element::TriangleRest;
use super::mesh::TriangleMesh;
use super::plane::{PlanarLaw, PlanarStress, PlaneModel};
use crate::Error;
use crate::material::{Material, with_hyperelastic_model};
use rapier3d::glamx::{DMat2, DVec2};

/// Describes a 2D soft body before it is built.
///
/// # Example
/// ```
/// use rapier_fvm::material::{Material, MaterialModel};
/// use rapier_fvm::planar::{PlanarBodyBuilder, PlaneModel, TriangleMesh};
/// use rapier_fvm::glamx::DVec2;
///
/// // A 1 m × 0.1 m strip of rubber, 1 cm thick.
/// let mesh = TriangleMesh::rectangle(DVec2::new(1.0, 0.1), [20, 2])?;
/// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
/// let strip = PlanarBodyBuilder::new(mesh, rubber)
///     .plane(PlaneModel::PlaneStress)
///     .thickness(0.01)
///     .build()?;
/// assert!((strip.total_mass() - 1100.0 * 0.1 * 0.01).abs() < 1e-12);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone)]
#[must_use = "a builder does nothing until `build` is called"]
pub struct PlanarBodyBuilder {
    mesh: TriangleMesh,
    material: Material,
    plane: PlaneModel,
    thickness: f64,
    control_volumes: ControlVolumes,
    /// Held nodes and the axes (x, y) each is held along, in the order given.
    pinned: Vec<(usize, [bool; 2])>,
}

impl PlanarBodyBuilder {
    /// A body of `mesh` and `material`: plane stress, 1 m thick, median control volumes, no
    /// pinned node.
    pub fn new(mesh: TriangleMesh, material: Material) -> Self {
        Self {
            mesh,
            material,
            plane: PlaneModel::PlaneStress,
            thickness: 1.0,
            control_volumes: ControlVolumes::Median,
            pinned: Vec::new(),
        }
    }

    /// Why the body is flat.
    pub fn plane(mut self, plane: PlaneModel) -> Self {
        self.plane = plane;
        self
    }

    /// The rest thickness (m): positive and finite.
    pub fn thickness(mut self, thickness: f64) -> Self {
        self.thickness = thickness;
        self
    }

    /// How the nodes' control volumes, and so their masses, are drawn.
    pub fn control_volumes(mut self, control_volumes: ControlVolumes) -> Self {
        self.control_volumes = control_volumes;
        self
    }

    /// Nodes held where they are (by index).
    pub fn pinned_nodes(mut self, nodes: impl IntoIterator<Item = usize>) -> Self {
        self.pinned
            .extend(nodes.into_iter().map(|n| (n, [true, true])));
        self
    }

    /// Nodes held along one axis only (0 for x, 1 for y), free along the other: rollers.
    pub fn pinned_along(mut self, nodes: impl IntoIterator<Item = usize>, axis: usize) -> Self {
        let held = [axis == 0, axis == 1];
        self.pinned.extend(nodes.into_iter().map(|n| (n, held)));
        self
    }

    /// Builds the body at its rest positions.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] for a thickness that is not positive and finite,
    /// [`Error::NodeOutOfRange`] for a pinned node that does not exist,
    /// [`Error::NonPositiveControlArea`] from [`ControlVolumes::nodal_areas`].
    pub fn build(self) -> Result<PlanarBody, Error> {
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "thickness",
                value: self.thickness,
                reason: "must be positive and finite (m)",
            });
        }
        let node_count = self.mesh.rest_positions().len();
        let mut pinned = vec![[false; 2]; node_count];
        for &(node, held) in &self.pinned {
            let axes = pinned
                .get_mut(node)
                .ok_or(Error::NodeOutOfRange { node, node_count })?;
            axes[0] |= held[0];
            axes[1] |= held[1];
        }
        let areas = self.control_volumes.nodal_areas(&self.mesh)?;
        let per_area = self.material.density() * self.thickness;
        let rest = (0..self.mesh.triangles().len())
            .map(|t| TriangleRest::new(self.mesh.corners(t)))
            .collect();
        Ok(PlanarBody {
            positions: self.mesh.rest_positions().to_vec(),
            masses: areas.iter().map(|a| a * per_area).collect(),
            mesh: self.mesh,
            material: self.material,
            plane: self.plane,
            thickness: self.thickness,
            control_volumes: self.control_volumes,
            rest,
            pinned,
        })
    }
}

/// A 2D soft body: its mesh, material and plane model, and where its nodes are.
#[derive(Debug, Clone)]
pub struct PlanarBody {
    mesh: TriangleMesh,
    material: Material,
    plane: PlaneModel,
    thickness: f64,
    control_volumes: ControlVolumes,
    rest: Vec<TriangleRest>,
    masses: Vec<f64>,
    positions: Vec<DVec2>,
    pub(super) pinned: Vec<[bool; 2]>,
}

impl PlanarBody {
    /// The mesh.
    pub fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }

    /// The plane model.
    pub fn plane(&self) -> PlaneModel {
        self.plane
    }

    /// The rest thickness (m).
    pub fn thickness(&self) -> f64 {
        self.thickness
    }

    /// The control volumes the masses were lumped from.
    pub fn control_volumes(&self) -> ControlVolumes {
        self.control_volumes
    }

    /// Per-triangle rest data.
    pub fn triangle_rest(&self) -> &[TriangleRest] {
        &self.rest
    }

    /// Nodal masses (kg).
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// The total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.masses.iter().sum()
    }

    /// World positions (m).
    pub fn positions(&self) -> &[DVec2] {
        &self.positions
    }

    /// World positions (m), to set.
    pub fn positions_mut(&mut self) -> &mut [DVec2] {
        &mut self.positions
    }

    /// Whether each node is held along x and along y.
    pub fn pinned(&self) -> &[[bool; 2]] {
        &self.pinned
    }

    /// The world corners (m) of triangle `t` in `positions`.
    pub(super) fn corners_in(&self, t: usize, positions: &[DVec2]) -> [DVec2; 3] {
        self.mesh.triangles()[t].map(|n| positions[n as usize])
    }

    /// The deformation gradient (dimensionless) of triangle `t`.
    pub fn deformation_gradient(&self, t: usize) -> DMat2 {
        self.rest[t].gradient(&self.corners_in(t, &self.positions))
    }

    /// The stress in triangle `t` (see [`PlanarStress`]).
    pub fn stress(&self, t: usize) -> PlanarStress {
        let f = self.deformation_gradient(t);
        self.with_law(|law| law.stress(&f))
    }

    /// Runs `body` with the body's [`PlanarLaw`] for its material model.
    pub(super) fn with_law<R>(&self, body: impl FnOnce(&dyn PlanarLawDyn) -> R) -> R {
        let plane = self.plane;
        with_hyperelastic_model!(self.material, |model| body(&PlanarLaw { model, plane }))
    }

    /// The elastic energy (J) at `positions` (m).
    pub fn elastic_energy_at(&self, positions: &[DVec2]) -> f64 {
        self.with_law(|law| {
            (self.rest.iter().enumerate())
                .map(|(t, rest)| {
                    let f = rest.gradient(&self.corners_in(t, positions));
                    law.energy_density(&f) * rest.area() * self.thickness
                })
                .sum()
        })
    }

    /// The elastic energy (J) where the body is.
    pub fn elastic_energy(&self) -> f64 {
        self.elastic_energy_at(&self.positions)
    }

    /// The internal (elastic) forces (N) on the nodes at `positions` (m).
    pub fn internal_forces_at(&self, positions: &[DVec2]) -> Vec<DVec2> {
        let mut forces = vec![DVec2::ZERO; positions.len()];
        self.with_law(|law| {
            for (t, rest) in self.rest.iter().enumerate() {
                let f = rest.gradient(&self.corners_in(t, positions));
                let p = law.stress(&f).p;
                let nodes = self.mesh.triangles()[t];
                for (node, force) in nodes.iter().zip(rest.forces(&p, self.thickness)) {
                    forces[*node as usize] += force;
                }
            }
        });
        forces
    }

    /// The internal forces (N) where the body is.
    pub fn internal_forces(&self) -> Vec<DVec2> {
        self.internal_forces_at(&self.positions)
    }
}

/// A [`PlanarLaw`] whatever its model, for the body's loops.
pub(super) trait PlanarLawDyn {
    /// See [`PlanarLaw::stress`].
    fn stress(&self, f: &DMat2) -> PlanarStress;
    /// See [`PlanarLaw::energy_density`].
    fn energy_density(&self, f: &DMat2) -> f64;
    /// See [`PlanarLaw::tangent`].
    fn tangent(&self, f: &DMat2) -> [DMat2; 4];
}

impl<M: crate::material::HyperelasticModel> PlanarLawDyn for PlanarLaw<M> {
    fn stress(&self, f: &DMat2) -> PlanarStress {
        PlanarLaw::stress(self, f)
    }
    fn energy_density(&self, f: &DMat2) -> f64 {
        PlanarLaw::energy_density(self, f)
    }
    fn tangent(&self, f: &DMat2) -> [DMat2; 4] {
        PlanarLaw::tangent(self, f)
    }
}

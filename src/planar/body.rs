//! [`PlanarBody`]: a 2D soft body on a triangle mesh, and its builder.
//!
//! Contract: nodal masses are `ρ t A_i` (density, rest thickness, the node's control area of the
//! chosen [`ControlVolumes`], or HRZ shares of quadratic triangles), summing to `ρ t A`;
//! internal forces are those of the elements' integration points (for linear triangles the
//! finite-volume forces of [`TriangleRest::forces`]) under the [`PlanarLaw`] of the body's
//! material and [`PlaneModel`] (with the volumetric term averaged if asked, see
//! [`PlanarBodyBuilder::volumetric`]), and are minus the gradient of
//! [`PlanarBody::elastic_energy`].

use super::ControlVolumes;
use super::element::TriangleRest;
use super::evaluate::PlanarLawDyn;
use super::mesh::TriangleMesh;
use super::plane::{PlanarLaw, PlanarStress, PlaneModel};
use super::points::{IntegrationPoints, QUADRATIC_MASS_FRACTIONS};
use super::volumetric::VolumeAveraging;
use crate::Error;
use crate::damping::RayleighDamping;
use crate::fvm::VolumetricTreatment;
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
    volumetric: VolumetricTreatment,
    damping: Option<RayleighDamping>,
    quadratic: bool,
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
            volumetric: VolumetricTreatment::PerElement,
            damping: None,
            quadratic: false,
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

    /// How the volumetric term `K/2 m²` is evaluated (plane strain only): per element, or
    /// averaged over groups of integration points with their rest areas as weights, on node
    /// patches ([`VolumetricTreatment::NodalAverage`], linear triangles) or over each
    /// element's points ([`VolumetricTreatment::ElementAverage`], mean dilatation, quadratic
    /// triangles; for linear triangles, as for linear tetrahedra, it is the per-element term):
    /// locking-free for nearly incompressible bodies.
    pub fn volumetric(mut self, volumetric: VolumetricTreatment) -> Self {
        self.volumetric = volumetric;
        self
    }

    /// Rayleigh damping on the strain rate (see [`crate::damping`]; in plane stress with the
    /// reduced volumetric viscosity, see [`PlaneModel::damping_stress`]). None by default.
    pub fn damping(mut self, damping: RayleighDamping) -> Self {
        self.damping = Some(damping);
        self
    }

    /// Quadratic (6-node) triangles: a node is added at the middle of each edge of the mesh
    /// (numbered after the corners, see [`PlanarBody::rest_positions`]), the elements are
    /// integrated at three points each and their masses lumped by HRZ (see
    /// [`crate::planar`]'s integration points); far more accurate in bending per unknown.
    /// Median control volumes and the volumetric term per element only.
    pub fn quadratic(mut self) -> Self {
        self.quadratic = true;
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
    /// [`Error::NonPositiveControlArea`] from [`ControlVolumes::nodal_areas`],
    /// [`Error::UnsupportedOption`] for nodal averaging in plane stress.
    pub fn build(self) -> Result<PlanarBody, Error> {
        let averaged = self.volumetric == VolumetricTreatment::NodalAverage
            || (self.volumetric == VolumetricTreatment::ElementAverage && self.quadratic);
        if averaged && self.plane == PlaneModel::PlaneStress {
            return Err(Error::UnsupportedOption {
                option: "an averaged volumetric term in plane stress",
                reason: "a sheet free across its thickness does not lock: nothing holds its volume",
            });
        }
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return Err(Error::InvalidSetting {
                parameter: "thickness",
                value: self.thickness,
                reason: "must be positive and finite (m)",
            });
        }
        let (rest_positions, points, masses, boundary) = self.discretize()?;
        let node_count = rest_positions.len();
        let mut pinned = vec![[false; 2]; node_count];
        for &(node, held) in &self.pinned {
            let axes = pinned
                .get_mut(node)
                .ok_or(Error::NodeOutOfRange { node, node_count })?;
            axes[0] |= held[0];
            axes[1] |= held[1];
        }
        let averaging = match (self.volumetric, self.quadratic) {
            (VolumetricTreatment::NodalAverage, _) => {
                let areas = self.control_volumes.nodal_areas(&self.mesh)?;
                Some(VolumeAveraging::nodal(&points, &areas))
            }
            (VolumetricTreatment::ElementAverage, true) => {
                Some(VolumeAveraging::per_element(&points))
            }
            _ => None,
        };
        let volumetric = match averaging {
            Some(_) => self.volumetric,
            None => VolumetricTreatment::PerElement,
        };
        Ok(PlanarBody {
            boundary,
            averaging,
            volumetric,
            velocities: vec![DVec2::ZERO; node_count],
            damping: self.damping,
            positions: rest_positions.clone(),
            rest_positions,
            masses,
            mesh: self.mesh,
            material: self.material,
            plane: self.plane,
            thickness: self.thickness,
            control_volumes: self.control_volumes,
            points,
            pinned,
        })
    }

    /// The body's rest positions (m), integration points and nodal masses (kg).
    fn discretize(&self) -> Result<Discretized, Error> {
        let per_area = self.material.density() * self.thickness;
        let rest: Vec<TriangleRest> = (0..self.mesh.triangles().len())
            .map(|t| TriangleRest::new(self.mesh.corners(t)))
            .collect();
        if !self.quadratic {
            let areas = self.control_volumes.nodal_areas(&self.mesh)?;
            let masses = areas.iter().map(|a| a * per_area).collect();
            let points = IntegrationPoints::linear(self.mesh.triangles(), &rest);
            let boundary = self.mesh.boundary_edges();
            return Ok((
                self.mesh.rest_positions().to_vec(),
                points,
                masses,
                boundary,
            ));
        }
        let unsupported = |option, reason| Err(Error::UnsupportedOption { option, reason });
        if self.control_volumes != ControlVolumes::Median {
            return unsupported(
                "circumcentric control volumes with quadratic triangles",
                "quadratic triangles lump their masses by HRZ",
            );
        }
        if self.volumetric == VolumetricTreatment::NodalAverage {
            return unsupported(
                "nodal averaging with quadratic triangles",
                "quadratic triangles average over each element (ElementAverage)",
            );
        }
        let (positions, elements, boundary) = self.mesh.quadratic_nodes();
        let mut masses = vec![0.0; positions.len()];
        for (nodes, rest) in elements.iter().zip(&rest) {
            for (n, fraction) in nodes.iter().zip(QUADRATIC_MASS_FRACTIONS) {
                masses[*n as usize] += fraction * rest.area() * per_area;
            }
        }
        let points = IntegrationPoints::quadratic(&elements, &rest);
        Ok((positions, points, masses, boundary))
    }
}

/// A body's rest positions (m), integration points, nodal masses (kg) and boundary segments.
type Discretized = (Vec<DVec2>, IntegrationPoints, Vec<f64>, Vec<[u32; 2]>);

/// A 2D soft body: its mesh, material and plane model, and where its nodes are.
#[derive(Debug, Clone)]
pub struct PlanarBody {
    mesh: TriangleMesh,
    material: Material,
    plane: PlaneModel,
    thickness: f64,
    control_volumes: ControlVolumes,
    points: IntegrationPoints,
    rest_positions: Vec<DVec2>,
    masses: Vec<f64>,
    positions: Vec<DVec2>,
    pub(super) pinned: Vec<[bool; 2]>,
    /// The groups the volumetric term is averaged over, if it is.
    pub(super) averaging: Option<VolumeAveraging>,
    /// How the volumetric term is evaluated.
    volumetric: VolumetricTreatment,
    velocities: Vec<DVec2>,
    damping: Option<RayleighDamping>,
    boundary: Vec<[u32; 2]>,
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

    /// The integration points of the elements.
    pub(super) fn points(&self) -> &IntegrationPoints {
        &self.points
    }

    /// The rest positions (m) of the body's nodes: the mesh's, then, for quadratic triangles,
    /// the mid-edge nodes.
    pub fn rest_positions(&self) -> &[DVec2] {
        &self.rest_positions
    }

    /// The nodes within `tolerance` (m) of the line through `point` along `direction`, in
    /// order along it: a clamped or loaded edge, mid-edge nodes included.
    pub fn nodes_on_line(&self, point: DVec2, direction: DVec2, tolerance: f64) -> Vec<usize> {
        let normal = direction.perp().normalize();
        let mut nodes: Vec<usize> = (self.rest_positions.iter().enumerate())
            .filter(|(_, p)| (**p - point).dot(normal).abs() <= tolerance)
            .map(|(i, _)| i)
            .collect();
        let along = |n: &usize| (self.rest_positions[*n] - point).dot(direction);
        nodes.sort_by(|a, b| along(a).total_cmp(&along(b)));
        nodes
    }

    /// The boundary as segments between nodes, the body to their left (see
    /// [`TriangleMesh::boundary_edges`]; quadratic triangles' edges cut at their mid-edge
    /// nodes).
    pub fn boundary(&self) -> &[[u32; 2]] {
        &self.boundary
    }

    /// Whether the elements are quadratic (6-node) triangles.
    pub fn is_quadratic(&self) -> bool {
        self.points.per_element() == 3
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

    /// Nodal velocities (m/s).
    pub fn velocities(&self) -> &[DVec2] {
        &self.velocities
    }

    /// Nodal velocities (m/s), to set (a held axis's is zeroed by the next step).
    pub fn velocities_mut(&mut self) -> &mut [DVec2] {
        &mut self.velocities
    }

    /// The damping, if any.
    pub fn damping(&self) -> Option<&RayleighDamping> {
        self.damping.as_ref()
    }

    /// The material.
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// The kinetic energy (J).
    pub fn kinetic_energy(&self) -> f64 {
        (self.masses.iter().zip(&self.velocities))
            .map(|(m, v)| 0.5 * m * v.length_squared())
            .sum()
    }

    /// The linear momentum (kg m/s).
    pub fn linear_momentum(&self) -> DVec2 {
        (self.masses.iter().zip(&self.velocities))
            .map(|(m, v)| *v * *m)
            .sum()
    }

    /// The angular momentum about the origin (kg m²/s, counterclockwise positive).
    pub fn angular_momentum(&self) -> f64 {
        (self
            .masses
            .iter()
            .zip(&self.positions)
            .zip(&self.velocities))
        .map(|((m, x), v)| m * x.perp_dot(*v))
        .sum()
    }

    /// One symplectic Euler update over `h` (s): velocities kicked by `forces` (N per node) and
    /// `gravity` (m/s²), held axes stopped, then positions drifted by the new velocities.
    pub(super) fn kick_and_drift(&mut self, h: f64, forces: &[DVec2], gravity: DVec2) {
        let nodes = self
            .velocities
            .iter_mut()
            .zip(&self.masses)
            .zip(&self.pinned);
        for (((v, m), held), f) in nodes.zip(forces) {
            *v += *f * (h / m) + gravity * h;
            for axis in 0..2 {
                if held[axis] {
                    v[axis] = 0.0;
                }
            }
        }
        for (x, v) in self.positions.iter_mut().zip(&self.velocities) {
            *x += *v * h;
        }
    }

    /// Holds node `node` along the axes set in `axes` (x, y), in addition to those it is
    /// held along; its velocity along them is zeroed by the next step. For nodes a builder
    /// cannot name, such as the mid-edge nodes of quadratic triangles.
    ///
    /// # Errors
    /// [`Error::NodeOutOfRange`] for a node that does not exist.
    pub fn pin(&mut self, node: usize, axes: [bool; 2]) -> Result<(), Error> {
        let node_count = self.pinned.len();
        let held = (self.pinned.get_mut(node)).ok_or(Error::NodeOutOfRange { node, node_count })?;
        held[0] |= axes[0];
        held[1] |= axes[1];
        Ok(())
    }

    /// Whether each node is held along x and along y.
    pub fn pinned(&self) -> &[[bool; 2]] {
        &self.pinned
    }

    /// The deformation gradient (dimensionless) at integration point `q` (triangle `q`'s for
    /// linear triangles; points `3e..3e + 3` are element `e`'s for quadratic ones).
    pub fn deformation_gradient(&self, q: usize) -> DMat2 {
        self.points.gradient(q, &self.positions)
    }

    /// The stress at integration point `q` (see [`PlanarStress`]): the model's at its
    /// deformation gradient, with an averaged volumetric term its volumetric part (in `P` and
    /// `P₃₃`) averaged as the forces take it.
    pub fn stress(&self, q: usize) -> PlanarStress {
        self.with_law(|law| {
            if self.averaging.is_none() {
                return law.stress(&self.points.gradient(q, &self.positions));
            }
            self.point_planar_stress(law, &self.evaluate(law, &self.positions), q)
        })
    }

    /// How the volumetric term is evaluated ([`VolumetricTreatment::ElementAverage`] of
    /// linear triangles is [`VolumetricTreatment::PerElement`]).
    pub fn volumetric(&self) -> VolumetricTreatment {
        self.volumetric
    }

    /// Runs `body` with the body's [`PlanarLaw`] for its material model.
    pub(super) fn with_law<R>(&self, body: impl FnOnce(&dyn PlanarLawDyn) -> R) -> R {
        let plane = self.plane;
        with_hyperelastic_model!(self.material, |model| body(&PlanarLaw { model, plane }))
    }

    /// The elastic energy (J) at `positions` (m).
    pub fn elastic_energy_at(&self, positions: &[DVec2]) -> f64 {
        self.with_law(|law| self.energy_of(law, &self.evaluate(law, positions)))
    }

    /// The elastic energy (J) where the body is.
    pub fn elastic_energy(&self) -> f64 {
        self.elastic_energy_at(&self.positions)
    }

    /// The internal (elastic) forces (N) on the nodes at `positions` (m).
    pub fn internal_forces_at(&self, positions: &[DVec2]) -> Vec<DVec2> {
        self.with_law(|law| self.forces_of(law, &self.evaluate(law, positions)))
    }

    /// The internal forces (N) where the body is.
    pub fn internal_forces(&self) -> Vec<DVec2> {
        self.internal_forces_at(&self.positions)
    }
}

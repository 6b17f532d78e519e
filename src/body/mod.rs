//! Soft bodies: a mesh, a material, and the state that moves: nodal positions (m), velocities
//! (m/s) and lumped masses (kg), plus pinned (Dirichlet) nodes. The state is set through checked
//! setters ([`DeformableBody::set_positions`], [`DeformableBody::set_node_velocity`], ...) or
//! raw slices; a step refuses a state it cannot take ([`DeformableBody::check_state`]).

mod builder;
mod loads;
#[cfg(feature = "serde-serialize")]
mod record;
mod set;
mod stand_in;
mod state;
mod stress;
mod surface;

pub use builder::{DEFAULT_FRICTION, DEFAULT_MIN_ELEMENT_QUALITY, DeformableBodyBuilder};
pub use set::{DeformableBodyHandle, DeformableBodySet};
pub use stand_in::RigidStandIn;
pub use state::SPEED_OF_LIGHT;
pub(crate) use surface::BodySurface;

use crate::damping::{RayleighDamping, StepDamping};
use crate::element::{ElementOrder, ElementShape, Elements};
use crate::embedding::Embedding;
use crate::fvm::VolumetricTreatment;
use crate::material::{ElementMaterials, Material, with_hyperelastic_model};
use crate::mesh::TetMesh;
use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::geometry::InteractionGroups;
use rapier3d::glamx::{DMat3, DVec3};

/// A deformable body discretized by tetrahedra, linear (simulated by finite volumes) or
/// quadratic.
///
/// Built with [`DeformableBodyBuilder`]. Mass is lumped on the nodes from their control volumes (a
/// quarter of each incident linear tetrahedron's rest volume times its density; HRZ fractions
/// for quadratic ones), so the nodal masses sum to the elements' densities times their rest
/// volumes.
#[derive(Debug, Clone)]
pub struct DeformableBody {
    /// The linear tetrahedra: the elements, or the subdivision of the quadratic ones.
    pub(crate) mesh: TetMesh,
    pub(crate) elements: Elements,
    /// The elements' own materials, when not all have the body's.
    pub(crate) element_materials: Option<ElementMaterials>,
    /// For quadratic elements, the element each tetrahedron of `mesh` lies in.
    pub(crate) subdivision_parents: Vec<u32>,
    pub(crate) material: Material,
    pub(crate) damping: Option<RayleighDamping>,
    pub(crate) positions: Vec<DVec3>,
    pub(crate) velocities: Vec<DVec3>,
    pub(crate) masses: Vec<f64>,
    pub(crate) pinned: Vec<bool>,
    /// The mesh's boundary: the nodes contacts are detected for (unless the body has an
    /// embedded mesh), the triangles self-contact pushes against, each node's ring.
    pub(crate) surface: BodySurface,
    /// A fine mesh carried by the nodes, whose surface contacts with colliders act on.
    pub(crate) embedding: Option<Embedding>,
    /// The loads besides gravity ([`DeformableBody::add_load`]).
    pub(crate) loads: Vec<crate::load::Load>,
    /// How many times a load was added or changed: a sleeping body wakes when it is.
    pub(crate) load_edits: u64,
    /// The work (J) the changes of the loads' values did ([`DeformableBody::load_change_work`]).
    pub(crate) load_change_work: f64,
    /// How many times the state was edited from outside the integrators
    /// ([`DeformableBody::positions_mut`], [`DeformableBody::velocities_mut`], a static solve):
    /// two-step integrators restart after an edit.
    state_edits: u64,
    /// The collision groups of the surface: the body touches only the colliders whose groups
    /// pass `InteractionGroups::test` with these, as rapier's colliders do.
    pub collision_groups: InteractionGroups,
    /// The surface's Coulomb friction coefficient, combined with a collider's or another soft
    /// body's by the stronger of their combine rules, as rapier combines two colliders'.
    pub friction: f64,
    /// How [`DeformableBody::friction`] combines with the other side's.
    pub friction_combine_rule: CoefficientCombineRule,
    /// The surface's restitution coefficient, combined with the other side's as
    /// [`DeformableBody::friction`] is: a node striking a surface faster than
    /// [`RESTITUTION_THRESHOLD`](crate::contact::RESTITUTION_THRESHOLD) leaves it at this fraction
    /// of its approach speed (explicit integration). The body's own elasticity makes it rebound
    /// too; with the default 0 that is the only rebound.
    pub restitution: f64,
    /// How [`DeformableBody::restitution`] combines with the other side's.
    pub restitution_combine_rule: CoefficientCombineRule,
    /// Whether the body's surface collides with itself (a body folding over itself, or made of
    /// separate parts): off by default, as it costs a bounding-volume query per surface node and
    /// detection. Both integrators solve self-contacts; the automatic one picks between them by
    /// cost, as for any other contact.
    pub self_contact: bool,
    /// Arbitrary user data, as on rapier's bodies.
    pub user_data: u128,
    /// Whether the coupling may step the body as a rapier rigid body while its strain stays
    /// small (see [`RigidStandIn`]); none by default.
    pub rigid_stand_in: Option<RigidStandIn>,
}

impl DeformableBody {
    /// The rest mesh (rest positions in the body's own frame, m): the elements for a body of
    /// linear tetrahedra; for quadratic ones their subdivision into linear tetrahedra on the same
    /// nodes (see [`QuadraticTetMesh::subdivided`](crate::mesh::QuadraticTetMesh::subdivided)),
    /// which its surface, contacts and output use.
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The order of the elements the body is simulated with.
    pub fn element_order(&self) -> ElementOrder {
        self.elements.order()
    }

    /// The fine mesh the body carries for contact and output, if it was built with one
    /// ([`DeformableBodyBuilder::embedded`]).
    pub fn embedding(&self) -> Option<&Embedding> {
        self.embedding.as_ref()
    }

    /// The world positions (m) of the embedded mesh's vertices, interpolated from the nodes';
    /// `None` without an embedded mesh.
    pub fn embedded_positions(&self) -> Option<Vec<DVec3>> {
        self.embedding
            .as_ref()
            .map(|embedding| embedding.positions(&self.positions))
    }

    /// The shape of the elements the body is simulated with.
    pub fn element_shape(&self) -> ElementShape {
        self.elements.shape()
    }

    /// The number of elements the body is simulated with: the mesh's tetrahedra for linear
    /// elements, the quadratic tetrahedra or hexahedra otherwise (each subdivided in
    /// [`DeformableBody::mesh`]).
    pub fn element_count(&self) -> usize {
        match &self.elements {
            Elements::Linear { .. } => self.mesh.tet_count(),
            Elements::Quadratic { elements, .. } => elements.element_count(),
        }
    }

    /// The body's material: every element's but those given their own by
    /// [`DeformableBodyBuilder::region_material`] (see [`DeformableBody::element_material`]).
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// The material of element `element` (a tetrahedron of a linear body, a quadratic element of
    /// a quadratic one); `None` if the body has no such element.
    pub fn element_material(&self, element: usize) -> Option<Material> {
        if element >= self.element_count() {
            return None;
        }
        Some(match &self.element_materials {
            Some(materials) => materials.material_of(&self.material, element),
            None => self.material,
        })
    }

    /// Whether the elements' materials differ (see [`DeformableBodyBuilder::region_material`]).
    pub fn has_region_materials(&self) -> bool {
        self.element_materials.is_some()
    }

    /// The Rayleigh damping, if any.
    pub fn damping(&self) -> Option<&RayleighDamping> {
        self.damping.as_ref()
    }

    /// How the volumetric part of the energy is evaluated.
    /// ([`VolumetricTreatment::ElementAverage`] on linear tetrahedra is reported as the
    /// [`VolumetricTreatment::PerElement`] it amounts to.)
    pub fn volumetric_treatment(&self) -> VolumetricTreatment {
        self.elements.volumetric_treatment()
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }

    /// World positions of the nodes (m).
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Mutable world positions of the nodes (m), unchecked: a step refuses a body left with a
    /// position NaN, infinite or beyond ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE) (see
    /// [`DeformableBody::check_state`]); [`DeformableBody::set_positions`] refuses it at once.
    /// Editing the state restarts two-step integrators.
    pub fn positions_mut(&mut self) -> &mut [DVec3] {
        self.state_edits += 1;
        &mut self.positions
    }

    /// Node velocities (m/s).
    pub fn velocities(&self) -> &[DVec3] {
        &self.velocities
    }

    /// Mutable node velocities (m/s), unchecked: a step refuses a body left with a velocity NaN,
    /// infinite or faster than [`SPEED_OF_LIGHT`] (see [`DeformableBody::check_state`]);
    /// [`DeformableBody::set_velocities`] refuses it at once. The integrators hold pinned nodes
    /// at rest, whatever is written here. Editing the state restarts two-step integrators.
    pub fn velocities_mut(&mut self) -> &mut [DVec3] {
        self.state_edits += 1;
        &mut self.velocities
    }

    /// Lumped nodal masses (kg).
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.masses.iter().sum()
    }

    /// Whether node `node` is pinned (held at its position with zero velocity).
    ///
    /// # Panics
    /// If `node >= self.node_count()`.
    pub fn is_pinned(&self, node: usize) -> bool {
        self.pinned[node]
    }

    /// The mesh's wave length scale (m) at the current positions, see
    /// [`FvmMesh::wave_length_scale`](crate::fvm::FvmMesh::wave_length_scale): the explicit
    /// critical step is about [`COURANT_NUMBER`](crate::integrate::COURANT_NUMBER) times this over
    /// the pressure wave speed.
    ///
    /// With [region materials](DeformableBodyBuilder::region_material) it counts each element's
    /// stiffness and each node's mass, for the wave speed of the body's
    /// [material](DeformableBody::material).
    pub fn wave_length_scale(&self) -> f64 {
        let mass_volumes: Option<Vec<f64>> = self.element_materials.as_ref().map(|_| {
            let density = self.material.density();
            self.masses.iter().map(|m| m / density).collect()
        });
        (self.elements).wave_length_scale(&self.positions, mass_volumes.as_deref())
    }

    /// The speed (m/s) of pressure waves through the body as a whole: its material's
    /// [`dilatational_wave_speed`](Material::dilatational_wave_speed), or with region materials
    /// `sqrt((λ + 2μ) Σ s_e V_e / M)`, the elements' mean stiffness over their mean density.
    pub(crate) fn mean_wave_speed(&self) -> f64 {
        match &self.element_materials {
            Some(materials) => {
                let modulus = self.material.lame().p_wave_modulus();
                (modulus * materials.stiffness_volume() / self.total_mass()).sqrt()
            }
            None => self.material.dilatational_wave_speed(),
        }
    }

    /// Internal forces (N per node): elastic plus damping, at the current positions and velocities.
    pub fn internal_forces(&mut self) -> Vec<DVec3> {
        let mut forces = Vec::new();
        self.internal_forces_into(&mut forces);
        forces
    }

    /// [`DeformableBody::internal_forces`] written into `forces` (resized to one per node), so
    /// that repeated calls do not allocate.
    pub fn internal_forces_into(&mut self, forces: &mut Vec<DVec3>) {
        forces.resize(self.node_count(), DVec3::ZERO);
        let Self {
            elements,
            material,
            damping,
            positions,
            velocities,
            ..
        } = self;
        with_hyperelastic_model!(material, |model| {
            elements.internal_forces(&model, damping.as_ref(), positions, velocities, forces);
        });
    }

    /// How many times the state was edited from outside the integrators.
    pub(crate) fn state_edits(&self) -> u64 {
        self.state_edits
    }

    /// Counts a change of the state made outside the integrators (a rigid stand-in handing the
    /// body back): two-step integrators restart.
    pub(crate) fn mark_state_edited(&mut self) {
        self.state_edits += 1;
    }

    /// Counts an edit of the state from outside the integrators (a static solve).
    pub(crate) fn count_state_edit(&mut self) {
        self.state_edits += 1;
    }

    /// Elastic strain energy (J) at the current positions.
    pub fn elastic_energy(&self) -> f64 {
        with_hyperelastic_model!(self.material, |model| self
            .elements
            .elastic_energy(&model, &self.positions))
    }

    /// The internal forces (N per node) at the current positions in an implicit step of `h`
    /// (s) whose damping rate is measured from `green` (per integration point; unused when the
    /// body is undamped), written into `forces` (resized to one per node): the elastic force
    /// and the step's damping force, each element's deformation gradient found once.
    pub(crate) fn step_forces_into(
        &mut self,
        (green, h): (&[DMat3], f64),
        forces: &mut Vec<DVec3>,
    ) {
        forces.resize(self.node_count(), DVec3::ZERO);
        let damping = self.damping;
        let damping = (damping.as_ref()).map(|damping| StepDamping { damping, green, h });
        with_hyperelastic_model!(self.material, |model| {
            (self.elements).step_forces(&model, damping, &self.positions, forces);
        });
    }

    /// The elastic energy (J) at the current positions plus, when the body is damped, the
    /// dissipation potential of an implicit step of `h` (s) whose rate is measured from `green`
    /// (per integration point; see [`RayleighDamping::step_potential`]).
    pub(crate) fn step_energy(&self, (green, h): (&[DMat3], f64)) -> f64 {
        let damping = (self.damping.as_ref()).map(|damping| StepDamping { damping, green, h });
        with_hyperelastic_model!(self.material, |model| self.elements.step_energy(
            &model,
            damping,
            &self.positions
        ))
    }

    /// Kinetic energy `Σ m v²/2` (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.masses
            .iter()
            .zip(&self.velocities)
            .map(|(m, v)| 0.5 * m * v.length_squared())
            .sum()
    }

    /// Potential energy `-Σ m g·x` (J) in the uniform gravity `gravity` (m/s²).
    pub fn gravity_potential_energy(&self, gravity: DVec3) -> f64 {
        -self
            .masses
            .iter()
            .zip(&self.positions)
            .map(|(m, x)| m * gravity.dot(*x))
            .sum::<f64>()
    }

    /// Total linear momentum `Σ m v` (kg·m/s).
    pub fn linear_momentum(&self) -> DVec3 {
        self.masses
            .iter()
            .zip(&self.velocities)
            .map(|(m, v)| *v * *m)
            .sum()
    }

    /// Angular momentum about the centre of mass `c`, `Σ m (x - c) × v` (N·m·s = kg·m²/s), of the
    /// lumped nodal masses: a body spinning rigidly at `ω` (rad/s) carries `I ω`, `I` the inertia
    /// tensor `Σ m (|r|² 1 - r rᵀ)` of the nodal masses about `c` (`r = x - c`). The internal
    /// forces of the rotation-invariant models and the damping exert no net torque, so that a
    /// body free of loads keeps it when stepped explicitly (to round-off); an implicit
    /// (backward Euler) step of `h` (s) loses about `(ω h)²` of it, its numerical damping.
    pub fn angular_momentum(&self) -> DVec3 {
        let center_of_mass = self.center_of_mass();
        self.masses
            .iter()
            .zip(self.positions.iter().zip(&self.velocities))
            .map(|(m, (x, v))| (*x - center_of_mass).cross(*v) * *m)
            .sum()
    }

    /// The first node whose position or velocity is NaN or infinite, if any.
    pub(crate) fn first_non_finite_node(&self) -> Option<usize> {
        self.positions
            .iter()
            .zip(&self.velocities)
            .position(|(x, v)| !(x.is_finite() && v.is_finite()))
    }

    /// Each element's volume ratio `J = det F` (dimensionless) at the current positions, in
    /// element order: a linear tetrahedron's `V / V₀`; a quadratic element's smallest `det F` at
    /// its quadrature points, where its stiffness is sampled (the straight-sided tetrahedra of
    /// its subdivision, [`DeformableBody::mesh`], can fold where the curved element does not).
    /// Negative for an inverted element, NaN for non-finite positions.
    pub fn element_volume_ratios(&self) -> Vec<f64> {
        match &self.elements {
            Elements::Linear { .. } => (self.mesh.tets().iter().enumerate())
                .map(|(t, tet)| {
                    crate::mesh::signed_volume(&self.positions, tet) / self.mesh.tet_volume(t)
                })
                .collect(),
            Elements::Quadratic { elements, .. } => (self.elements.gradients(&self.positions))
                .chunks(elements.shape().quadrature().len())
                .map(|element| {
                    (element.iter()).fold(f64::INFINITY, |smallest, f| {
                        let ratio = f.determinant();
                        if smallest.is_nan() || ratio.is_nan() {
                            f64::NAN
                        } else {
                            smallest.min(ratio)
                        }
                    })
                })
                .collect(),
        }
    }

    /// Number of tetrahedra whose current volume is zero or negative (inverted elements).
    pub fn inverted_tet_count(&self) -> usize {
        self.mesh
            .tets()
            .iter()
            .filter(|tet| crate::mesh::signed_volume(&self.positions, tet) <= 0.0)
            .count()
    }

    /// Current volume (m³): the sum of the tetrahedra's signed volumes.
    pub fn deformed_volume(&self) -> f64 {
        self.mesh
            .tets()
            .iter()
            .map(|tet| crate::mesh::signed_volume(&self.positions, tet))
            .sum()
    }

    /// The inertia tensor (kg m²) of the nodes about `point` (m), `Σ mᵢ (|rᵢ|² 𝟙 − rᵢ rᵢᵀ)` with
    /// `rᵢ = xᵢ − point`.
    pub(crate) fn inertia_about(&self, point: DVec3) -> DMat3 {
        (self.positions.iter())
            .zip(&self.masses)
            .map(|(x, m)| {
                let r = *x - point;
                (DMat3::IDENTITY * r.length_squared() - outer(r, r)) * *m
            })
            .fold(DMat3::ZERO, |a, b| a + b)
    }

    /// Centre of mass (m).
    pub fn center_of_mass(&self) -> DVec3 {
        let weighted: DVec3 = self
            .masses
            .iter()
            .zip(&self.positions)
            .map(|(m, x)| *x * *m)
            .sum();
        weighted / self.total_mass()
    }
}

/// `a bᵀ`.
pub(crate) fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The angular velocity `I⁻¹ L` (rad/s) of the inertia tensor `inertia` (kg m²) holding the
/// angular momentum `momentum` (N m s), or `None` for a singular inertia (every node on one
/// line through the point).
pub(crate) fn spin_of(inertia: DMat3, momentum: DVec3) -> Option<DVec3> {
    let trace = inertia.x_axis.x + inertia.y_axis.y + inertia.z_axis.z;
    (inertia.determinant() > 1e-12 * trace.powi(3)).then(|| inertia.inverse() * momentum)
}

/// Lumped nodal masses (kg): each node receives a quarter of the mass of every tetrahedron it
/// belongs to (its median-dual control volume times the tetrahedron's `density(t)`, kg/m³).
pub(crate) fn lumped_masses(mesh: &TetMesh, density: impl Fn(usize) -> f64) -> Vec<f64> {
    let mut masses = vec![0.0; mesh.node_count()];
    for (t, tet) in mesh.tets().iter().enumerate() {
        let quarter = 0.25 * density(t) * mesh.tet_volume(t);
        for &n in tet {
            masses[n as usize] += quarter;
        }
    }
    masses
}

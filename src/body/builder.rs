//! [`DeformableBodyBuilder`]: the rapier-style way to describe a soft body before creating it.

use super::state::check_velocity;
use super::{BodySurface, DeformableBody, RigidStandIn, SPEED_OF_LIGHT, lumped_masses};
use crate::Error;
use crate::damping::RayleighDamping;
use crate::element::{ElementShape, Elements, PressureBasis, QuadraticElements};
use crate::embedding::Embedding;
use crate::fvm::{FvmMesh, NodalAveraging, VolumetricTreatment};
use crate::material::{ElementMaterials, Material};
use crate::mesh::{QuadraticHexMesh, QuadraticTetMesh, SUB_TETS, TetMesh, check_position};
use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::geometry::InteractionGroups;
use rapier3d::glamx::{DQuat, DVec3};

/// Describes a soft body: its mesh and material, placement, initial velocity (linear, angular,
/// and per region), damping and pinned nodes.
///
/// # Example
/// ```
/// use rapier_fvm::prelude::*;
///
/// let mesh = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [10, 1, 1])?;
/// let clamped = mesh.nodes_where(|p| p.x <= -0.5 + 1e-9);
/// let steel = Material::new(MaterialModel::Corotated, 200e9, 0.3, 7850.0)?;
/// let beam = DeformableBodyBuilder::new(mesh, steel)
///     .translation(DVec3::new(0.5, 1.0, 0.0))
///     .pinned_nodes(clamped)
///     .build()?;
/// assert!((beam.total_mass() - 7850.0 * 0.01).abs() < 1e-9);
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone)]
#[must_use = "a builder does nothing until `build` is called"]
pub struct DeformableBodyBuilder {
    /// The linear tetrahedra: the body's elements, or the subdivision of its quadratic ones.
    mesh: TetMesh,
    /// The quadratic elements, for a body of them.
    quadratic: Option<QuadraticSpec>,
    material: Material,
    damping: Option<RayleighDamping>,
    volumetric: VolumetricTreatment,
    rotation: DQuat,
    translation: DVec3,
    linvel: DVec3,
    /// Initial angular velocity (rad/s) about the placed body's centre of mass.
    angvel: DVec3,
    /// Nodes given their own initial velocity (m/s), in the order given.
    region_linvels: Vec<(Vec<u32>, DVec3)>,
    pinned: Vec<u32>,
    user_data: u128,
    min_quality: f64,
    collision_groups: InteractionGroups,
    friction: f64,
    friction_combine_rule: CoefficientCombineRule,
    restitution: f64,
    restitution_combine_rule: CoefficientCombineRule,
    self_contact: bool,
    rigid_stand_in: Option<f64>,
    embedded: Option<TetMesh>,
    /// Elements given their own material, in the order given.
    region_materials: Vec<(Vec<u32>, Material)>,
}

/// The quadratic elements a builder was given.
#[derive(Debug, Clone)]
struct QuadraticSpec {
    shape: ElementShape,
    /// The elements' nodes, `shape.node_count()` each.
    nodes: Vec<u32>,
    /// The element each tetrahedron of the subdivision lies in.
    parents: Vec<u32>,
}

/// Default [`DeformableBodyBuilder::friction`]: rapier's default collider friction.
pub const DEFAULT_FRICTION: f64 = 0.5;

/// Default [`DeformableBodyBuilder::min_element_quality`]: a tetrahedron whose smallest altitude is a
/// thousandth of its longest edge is refused.
pub const DEFAULT_MIN_ELEMENT_QUALITY: f64 = 1e-3;

impl DeformableBodyBuilder {
    /// A body of `mesh` (rest positions in m) made of `material`, at rest where the mesh lies,
    /// undamped, with no pinned node.
    pub fn new(mesh: TetMesh, material: Material) -> Self {
        Self {
            mesh,
            quadratic: None,
            material,
            damping: None,
            volumetric: VolumetricTreatment::PerElement,
            rotation: DQuat::IDENTITY,
            translation: DVec3::ZERO,
            linvel: DVec3::ZERO,
            angvel: DVec3::ZERO,
            region_linvels: Vec::new(),
            pinned: Vec::new(),
            user_data: 0,
            min_quality: DEFAULT_MIN_ELEMENT_QUALITY,
            collision_groups: InteractionGroups::all(),
            friction: DEFAULT_FRICTION,
            friction_combine_rule: CoefficientCombineRule::Average,
            restitution: 0.0,
            restitution_combine_rule: CoefficientCombineRule::Average,
            self_contact: false,
            rigid_stand_in: None,
            embedded: None,
            region_materials: Vec::new(),
        }
    }

    /// A body of quadratic (10-node) tetrahedra: far more accurate in bending per degree of
    /// freedom than linear ones (see [`crate::element::tet10`]). The body's
    /// [`DeformableBody::mesh`] is then `mesh`'s [subdivision](QuadraticTetMesh::subdivided), on the
    /// same nodes; node indices (pins, attachments, probes) are those of `mesh`.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// let linear = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [5, 1, 1])?;
    /// let mesh = mesh::QuadraticTetMesh::from_linear(&linear)?;
    /// let clamped = mesh.nodes_where(|p| p.x <= -0.5 + 1e-9);
    /// let material = Material::new(MaterialModel::Corotated, 1e8, 0.3, 1000.0)?;
    /// let beam = DeformableBodyBuilder::quadratic(mesh, material)
    ///     .pinned_nodes(clamped)
    ///     .build()?;
    /// assert_eq!(beam.element_order(), rapier_fvm::element::ElementOrder::Quadratic);
    /// assert!((beam.total_mass() - 10.0).abs() < 1e-12);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn quadratic(mesh: QuadraticTetMesh, material: Material) -> Self {
        let parents = (0..mesh.subdivided().tet_count())
            .map(|t| (t / SUB_TETS) as u32)
            .collect();
        Self {
            quadratic: Some(QuadraticSpec {
                shape: ElementShape::Tetrahedron,
                nodes: mesh.elements().as_flattened().to_vec(),
                parents,
            }),
            ..Self::new(mesh.subdivided().clone(), material)
        }
    }

    /// A body simulated on a coarse cage of quadratic (27-node) hexahedra: one element across a
    /// beam's section bends it as a continuum does (see [`crate::element::hex27`]), so bending
    /// bodies need the fewest nodes this way. The body's [`DeformableBody::mesh`] is the cage's
    /// [subdivision](QuadraticHexMesh::subdivided), on the same nodes.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// let cage = mesh::QuadraticHexMesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [5, 1, 1])?;
    /// let clamped = cage.nodes_where(|p| p.x <= -0.5 + 1e-9);
    /// let material = Material::new(MaterialModel::Corotated, 1e8, 0.3, 1000.0)?;
    /// let beam = DeformableBodyBuilder::quadratic_hex(cage, material)
    ///     .pinned_nodes(clamped)
    ///     .build()?;
    /// assert_eq!(beam.element_shape(), rapier_fvm::element::ElementShape::Hexahedron);
    /// assert!((beam.total_mass() - 10.0).abs() < 1e-12);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn quadratic_hex(mesh: QuadraticHexMesh, material: Material) -> Self {
        Self {
            quadratic: Some(QuadraticSpec {
                shape: ElementShape::Hexahedron,
                nodes: mesh.elements().as_flattened().to_vec(),
                parents: mesh.subdivision_parents().to_vec(),
            }),
            ..Self::new(mesh.subdivided().clone(), material)
        }
    }

    /// A body of quadratic elements of `shape` on `subdivision` (their linear subdivision):
    /// `nodes` lists each element's nodes, `parents` the element of each subdivision tetrahedron.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] for node lists of the wrong length or an element node or parent
    /// beyond the mesh's or the elements' count.
    #[cfg(feature = "serde-serialize")]
    pub(super) fn from_quadratic_parts(
        subdivision: TetMesh,
        material: Material,
        (shape, nodes, parents): (ElementShape, Vec<u32>, Vec<u32>),
    ) -> Result<Self, Error> {
        let per_element = shape.node_count();
        let elements = nodes.len() / per_element;
        if nodes.len() % per_element != 0 || parents.len() != subdivision.tet_count() {
            return Err(Error::InvalidSetting {
                parameter: "quadratic elements",
                value: nodes.len() as f64,
                reason: "need the element's node count per element and a parent per tetrahedron",
            });
        }
        let out_of_range = |index: u32, count: usize| (index as usize >= count).then_some(index);
        let bad_node = nodes
            .iter()
            .find_map(|&n| out_of_range(n, subdivision.node_count()));
        let bad_parent = parents.iter().find_map(|&p| out_of_range(p, elements));
        if let Some(index) = bad_node.or(bad_parent) {
            return Err(Error::InvalidSetting {
                parameter: "quadratic elements",
                value: f64::from(index),
                reason: "an element node or parent index beyond the mesh's nodes or elements",
            });
        }
        Ok(Self {
            quadratic: Some(QuadraticSpec {
                shape,
                nodes,
                parents,
            }),
            ..Self::new(subdivision, material)
        })
    }

    /// Rayleigh damping on the strain rate.
    pub fn damping(mut self, damping: RayleighDamping) -> Self {
        self.damping = Some(damping);
        self
    }

    /// Gives the elements `elements` the material `material`: a region of another Young's
    /// modulus and density (a stiff wall inside a soft finger). The indices are the body's
    /// elements: the tetrahedra of a linear body, the quadratic elements of a quadratic one, as
    /// a volume region of a file lists them (`MeshRegion::tets` of `mesh::import`), the
    /// hexahedra of a cage (for a file's region, `MeshRegion::cage_elements`).
    /// The material must have the body's model and Poisson's ratio. A later call takes
    /// precedence for the elements it shares with an earlier one; materials that change no
    /// element's modulus or density leave the body of one material. The elements' Rayleigh damping
    /// is the body's times `E_e / E`: stiffness-proportional damping keeps its time constant.
    /// Not with [`VolumetricTreatment::NodalAverage`] (its patches mix elements) nor an
    /// [embedded](DeformableBodyBuilder::embedded) mesh.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// // A 1 m bar of ten cells, its right half ten times as stiff and twice as dense.
    /// let mesh = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [10, 1, 1])?;
    /// let right: Vec<u32> = (0..mesh.tet_count() as u32)
    ///     .filter(|&t| mesh.tets()[t as usize].iter().all(|&n| mesh.positions()[n as usize].x >= 0.0))
    ///     .collect();
    /// let soft = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0)?;
    /// let stiff = Material::new(MaterialModel::Linear, 1e7, 0.3, 2000.0)?;
    /// let bar = DeformableBodyBuilder::new(mesh, soft)
    ///     .region_material(right, stiff)
    ///     .build()?;
    /// assert!((bar.total_mass() - 15.0).abs() < 1e-9);
    /// assert_eq!(bar.element_material(0), Some(soft));
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn region_material(
        mut self,
        elements: impl IntoIterator<Item = u32>,
        material: Material,
    ) -> Self {
        self.region_materials
            .push((elements.into_iter().collect(), material));
        self
    }

    /// How the volumetric part of the energy is evaluated; default per element. Choose
    /// [`VolumetricTreatment::NodalAverage`] for linear tetrahedra and
    /// [`VolumetricTreatment::ElementAverage`] for quadratic ones of nearly incompressible
    /// materials (`ν` above about 0.45), which otherwise lock.
    pub fn volumetric(mut self, treatment: VolumetricTreatment) -> Self {
        self.volumetric = treatment;
        self
    }

    /// Translation (m) applied to the rest mesh to place the body in the world.
    pub fn translation(mut self, translation: DVec3) -> Self {
        self.translation = translation;
        self
    }

    /// Rotation applied to the rest mesh (about the mesh origin, before the translation), as a
    /// scaled axis: the rotation axis times the angle (rad), as rapier's `RigidBodyBuilder` takes it.
    pub fn rotation(mut self, scaled_axis: DVec3) -> Self {
        self.rotation = DQuat::from_scaled_axis(scaled_axis);
        self
    }

    /// Rotation applied to the rest mesh, as a unit quaternion.
    pub fn orientation(mut self, orientation: DQuat) -> Self {
        self.rotation = orientation;
        self
    }

    /// Initial velocity (m/s) of every node (pinned nodes stay at rest); composes with
    /// [`DeformableBodyBuilder::angvel`].
    pub fn linvel(mut self, linvel: DVec3) -> Self {
        self.linvel = linvel;
        self
    }

    /// Initial angular velocity `ω` (rad/s) about the body's centre of mass `c` where the
    /// translation and rotation place it, as rapier's `RigidBodyBuilder::angvel`: node `i` at `xᵢ`
    /// starts at `linvel + ω × (xᵢ - c)` (pinned nodes stay at rest). The body then carries the
    /// angular momentum `I ω` ([`DeformableBody::angular_momentum`]), `I` the inertia tensor of
    /// its lumped nodal masses about `c`.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// let mesh = mesh::cuboid(DVec3::new(0.2, 0.1, 0.05), [4, 2, 1])?;
    /// let material = Material::new(MaterialModel::Corotated, 1e5, 0.3, 1000.0)?;
    /// let block = DeformableBodyBuilder::new(mesh, material)
    ///     .translation(DVec3::new(0.0, 1.0, 0.0))
    ///     .linvel(DVec3::new(0.5, 0.0, 0.0))
    ///     .angvel(DVec3::new(0.0, 0.0, 3.0))
    ///     .build()?;
    /// // The spin adds no linear momentum; the angular momentum lies along the spin axis.
    /// let momentum = block.linear_momentum();
    /// assert!((momentum - DVec3::new(0.5, 0.0, 0.0) * block.total_mass()).length() < 1e-12);
    /// let angular = block.angular_momentum();
    /// assert!(angular.z > 0.0 && angular.x.abs() + angular.y.abs() < 1e-12 * angular.z);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn angvel(mut self, angvel: DVec3) -> Self {
        self.angvel = angvel;
        self
    }

    /// Initial velocity (m/s) of `nodes`, in place of the one [`DeformableBodyBuilder::linvel`]
    /// and [`DeformableBodyBuilder::angvel`] give them: a region of the body set moving on its
    /// own (pick the nodes with [`TetMesh::nodes_where`]). A later call wins on the nodes two
    /// calls share; pinned nodes stay at rest.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// let mesh = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [10, 1, 1])?;
    /// let right_half = mesh.nodes_where(|p| p.x > 0.0);
    /// let material = Material::new(MaterialModel::Corotated, 1e5, 0.3, 1000.0)?;
    /// let bar = DeformableBodyBuilder::new(mesh, material)
    ///     .nodes_linvel(right_half, DVec3::new(1.0, 0.0, 0.0))
    ///     .build()?;
    /// for (x, v) in bar.positions().iter().zip(bar.velocities()) {
    ///     assert_eq!(*v, if x.x > 0.0 { DVec3::X } else { DVec3::ZERO });
    /// }
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn nodes_linvel(mut self, nodes: impl IntoIterator<Item = u32>, linvel: DVec3) -> Self {
        self.region_linvels
            .push((nodes.into_iter().collect(), linvel));
        self
    }

    /// Nodes held fixed at their initial world position (added to any pinned before).
    pub fn pinned_nodes(mut self, nodes: impl IntoIterator<Item = u32>) -> Self {
        self.pinned.extend(nodes);
        self
    }

    /// The smallest tetrahedron quality (smallest altitude over longest edge, dimensionless)
    /// accepted by [`DeformableBodyBuilder::build`]; default [`DEFAULT_MIN_ELEMENT_QUALITY`], 0 accepts
    /// every valid mesh.
    pub fn min_element_quality(mut self, quality: f64) -> Self {
        self.min_quality = quality;
        self
    }

    /// The collision groups of the body's surface, tested against each collider's as rapier
    /// tests two colliders' (`InteractionGroups::test`); default: every group.
    pub fn collision_groups(mut self, groups: InteractionGroups) -> Self {
        self.collision_groups = groups;
        self
    }

    /// The surface's Coulomb friction coefficient (non-negative, finite); default
    /// [`DEFAULT_FRICTION`]. A contact's coefficient combines it with the collider's or the other
    /// soft body's by the stronger of the two combine rules, as rapier combines two colliders'.
    pub fn friction(mut self, friction: f64) -> Self {
        self.friction = friction;
        self
    }

    /// How the body's friction combines with the other side's; default
    /// [`CoefficientCombineRule::Average`], as rapier's colliders.
    pub fn friction_combine_rule(mut self, rule: CoefficientCombineRule) -> Self {
        self.friction_combine_rule = rule;
        self
    }

    /// The surface's restitution coefficient (non-negative, finite); default 0, as rapier's
    /// colliders (see [`DeformableBody::restitution`]).
    pub fn restitution(mut self, restitution: f64) -> Self {
        self.restitution = restitution;
        self
    }

    /// How the body's restitution combines with the other side's; default
    /// [`CoefficientCombineRule::Average`], as rapier's colliders.
    pub fn restitution_combine_rule(mut self, rule: CoefficientCombineRule) -> Self {
        self.restitution_combine_rule = rule;
        self
    }

    /// Whether the surface collides with itself where the motion brings together parts far apart
    /// in the rest shape; default off (see [`DeformableBody::self_contact`]).
    pub fn self_contact(mut self, enabled: bool) -> Self {
        self.self_contact = enabled;
        self
    }

    /// Lets the coupling step the body as a rapier rigid body while its strain stays below
    /// `strain_tolerance` (dimensionless), and as a deformable body again when the loads on it
    /// rise (see [`RigidStandIn`](super::RigidStandIn)); for stiff bodies whose deformation does
    /// not matter. Refused by [`DeformableBodyBuilder::build`] unless `0 < strain_tolerance < 1`.
    pub fn rigid_stand_in(mut self, strain_tolerance: f64) -> Self {
        self.rigid_stand_in = Some(strain_tolerance);
        self
    }

    /// A fine tetrahedral mesh (rest positions in the same frame as the body's mesh, m) for the
    /// body to carry: each vertex moves with the element it lies in at rest (see
    /// [`crate::embedding`]), and contacts with colliders act on its surface instead of the
    /// simulation mesh's. A coarse cage of quadratic elements then sets the cost and accuracy
    /// of the elasticity, and the fine mesh the resolution of contact and output
    /// ([`DeformableBody::embedded_positions`]). Self-contact, contacts between soft bodies and rigid
    /// corners pressing on the body act on the simulation mesh's surface.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// // A 4-cell cage of quadratic hexahedra carrying a beam of 3 840 linear tetrahedra.
    /// let half = DVec3::new(0.5, 0.05, 0.05);
    /// let cage = mesh::QuadraticHexMesh::cuboid(half, [4, 1, 1])?;
    /// let fine = mesh::cuboid(half, [32, 4, 4])?;
    /// let material = Material::new(MaterialModel::Corotated, 1e6, 0.3, 1000.0)?;
    /// let beam = DeformableBodyBuilder::quadratic_hex(cage, material)
    ///     .embedded(fine)
    ///     .build()?;
    /// let surface = beam.embedded_positions().expect("embedded");
    /// assert_eq!(surface.len(), 33 * 5 * 5);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn embedded(mut self, fine: TetMesh) -> Self {
        self.embedded = Some(fine);
        self
    }

    /// User data stored on the body.
    pub fn user_data(mut self, user_data: u128) -> Self {
        self.user_data = user_data;
        self
    }

    /// Creates the body.
    ///
    /// The minimum element quality must lie in `[0, 1)`.
    ///
    /// # Errors
    /// [`Error::NodeOutOfRange`] for a pinned node or a node given a velocity
    /// ([`DeformableBodyBuilder::nodes_linvel`]) that does not exist;
    /// [`Error::NonFiniteInput`] for a non-finite velocity, angular velocity or translation or a
    /// zero rotation;
    /// [`Error::CoordinateOutOfRange`] naming the first node the placement puts beyond
    /// ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE);
    /// [`Error::SliverTet`] for a tetrahedron below the minimum quality (of the subdivision, for
    /// quadratic elements); [`Error::InvertedTet`] for a quadratic element whose rest map folds;
    /// [`Error::UnsupportedOption`] for nodal averaging on quadratic elements, or with region
    /// materials, and for region materials with an embedded mesh; [`Error::ElementOutOfRange`]
    /// and [`Error::RegionMaterialMismatch`] for a [region material](DeformableBodyBuilder::region_material)
    /// on an element that does not exist or of another model or Poisson's ratio;
    /// [`Error::OutsideSimulationMesh`] naming a vertex of the embedded mesh that no element
    /// carries;
    /// [`Error::InvalidSetting`] for a minimum quality outside `[0, 1)`, a
    /// [rigid stand-in](DeformableBodyBuilder::rigid_stand_in) tolerance outside `(0, 1)`, a negative or
    /// non-finite friction or restitution, or a [`DeformableBodyBuilder::linvel`] faster than
    /// [`SPEED_OF_LIGHT`](crate::body::SPEED_OF_LIGHT); [`Error::SpeedOutOfRange`] naming the
    /// first node that the angular velocity or a region's velocity sets moving faster than that.
    pub fn build(self) -> Result<DeformableBody, Error> {
        self.check_settings()?;
        let rigid_stand_in = self.rigid_stand_in.map(RigidStandIn::new).transpose()?;
        let pinned = self.pinned_flags()?;
        self.check_placement_and_velocity()?;
        let positions = self.placed_positions()?;
        let subdivision_parents = self
            .quadratic
            .as_ref()
            .map_or_else(Vec::new, |quadratic| quadratic.parents.clone());
        let mut materials = self.element_materials()?;
        let (elements, masses) = self.elements_and_masses(materials.as_ref())?;
        if let Some(materials) = &mut materials {
            let stiffness_volume = elements.sum_over_points(|_, _, _, weight| weight);
            let control_volumes = match &elements {
                Elements::Linear { .. } => lumped_masses(&self.mesh, |_| 1.0),
                Elements::Quadratic { elements, .. } => elements.lumped_volumes().to_vec(),
            };
            materials.set_geometry(control_volumes, stiffness_volume);
        }
        let velocities = self.initial_velocities(&positions, &masses, &pinned)?;
        let embedding = match self.embedded {
            Some(fine) => Some(Embedding::new(
                fine,
                &self.mesh,
                &elements,
                &subdivision_parents,
            )?),
            None => None,
        };
        Ok(DeformableBody {
            elements,
            masses,
            surface: BodySurface::of(&self.mesh),
            state_edits: 0,
            mesh: self.mesh,
            subdivision_parents,
            material: self.material,
            element_materials: materials,
            damping: self.damping,
            positions,
            velocities,
            pinned,
            embedding,
            loads: Vec::new(),
            load_edits: 0,
            load_change_work: 0.0,
            collision_groups: self.collision_groups,
            friction: self.friction,
            friction_combine_rule: self.friction_combine_rule,
            restitution: self.restitution,
            restitution_combine_rule: self.restitution_combine_rule,
            self_contact: self.self_contact,
            user_data: self.user_data,
            rigid_stand_in,
        })
    }

    /// Refuses contact coefficients and a minimum quality out of range, and a mesh with an
    /// element below the minimum quality.
    fn check_settings(&self) -> Result<(), Error> {
        for (parameter, value) in [
            ("friction", self.friction),
            ("restitution", self.restitution),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidSetting {
                    parameter,
                    value,
                    reason: "must be non-negative and finite",
                });
            }
        }
        if !(0.0..1.0).contains(&self.min_quality) {
            return Err(Error::InvalidSetting {
                parameter: "min_element_quality",
                value: self.min_quality,
                reason: "must lie in [0, 1)",
            });
        }
        let (tet, quality) = self.mesh.worst_tet();
        if quality < self.min_quality {
            return Err(Error::SliverTet {
                tet,
                quality,
                threshold: self.min_quality,
            });
        }
        Ok(())
    }

    /// Per node, whether it is pinned.
    fn pinned_flags(&self) -> Result<Vec<bool>, Error> {
        let node_count = self.mesh.node_count();
        let mut pinned = vec![false; node_count];
        for &node in &self.pinned {
            let flag = pinned.get_mut(node as usize).ok_or(Error::NodeOutOfRange {
                node: node as usize,
                node_count,
            })?;
            *flag = true;
        }
        Ok(pinned)
    }

    /// Refuses a non-finite translation, rotation or initial velocity, a zero rotation and a
    /// [`DeformableBodyBuilder::linvel`] faster than light.
    fn check_placement_and_velocity(&self) -> Result<(), Error> {
        let regions_finite = (self.region_linvels.iter()).all(|(_, linvel)| linvel.is_finite());
        for (parameter, finite) in [
            ("translation", self.translation.is_finite()),
            (
                "rotation",
                self.rotation.is_finite() && self.rotation.length() > 0.0,
            ),
            ("linvel", self.linvel.is_finite()),
            ("angvel", self.angvel.is_finite()),
            ("nodes_linvel", regions_finite),
        ] {
            if !finite {
                return Err(Error::NonFiniteInput { parameter });
            }
        }
        let speed = self.linvel.length();
        if speed > SPEED_OF_LIGHT {
            return Err(Error::InvalidSetting {
                parameter: "linvel",
                value: speed,
                reason: "no node may move faster than light (299792458 m/s)",
            });
        }
        Ok(())
    }

    /// The nodes' world positions (m): the rest mesh rotated, then translated.
    fn placed_positions(&self) -> Result<Vec<DVec3>, Error> {
        let rotation = self.rotation.normalize();
        let positions: Vec<DVec3> = self
            .mesh
            .positions()
            .iter()
            .map(|p| rotation * *p + self.translation)
            .collect();
        for (node, &position) in positions.iter().enumerate() {
            check_position(node, position)?;
        }
        Ok(positions)
    }

    /// The nodes' initial velocities (m/s): the rigid motion `linvel + angvel × (x - c)` about
    /// the centre of mass `c` of `positions` (m) weighted by `masses` (kg), the regions' own
    /// velocities on their nodes, and rest on the `pinned` ones.
    fn initial_velocities(
        &self,
        positions: &[DVec3],
        masses: &[f64],
        pinned: &[bool],
    ) -> Result<Vec<DVec3>, Error> {
        let center_of_mass = positions
            .iter()
            .zip(masses)
            .map(|(x, m)| *x * *m)
            .sum::<DVec3>()
            / masses.iter().sum::<f64>();
        let mut velocities: Vec<DVec3> = positions
            .iter()
            .map(|x| self.linvel + self.angvel.cross(*x - center_of_mass))
            .collect();
        for (nodes, linvel) in &self.region_linvels {
            for &node in nodes {
                let node_count = velocities.len();
                let velocity = velocities
                    .get_mut(node as usize)
                    .ok_or(Error::NodeOutOfRange {
                        node: node as usize,
                        node_count,
                    })?;
                *velocity = *linvel;
            }
        }
        for (node, (velocity, &pinned)) in velocities.iter_mut().zip(pinned).enumerate() {
            if pinned {
                *velocity = DVec3::ZERO;
            }
            check_velocity(node, *velocity)?;
        }
        Ok(velocities)
    }

    /// The materials of the elements given their own ([`DeformableBodyBuilder::region_material`]);
    /// `None` if none is.
    fn element_materials(&self) -> Result<Option<ElementMaterials>, Error> {
        if self.region_materials.is_empty() {
            return Ok(None);
        }
        let element_count = match &self.quadratic {
            Some(quadratic) => quadratic.nodes.len() / quadratic.shape.node_count(),
            None => self.mesh.tet_count(),
        };
        let materials =
            ElementMaterials::new(&self.material, self.region_materials.clone(), element_count)?;
        let unsupported = if self.volumetric == VolumetricTreatment::NodalAverage {
            Some((
                "VolumetricTreatment::NodalAverage with region materials",
                "its patches of elements would mix materials",
            ))
        } else if self.embedded.is_some() {
            Some((
                "an embedded mesh with region materials",
                "its stresses would take the body's material",
            ))
        } else {
            None
        };
        match unsupported {
            Some((option, reason)) if materials.is_some() => {
                Err(Error::UnsupportedOption { option, reason })
            }
            _ => Ok(materials),
        }
    }

    /// The elements (linear, with nodal averaging if asked; or quadratic, with the projected
    /// pressure if asked) and the nodes' lumped masses (kg), each element weighted by its
    /// stiffness and lumped with its density when `materials` differ by element.
    fn elements_and_masses(
        &self,
        materials: Option<&ElementMaterials>,
    ) -> Result<(Elements, Vec<f64>), Error> {
        let density =
            |element: usize| materials.map_or(self.material.density(), |m| m.densities()[element]);
        let Some(quadratic) = &self.quadratic else {
            let mut fvm = FvmMesh::new(&self.mesh);
            if let Some(materials) = materials {
                fvm.scale_stiffness(materials.stiffness_factors());
            }
            let nodal_averaging = (self.volumetric == VolumetricTreatment::NodalAverage)
                .then(|| NodalAveraging::new(&fvm));
            return Ok((
                Elements::Linear {
                    fvm,
                    nodal_averaging,
                },
                lumped_masses(&self.mesh, density),
            ));
        };
        if self.volumetric == VolumetricTreatment::NodalAverage {
            return Err(Error::UnsupportedOption {
                option: "VolumetricTreatment::NodalAverage",
                reason: "nodal averaging applies to linear tetrahedra; quadratic ones \
                         average per element (VolumetricTreatment::ElementAverage)",
            });
        }
        let mut elements =
            QuadraticElements::new(quadratic.shape, self.mesh.positions(), &quadratic.nodes)?;
        let masses = match materials {
            Some(materials) => {
                elements.scale_stiffness(materials.stiffness_factors());
                elements.lumped(density)
            }
            None => (elements.lumped_volumes().iter())
                .map(|volume| volume * self.material.density())
                .collect(),
        };
        let pressure = (self.volumetric == VolumetricTreatment::ElementAverage)
            .then(|| PressureBasis::new(&elements));
        Ok((Elements::Quadratic { elements, pressure }, masses))
    }
}

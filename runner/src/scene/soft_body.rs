//! `[[soft_body]]`: a finite-volume soft body: its mesh, material, placement, initial velocity
//! (linear, angular and per region), contact properties, pinned regions, attachments to
//! rigid bodies and loads.
//!
//! ```toml
//! [[soft_body]]
//! name = "beam"
//! mesh = { cuboid = { half_extents = [0.5, 0.05, 0.05], cells = [20, 2, 2] } }
//! material = { model = "st_venant_kirchhoff", young = 1e8, poisson = 0.3, density = 1000.0 }
//! damping = { stiffness_time = 1e-3 }
//! materials = [{ min = [0, -1, -1], max = [1, 1, 1], young = 4e8 }]
//!                                 # elements (centroid in the box, or a file's volume `region`)
//!                                 # of their own `young` (Pa) and `density` (kg/m³); see
//!                                 # `material`
//! translation = [0.5, 0.0, 0.0]   # m, default 0
//! rotation = [0.0, 0.0, 0.0]      # scaled axis (rad), default 0
//! linvel = [0.0, 0.0, 0.0]        # m/s, default 0
//! angvel = [0.0, 0.0, 0.0]        # rad/s about the placed centre of mass, default 0
//! friction = 0.5                  # default 0.5
//! self_contact = false            # default false
//! rigid_stand_in = 1e-4           # strain tolerance: while strained less, the body steps as a
//!                                 # rapier rigid body (its hull the collider), elastic again
//!                                 # when loads rise; default none
//! volumetric = "per_element"      # or "nodal_average" / "element_average" (nearly incompressible:
//!                                 # linear / quadratic elements), default per_element
//! elements = "linear"             # or "quadratic" (10-node tetrahedra, accurate in bending), or
//!                                 # "quadratic_hex" (a cage of 27-node hexahedra: over a cuboid
//!                                 # mesh's cells, or a file's hexahedra)
//! embedded = { cuboid = { half_extents = [0.5, 0.05, 0.05], cells = [40, 4, 4] } }
//!                                 # a fine mesh carried by the elements: contacts and output
//!                                 # use its surface; default none
//! pinned = [{ min = [-0.51, -1, -1], max = [-0.49, 1, 1] }]         # boxes in rest coordinates
//! attach = [{ rigid = "ball", min = [-1, -0.26, -1], max = [1, -0.24, 1] }]
//! velocity = [{ min = [0.4, -1, -1], max = [0.6, 1, 1], linvel = [0, 1, 0] }]
//!                                 # the box's nodes start at `linvel` (m/s) instead
//! loads = [{ traction = [0, -1e3, 0], min = [0.49, -1, -1], max = [0.51, 1, 1] }]
//!                                 # pressure, traction, body force, cable (see `load`)
//! ```
//! Regions are boxes `min`..`max` (m) in the mesh's rest coordinates, before the translation and
//! rotation, or, for a mesh file with named parts (Gmsh physical groups, a `.vtu` file's cell
//! tags), `region = "clamp"` (a group's name) or `region = 3` (its physical tag): the nodes of
//! that group's elements, as in
//! `pinned = [{ region = "clamp" }]`. Each region must hold at least one node.

use super::check::Checker;
use super::load::LoadSpec;
use super::material::{DampingSpec, MaterialSpec, RegionMaterialSpec};
use super::mesh::{CAGE_MESHES, MeshSpec};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::mesh::TetMesh;
use rapier_fvm::mesh::import::{MeshRegion, RegionId};
use serde::Deserialize;

/// A soft body.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SoftBodySpec {
    /// Its name, unique among all bodies (probes and file names use it).
    pub name: String,
    /// The mesh.
    pub mesh: MeshSpec,
    /// The material.
    pub material: MaterialSpec,
    /// Rayleigh damping; default none.
    pub damping: Option<DampingSpec>,
    /// Elements of their own Young's modulus and density; a later entry wins where two
    /// overlap.
    #[serde(default)]
    pub materials: Vec<RegionMaterialSpec>,
    /// Translation of the rest mesh (m); default 0.
    #[serde(default)]
    pub translation: [f64; 3],
    /// Rotation of the rest mesh about its origin, as a scaled axis (rad); default 0.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Initial velocity of every node (m/s); default 0.
    #[serde(default)]
    pub linvel: [f64; 3],
    /// Initial angular velocity (rad/s) about the centre of mass where the translation and
    /// rotation place the body, added to `linvel`; default 0.
    #[serde(default)]
    pub angvel: [f64; 3],
    /// Coulomb friction coefficient of the surface; default 0.5.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Whether the surface collides with itself; default false.
    #[serde(default)]
    pub self_contact: bool,
    /// The strain tolerance (dimensionless) below which the body may step as a rapier rigid
    /// body (see `rapier_fvm::body::RigidStandIn`); default none.
    pub rigid_stand_in: Option<f64>,
    /// How the volumetric energy is evaluated; default per element.
    #[serde(default)]
    pub volumetric: VolumetricSpec,
    /// The elements; default linear tetrahedra.
    #[serde(default)]
    pub elements: ElementsSpec,
    /// A fine mesh the elements carry, for contact and output; default none.
    pub embedded: Option<MeshSpec>,
    /// Regions whose nodes are held fixed.
    #[serde(default)]
    pub pinned: Vec<RegionSpec>,
    /// Regions whose nodes are glued to rigid bodies.
    #[serde(default)]
    pub attach: Vec<AttachmentSpec>,
    /// Regions whose nodes start at their own velocity, in place of `linvel` and `angvel`; a
    /// later region wins where two overlap, pinned nodes stay at rest.
    #[serde(default)]
    pub velocity: Vec<RegionVelocitySpec>,
    /// Loads besides gravity (see [`super::load`]).
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
}

fn default_friction() -> f64 {
    rapier_fvm::body::DEFAULT_FRICTION
}

/// How a soft body's volumetric energy is evaluated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VolumetricSpec {
    /// Per tetrahedron.
    #[default]
    PerElement,
    /// Averaged over each node's tetrahedra (against locking of linear elements at ν near 0.5).
    NodalAverage,
    /// Averaged over each element (against locking of quadratic elements at ν near 0.5).
    ElementAverage,
}

impl VolumetricSpec {
    /// The library's treatment.
    pub fn treatment(self) -> rapier_fvm::fvm::VolumetricTreatment {
        use rapier_fvm::fvm::VolumetricTreatment;
        match self {
            Self::PerElement => VolumetricTreatment::PerElement,
            Self::NodalAverage => VolumetricTreatment::NodalAverage,
            Self::ElementAverage => VolumetricTreatment::ElementAverage,
        }
    }
}

/// The elements of a soft body.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementsSpec {
    /// 4-node tetrahedra.
    #[default]
    Linear,
    /// 10-node tetrahedra: the mesh's, or mid-edge nodes added to it.
    Quadratic,
    /// A cage of 27-node hexahedra over a cuboid mesh's cells or a file's hexahedra.
    QuadraticHex,
}

/// The nodes a pin selects: a box of rest coordinates or a region of the mesh file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// Lower corner of the box (m).
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m).
    pub max: Option<[f64; 3]>,
    /// The mesh file's region, in place of a box.
    pub region: Option<RegionName>,
}

/// Nodes of a region glued to a rigid body.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttachmentSpec {
    /// The rigid body's name.
    pub rigid: String,
    /// Lower corner of the box (m, rest coordinates).
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m, rest coordinates).
    pub max: Option<[f64; 3]>,
    /// The mesh file's region, in place of a box.
    pub region: Option<RegionName>,
}

/// Nodes of a region given their own initial velocity.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionVelocitySpec {
    /// Lower corner of the box (m, rest coordinates).
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m, rest coordinates).
    pub max: Option<[f64; 3]>,
    /// The mesh file's region, in place of a box.
    pub region: Option<RegionName>,
    /// The nodes' initial velocity (m/s).
    pub linvel: [f64; 3],
}

/// A region of a mesh file as a scene names it: `"clamp"` (its name) or `3` (its tag).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum RegionName {
    /// The physical group's tag.
    Tag(i64),
    /// The physical group's name.
    Name(String),
}

impl RegionName {
    /// The library's name for it.
    pub fn id(&self) -> RegionId {
        match self {
            Self::Tag(tag) => RegionId::Tag(*tag),
            Self::Name(name) => RegionId::Name(name.clone()),
        }
    }
}

/// Which nodes a pin, an attachment or an initial velocity takes: a box or a file's region.
#[derive(Debug, Clone, Copy)]
pub struct Selection<'a> {
    /// Lower corner of the box (m, rest coordinates).
    pub min: Option<[f64; 3]>,
    /// Upper corner of the box (m, rest coordinates).
    pub max: Option<[f64; 3]>,
    /// The mesh file's region.
    pub region: Option<&'a RegionName>,
}

/// `selection()` for each spec that selects nodes (a load's boundary, a material's elements)
/// by a box or a region.
macro_rules! selects_nodes {
    ($($spec:ty),*) => {$(
        impl $spec {
            /// What it selects: a box of rest coordinates or a mesh file's region.
            pub fn selection(&self) -> Selection<'_> {
                Selection {
                    min: self.min,
                    max: self.max,
                    region: self.region.as_ref(),
                }
            }
        }
    )*};
}

selects_nodes!(
    RegionSpec,
    AttachmentSpec,
    RegionVelocitySpec,
    LoadSpec,
    RegionMaterialSpec
);

impl Selection<'_> {
    /// The nodes of `mesh` (rest coordinates) inside the box (bounds included), or those of the
    /// region among `regions` (numbered as `mesh`'s nodes) read from the file `path`.
    ///
    /// # Errors
    /// The library's words when the region is not in the file or is ambiguous.
    pub fn nodes(
        &self,
        mesh: &TetMesh,
        regions: &[MeshRegion],
        path: &str,
    ) -> Result<Vec<u32>, rapier_fvm::Error> {
        match (self.region, self.min, self.max) {
            (Some(name), _, _) => Ok(MeshRegion::find(regions, &name.id(), path)?.nodes.clone()),
            (None, Some(min), Some(max)) => Ok(nodes_in(mesh, min, max)),
            _ => Ok(Vec::new()),
        }
    }

    /// Checks that it is a box or a region, not both, and the box's corners.
    pub(crate) fn check(&self, key: &str, c: &mut Checker<'_>) {
        match (self.region, self.min, self.max) {
            (None, Some(min), Some(max)) => check_box(key, min, max, c),
            (Some(_), None, None) => {}
            (None, _, _) => c.fail(key, "give a box (`min` and `max`) or a `region`"),
            (Some(_), _, _) => c.fail(key, "give a box (`min` and `max`) or a `region`, not both"),
        }
    }
}

fn nodes_in(mesh: &TetMesh, min: [f64; 3], max: [f64; 3]) -> Vec<u32> {
    let (min, max) = (DVec3::from_array(min), DVec3::from_array(max));
    mesh.nodes_where(|p| p.cmpge(min).all() && p.cmple(max).all())
}

/// Checks a box's corners.
fn check_box(key: &str, min: [f64; 3], max: [f64; 3], c: &mut Checker<'_>) {
    c.finite_vector(&format!("{key}.min"), min);
    c.finite_vector(&format!("{key}.max"), max);
    if min.iter().zip(&max).any(|(a, b)| a > b) {
        c.fail(
            &format!("{key}.max"),
            format!("{max:?} is below min {min:?}"),
        );
    }
}

impl SoftBodySpec {
    /// Checks the values; `key` is the body's key path, `rigid_names` the scene's rigid bodies.
    pub(crate) fn check(&self, key: &str, rigid_names: &[&str], c: &mut Checker<'_>) {
        self.mesh.check(&format!("{key}.mesh"), c);
        if let Some(embedded) = &self.embedded {
            embedded.check(&format!("{key}.embedded"), c);
        }
        let cage_mesh = self.mesh.cuboid.is_some() || self.mesh.file.is_some();
        if self.elements == ElementsSpec::QuadraticHex && !cage_mesh {
            c.fail(&format!("{key}.elements"), CAGE_MESHES.to_owned());
        }
        self.material.check(&format!("{key}.material"), c);
        if let Some(damping) = &self.damping {
            damping.check(&format!("{key}.damping"), c);
        }
        c.finite_vector(&format!("{key}.translation"), self.translation);
        c.finite_vector(&format!("{key}.rotation"), self.rotation);
        c.speed(&format!("{key}.linvel"), self.linvel);
        c.finite_vector(&format!("{key}.angvel"), self.angvel);
        c.non_negative(&format!("{key}.friction"), self.friction, "dimensionless");
        if let Some(tolerance) = self.rigid_stand_in
            && !(tolerance > 0.0 && tolerance < 1.0)
        {
            c.fail(
                &format!("{key}.rigid_stand_in"),
                format!("the strain tolerance must lie in (0, 1), got {tolerance}"),
            );
        }
        let selections = (self.pinned.iter().map(RegionSpec::selection))
            .chain(self.attach.iter().map(AttachmentSpec::selection))
            .chain(self.velocity.iter().map(RegionVelocitySpec::selection))
            .chain(self.loads.iter().map(LoadSpec::selection))
            .chain(self.materials.iter().map(RegionMaterialSpec::selection));
        if self.mesh.file.is_none() && selections.into_iter().any(|s| s.region.is_some()) {
            c.fail(
                &format!("{key}.mesh"),
                "a `region` selects nodes of a mesh file's named parts; this mesh is not a file"
                    .to_owned(),
            );
        }
        for (i, region) in self.pinned.iter().enumerate() {
            region.selection().check(&format!("{key}.pinned[{i}]"), c);
        }
        for (i, attachment) in self.attach.iter().enumerate() {
            let key = format!("{key}.attach[{i}]");
            attachment.selection().check(&key, c);
            if !rigid_names.contains(&attachment.rigid.as_str()) {
                c.fail(
                    &format!("{key}.rigid"),
                    format!("no rigid body is named {:?}", attachment.rigid),
                );
            }
        }
        for (i, region) in self.velocity.iter().enumerate() {
            let key = format!("{key}.velocity[{i}]");
            region.selection().check(&key, c);
            c.speed(&format!("{key}.linvel"), region.linvel);
        }
        for (i, load) in self.loads.iter().enumerate() {
            load.check(&format!("{key}.loads[{i}]"), c);
        }
        for (i, material) in self.materials.iter().enumerate() {
            material.check(&format!("{key}.materials[{i}]"), c);
        }
        if !self.materials.is_empty() {
            if self.volumetric == VolumetricSpec::NodalAverage {
                c.fail(
                    &format!("{key}.materials"),
                    "region materials do not work with volumetric = \"nodal_average\" (its \
                     patches of elements would mix materials)"
                        .to_owned(),
                );
            }
            if self.embedded.is_some() {
                c.fail(
                    &format!("{key}.materials"),
                    "region materials do not work with an `embedded` mesh (its stresses would \
                     take the body's material)"
                        .to_owned(),
                );
            }
        }
    }
}

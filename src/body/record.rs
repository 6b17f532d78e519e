//! What a [`DeformableBody`] is written as with the feature `serde-serialize`: what it was built
//! from (rest mesh, elements, material and region materials, damping, volumetric treatment,
//! embedded mesh, pins, contact coefficients, user data, loads) and its nodal state. Read back,
//! the body is built again by [`DeformableBodyBuilder`], so every check of a new body applies to a file (a typed error,
//! never a panic), and the rest data comes out as it was: the build is deterministic.

use super::{DeformableBody, DeformableBodyBuilder, RigidStandIn};
use crate::Error;
use crate::damping::RayleighDamping;
use crate::element::ElementShape;
use crate::fvm::VolumetricTreatment;
use crate::load::Load;
use crate::material::Material;
use crate::mesh::TetMesh;
use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::geometry::InteractionGroups;
use rapier3d::glamx::DVec3;
use serde::{Deserialize, Serialize};

/// A deformable body as written.
#[derive(Serialize, Deserialize)]
pub(super) struct BodyRecord {
    /// The rest mesh: the elements, or the subdivision of the quadratic ones.
    mesh: TetMesh,
    /// The quadratic elements' shape, nodes and the element of each subdivision tetrahedron.
    quadratic: Option<(ElementShape, Vec<u32>, Vec<u32>)>,
    material: Material,
    /// Elements given their own material (none in files written before region materials, and
    /// not written for a body of one material).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    region_materials: Vec<(Vec<u32>, Material)>,
    damping: Option<RayleighDamping>,
    volumetric: VolumetricTreatment,
    embedded: Option<TetMesh>,
    pinned: Vec<u32>,
    collision_groups: InteractionGroups,
    friction: f64,
    friction_combine_rule: CoefficientCombineRule,
    restitution: f64,
    restitution_combine_rule: CoefficientCombineRule,
    self_contact: bool,
    user_data: u128,
    /// Whether the body may stand in as a rigid body (none in files written before stand-ins).
    #[serde(default)]
    rigid_stand_in: Option<RigidStandIn>,
    /// The loads besides gravity (none in files written before loads existed).
    #[serde(default)]
    loads: Vec<Load>,
    #[serde(default)]
    load_edits: u64,
    #[serde(default)]
    load_change_work: f64,
    /// Positions (m) and velocities (m/s) of the nodes.
    positions: Vec<DVec3>,
    velocities: Vec<DVec3>,
    state_edits: u64,
}

impl From<&DeformableBody> for BodyRecord {
    fn from(body: &DeformableBody) -> Self {
        let quadratic = body
            .elements
            .quadratic_nodes()
            .map(|(shape, nodes)| (shape, nodes.to_vec(), body.subdivision_parents.clone()));
        Self {
            mesh: body.mesh.clone(),
            quadratic,
            material: body.material,
            region_materials: (body.element_materials.as_ref())
                .map_or_else(Vec::new, |m| m.assignments().to_vec()),
            damping: body.damping,
            volumetric: body.volumetric_treatment(),
            embedded: body.embedding.as_ref().map(|e| e.mesh().clone()),
            pinned: (0..body.node_count() as u32)
                .filter(|&n| body.pinned[n as usize])
                .collect(),
            collision_groups: body.collision_groups,
            friction: body.friction,
            friction_combine_rule: body.friction_combine_rule,
            restitution: body.restitution,
            restitution_combine_rule: body.restitution_combine_rule,
            self_contact: body.self_contact,
            user_data: body.user_data,
            rigid_stand_in: body.rigid_stand_in,
            loads: body.loads.clone(),
            load_edits: body.load_edits,
            load_change_work: body.load_change_work,
            positions: body.positions.clone(),
            velocities: body.velocities.clone(),
            state_edits: body.state_edits,
        }
    }
}

impl TryFrom<BodyRecord> for DeformableBody {
    type Error = Error;

    fn try_from(record: BodyRecord) -> Result<Self, Error> {
        let mut builder = match record.quadratic {
            Some(parts) => {
                DeformableBodyBuilder::from_quadratic_parts(record.mesh, record.material, parts)?
            }
            None => DeformableBodyBuilder::new(record.mesh, record.material),
        };
        if let Some(damping) = record.damping {
            builder = builder.damping(damping);
        }
        if let Some(embedded) = record.embedded {
            builder = builder.embedded(embedded);
        }
        for (elements, material) in record.region_materials {
            builder = builder.region_material(elements, material);
        }
        builder = builder
            .volumetric(record.volumetric)
            .pinned_nodes(record.pinned)
            // The body passed its quality check when first built.
            .min_element_quality(0.0)
            .collision_groups(record.collision_groups)
            .friction(record.friction)
            .friction_combine_rule(record.friction_combine_rule)
            .restitution(record.restitution)
            .restitution_combine_rule(record.restitution_combine_rule)
            .self_contact(record.self_contact)
            .user_data(record.user_data);
        if let Some(stand_in) = record.rigid_stand_in {
            builder = builder.rigid_stand_in(stand_in.strain_tolerance);
        }
        let mut body = builder.build()?;
        let nodes = body.node_count();
        for given in [record.positions.len(), record.velocities.len()] {
            if given != nodes {
                return Err(Error::WrongNodeCount {
                    given,
                    node_count: nodes,
                });
            }
        }
        for load in record.loads {
            body.add_load(load)?;
        }
        body.load_edits = record.load_edits;
        body.load_change_work = record.load_change_work;
        body.positions = record.positions;
        body.velocities = record.velocities;
        body.state_edits = record.state_edits;
        // The state a step would take: written by one, or set through the raw slices.
        body.check_state()?;
        Ok(body)
    }
}

impl Serialize for DeformableBody {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        BodyRecord::from(self).serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for DeformableBody {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let record = BodyRecord::deserialize(deserializer)?;
        Self::try_from(record).map_err(serde::de::Error::custom)
    }
}

//! Rigid corners against soft faces: the vertices of a collider's polyhedral shape (cuboid,
//! convex polyhedron, triangle mesh, and those within compounds) against the soft body's
//! boundary triangles, so that a corner or a small box pressing between the nodes of a coarse
//! mesh is held by the face rather than sinking in until its faces meet nodes.
//!
//! A vertex within reach of a boundary triangle facing it (see [`SurfaceTree`]) gets a contact
//! plane through the triangle's nearest point, with the triangle's outward normal. The explicit
//! sweeps solve it like a node's contact with the roles swapped: the rigid body's point takes
//! the impulse, the triangle's nodes its opposite by the contact point's barycentric weights,
//! and the plane follows the triangle through the step.

use super::detect::NearCollider;
use super::surface_tree::SurfaceTree;
use super::{Coefficients, ContactSides, RigidProxy, SoftPoint, VelocityConstraint};
use crate::body::BodyConstraints;
use crate::body::DeformableBody;
use rapier3d::geometry::{ColliderHandle, Shape};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::parry::bounding_volume::BoundingVolume;

/// A collider's vertex touching one of the soft body's boundary triangles.
#[derive(Debug, Clone)]
pub(crate) struct CornerContact {
    /// The collider and its rigid body's index among the body's proxies, if it has one.
    pub(crate) collider: ColliderHandle,
    pub(crate) proxy: Option<usize>,
    /// The vertex in the world (m), moved at its rigid body's velocity through the soft step.
    vertex: DVec3,
    /// The contact point on the soft triangle.
    on_triangle: SoftPoint,
    /// The contact plane: a point (m) and the triangle's outward unit normal.
    point: DVec3,
    normal: DVec3,
    /// The soft body's and the collider's coefficients, combined.
    coefficients: Coefficients,
    constraint: VelocityConstraint,
    /// The impulse (N s) the triangle gave the collider over the last step.
    pub(crate) impulse: DVec3,
}

impl CornerContact {
    /// Where (m) and with what mean force (N) the soft body pushed the collider over the last
    /// step, of length `dt` (s).
    pub(crate) fn force_on_collider(&self, dt: f64) -> (DVec3, DVec3) {
        (self.vertex, self.impulse / dt)
    }
}

/// Whether `shape` has vertices [`for_each_vertex`] visits.
pub(crate) fn has_vertices(shape: &dyn Shape) -> bool {
    shape.as_cuboid().is_some()
        || shape.as_convex_polyhedron().is_some()
        || shape.as_trimesh().is_some()
        || shape.as_compound().is_some()
}

/// Calls `each(vertex, outward)` for the world-space vertices (m) of `shape` at `pose` that have
/// corners (cuboids, convex polyhedra, triangle meshes, and those within compounds), with the
/// direction from the shape's centre to the vertex.
fn for_each_vertex(shape: &dyn Shape, pose: &Pose, each: &mut impl FnMut(DVec3, DVec3)) {
    let centre = pose.translation.as_dvec3();
    let mut emit = |local: rapier3d::math::Vector| {
        let vertex = pose.transform_point(local).as_dvec3();
        each(vertex, vertex - centre);
    };
    if let Some(cuboid) = shape.as_cuboid() {
        let h = cuboid.half_extents;
        for corner in 0..8 {
            let sign = |bit: u32| if corner & (1 << bit) == 0 { -1.0 } else { 1.0 };
            emit(rapier3d::math::Vector::new(
                sign(0) * h.x,
                sign(1) * h.y,
                sign(2) * h.z,
            ));
        }
    } else if let Some(polyhedron) = shape.as_convex_polyhedron() {
        polyhedron.points().iter().for_each(|p| emit(*p));
    } else if let Some(mesh) = shape.as_trimesh() {
        mesh.vertices().iter().for_each(|p| emit(*p));
    } else if let Some(compound) = shape.as_compound() {
        for (local_pose, part) in compound.shapes() {
            for_each_vertex(&**part, &(*pose * *local_pose), each);
        }
    }
}

impl DeformableBody {
    /// The contacts of the vertices of `near`'s shape within its reach (m) of the body's boundary
    /// triangles in `tree`, skipping triangles with a node glued to the collider's rigid body;
    /// their proxy is left for the caller to set.
    pub(super) fn find_corner_contacts(
        &self,
        tree: &SurfaceTree,
        near: &NearCollider<'_>,
    ) -> Vec<CornerContact> {
        let NearCollider {
            handle: collider,
            shape,
            pose,
            reach,
            coefficients,
            ref glued,
            ..
        } = *near;
        let bounds = tree.bounds.loosened(reach as f32);
        let mut found = Vec::new();
        for_each_vertex(shape.as_ref(), pose, &mut |vertex, outward| {
            if !bounds.contains_local_point(vertex.as_vec3()) {
                return;
            }
            let skipped = |triangle: &[u32; 3]| triangle.iter().any(|n| glued.contains(n));
            if let Some(hit) = tree.nearest_facing(self, vertex, outward, reach, skipped) {
                found.push(CornerContact {
                    collider,
                    proxy: None,
                    vertex,
                    on_triangle: hit.soft_point(),
                    point: hit.point,
                    normal: hit.normal,
                    coefficients,
                    constraint: VelocityConstraint::default(),
                    impulse: DVec3::ZERO,
                });
            }
        });
        found
    }
}

/// Readies the corner contacts for an explicit substep of `h` (s): each plane moves to its
/// triangle's contact point where the nodes are now.
pub(crate) fn prepare_corners(body: &mut DeformableBody, h: f64) {
    let depenetration_speed = body.constraints.settings.depenetration_speed;
    for contact in &mut body.constraints.corner_contacts {
        if let Some((point, normal)) = contact.on_triangle.plane(&body.positions) {
            contact.point = point;
            contact.normal = normal;
        }
        let gap = (contact.vertex - contact.point).dot(contact.normal);
        let normal_speed = || {
            let vertex_velocity = contact.proxy.map_or(DVec3::ZERO, |p| {
                body.constraints.rigid_proxies[p].velocity_at(contact.vertex)
            });
            (vertex_velocity - contact.on_triangle.velocity(&body.velocities)).dot(contact.normal)
        };
        contact.constraint = VelocityConstraint::new(gap, h, depenetration_speed).bounce(
            gap,
            h,
            normal_speed,
            contact.coefficients.restitution,
        );
    }
}

/// Moves the corners with their rigid bodies' velocities for `h` (s), as the body's nodes move
/// at the end of an explicit substep: the gaps then follow both sides.
pub(crate) fn advance_corners(body: &mut DeformableBody, h: f64) {
    for contact in &mut body.constraints.corner_contacts {
        if let Some(p) = contact.proxy {
            contact.vertex += body.constraints.rigid_proxies[p].velocity_at(contact.vertex) * h;
        }
    }
}

/// One sweep over the corner contacts (see [`VelocityConstraint`]).
pub(crate) fn solve_corners(body: &mut DeformableBody) {
    let DeformableBody {
        constraints:
            BodyConstraints {
                corner_contacts,
                rigid_proxies,
                ..
            },
        velocities,
        masses,
        pinned,
        ..
    } = body;
    for contact in corner_contacts.iter_mut() {
        let mut sides = Corner {
            rigid: contact.proxy.map(|p| &mut rigid_proxies[p]),
            vertex: contact.vertex,
            velocities,
            masses,
            pinned,
            on_triangle: contact.on_triangle,
        };
        contact.impulse +=
            contact
                .constraint
                .correct(contact.normal, contact.coefficients.friction, &mut sides);
    }
}

/// A rigid vertex and a soft triangle, within a sweep.
struct Corner<'a> {
    rigid: Option<&'a mut RigidProxy>,
    vertex: DVec3,
    velocities: &'a mut [DVec3],
    masses: &'a [f64],
    pinned: &'a [bool],
    on_triangle: SoftPoint,
}

impl ContactSides for Corner<'_> {
    fn relative_velocity(&self) -> DVec3 {
        let vertex = self
            .rigid
            .as_ref()
            .map_or(DVec3::ZERO, |r| r.velocity_at(self.vertex));
        vertex - self.on_triangle.velocity(self.velocities)
    }

    fn inverse_mass_along(&self, direction: DVec3) -> f64 {
        self.rigid
            .as_ref()
            .map_or(0.0, |r| r.inverse_mass_along(self.vertex, direction))
            + self.on_triangle.inverse_mass(self.masses, self.pinned)
    }

    fn exchange(&mut self, impulse: DVec3) {
        if let Some(rigid) = self.rigid.as_mut() {
            rigid.apply(impulse, self.vertex);
        }
        self.on_triangle
            .apply(-impulse, self.velocities, self.masses, self.pinned);
    }
}

//! Rigid corners against soft faces: the vertices of a collider's polyhedral shape (cuboid,
//! convex polyhedron, triangle mesh), and the closest points of a rounded one (ball, capsule,
//! cylinder, cone, see [`super::support`]), alone or within compounds, against the soft body's
//! boundary triangles, so that a corner, a small box or a small ball pressing between the nodes
//! of a coarse mesh is held by the face rather than sinking in until its faces meet nodes.
//!
//! A vertex within reach of a boundary triangle facing it (see [`SurfaceTree`]) gets a contact
//! plane through the triangle's nearest point, with the triangle's outward normal. The explicit
//! sweeps solve it like a node's contact with the roles swapped: the rigid body's point takes
//! the impulse, the triangle's nodes its opposite by the contact point's barycentric weights,
//! and the plane follows the triangle through the step.
//!
//! The implicit side is in [`implicit`].

mod implicit;

pub(in crate::contact) use implicit::stiffen_deep_corners;
pub(crate) use implicit::{
    corner_penalty_energy, for_each_corner_stencil, for_each_corner_term, lag_corner_friction,
    record_corner_impulses,
};

use super::detect::NearCollider;
use super::stiffening::Stiffening;
use super::support;
use super::surface_tree::{SurfaceTree, TrianglePoint};
use super::{Coefficients, ContactSet, ContactSides, SoftPoint, VelocityConstraint};
use crate::body::DeformableBody;
use crate::rigid::RigidProxy;
use rapier3d::geometry::{ColliderHandle, Shape};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use rapier3d::parry::bounding_volume::BoundingVolume;

/// A collider's vertex touching one of the soft body's boundary triangles.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CornerContact {
    /// The collider and its rigid body's index among the body's proxies, if it has one.
    pub(crate) collider: ColliderHandle,
    pub(crate) proxy: Option<usize>,
    /// The vertex in the world (m), moved at its rigid body's velocity through the soft step.
    vertex: DVec3,
    /// The contact point on the soft triangle.
    on_triangle: SoftPoint,
    /// The contact plane: a point (m) and its unit normal, the triangle's outward normal when
    /// `follows_face` (then turning with it through the step), otherwise fixed at detection (a
    /// rounded shape on the triangle's edge or corner, see [`super::support`]).
    point: DVec3,
    normal: DVec3,
    follows_face: bool,
    /// The soft body's and the collider's coefficients, combined.
    coefficients: Coefficients,
    constraint: VelocityConstraint,
    /// The impulse (N s) the triangle gave the collider over the last step.
    pub(crate) impulse: DVec3,
    /// Within an implicit step: the normal force (N) friction is limited by, and the triangle
    /// point's position (m) at the start of the step.
    lagged_normal_force: f64,
    slip_origin: DVec3,
    /// Which of the collider's points it is, so that the next detection finds the stiffening
    /// of its implicit penalty that its load called for (see [`super::stiffening`]).
    pub(super) feature: CornerFeature,
    pub(super) stiffening: Stiffening,
}

/// Which point of a collider a corner contact is: a vertex by its place among the shape's
/// vertices (part after part in a compound), or a rounded part's closest point to a triangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum CornerFeature {
    Vertex(u32),
    Rounded([u32; 3]),
}

/// Where a step leaves a corner: its vertex and its contact plane's point (m) and unit normal.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CornerPlace {
    vertex: DVec3,
    point: DVec3,
    normal: DVec3,
}

impl CornerContact {
    /// Where the corner is now, for [`CornerContact::set_place`] to put it back.
    pub(crate) fn place(&self) -> CornerPlace {
        CornerPlace {
            vertex: self.vertex,
            point: self.point,
            normal: self.normal,
        }
    }

    /// Puts the corner back where [`CornerContact::place`] found it.
    pub(crate) fn set_place(&mut self, place: CornerPlace) {
        self.vertex = place.vertex;
        self.point = place.point;
        self.normal = place.normal;
    }

    /// The collider and which of its points: what a contact's stiffening is kept by from one
    /// detection to the next.
    pub(super) fn key(&self) -> (ColliderHandle, CornerFeature) {
        (self.collider, self.feature)
    }

    /// How deep (m) the vertex lies behind its contact plane where the detection left them.
    pub(crate) fn depth_found(&self) -> f64 {
        (self.point - self.vertex).dot(self.normal)
    }

    /// Where (m) and with what mean force (N) the soft body pushed the collider over the last
    /// step, of length `dt` (s).
    pub(crate) fn force_on_collider(&self, dt: f64) -> (DVec3, DVec3) {
        (self.vertex, self.impulse / dt)
    }
}

/// Whether `shape` meets the soft faces as [`find_corner_contacts`] finds: by its vertices or
/// its closest points, alone or within a compound (every shape but a half-space and a height
/// field).
pub(crate) fn meets_faces(shape: &dyn Shape) -> bool {
    has_vertices(shape) || shape.as_support_map().is_some() || shape.as_compound().is_some()
}

/// Whether `shape` has vertices [`for_each_vertex`] visits.
fn has_vertices(shape: &dyn Shape) -> bool {
    shape.as_cuboid().is_some()
        || shape.as_convex_polyhedron().is_some()
        || shape.as_trimesh().is_some()
}

/// Calls `each(part, pose)` for `shape` at `pose`, or for each shape within it at its pose if
/// it is a compound.
fn for_each_part(shape: &dyn Shape, pose: &Pose, each: &mut impl FnMut(&dyn Shape, &Pose)) {
    if let Some(compound) = shape.as_compound() {
        for (local_pose, part) in compound.shapes() {
            for_each_part(&**part, &(*pose * *local_pose), each);
        }
    } else {
        each(shape, pose);
    }
}

/// Calls `each(vertex, outward)` for the world-space vertices (m) of `shape` at `pose`, a shape
/// with corners (cuboid, convex polyhedron, triangle mesh), with the direction from the shape's
/// centre to the vertex.
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
    }
}

/// The contacts of `near`'s shape within its reach (m) of `body`'s boundary triangles in
/// `tree`: its vertices' if it has corners, its closest points' if it is rounded (see
/// [`super::support`]), part by part in a compound; skipping triangles with a node glued to the
/// collider's rigid body; their proxy is left for the caller to set.
pub(super) fn find_corner_contacts(
    body: &DeformableBody,
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
    let skipped = |triangle: &[u32; 3]| triangle.iter().any(|n| glued.contains(n));
    let mut found = Vec::new();
    let mut vertices = 0;
    let contact = |vertex: DVec3, hit: TrianglePoint, (follows_face, feature)| CornerContact {
        collider,
        proxy: None,
        vertex,
        on_triangle: hit.soft_point(),
        point: hit.point,
        normal: hit.normal,
        follows_face,
        coefficients,
        constraint: VelocityConstraint::default(),
        impulse: DVec3::ZERO,
        lagged_normal_force: 0.0,
        slip_origin: DVec3::ZERO,
        feature,
        stiffening: Stiffening::default(),
    };
    for_each_part(shape.as_ref(), pose, &mut |part, part_pose| {
        if has_vertices(part) {
            for_each_vertex(part, part_pose, &mut |vertex, outward| {
                let feature = CornerFeature::Vertex(vertices);
                vertices += 1;
                if !bounds.contains_local_point(vertex.as_vec3()) {
                    return;
                }
                if let Some(hit) = tree.nearest_facing(body, vertex, outward, reach, skipped)
                    && !beside_the_body(body, vertex, &hit)
                {
                    found.push(contact(vertex, hit, (true, feature)));
                }
            });
        } else if part.as_support_map().is_some() {
            support::for_each_support_contact(
                (body, tree),
                (part, part_pose),
                reach,
                skipped,
                &mut |c| {
                    let feature = CornerFeature::Rounded(c.on_triangle.triangle);
                    found.push(contact(c.vertex, c.on_triangle, (c.follows_face, feature)));
                },
            );
        }
    });
    found
}

/// Whether `vertex` (m) lies behind the plane of its nearest facing triangle `hit` of `body` but
/// farther aside from the triangle than behind it, by more than the triangle's longest edge:
/// beside the body, in the plane's extension, not in the body (which would put the triangle's
/// nearest point about straight above it; a dimple under a pressing corner tilts the triangles
/// around it by less than their size). A contact there would push on the body from afar: the 8
/// corners of a 1 m thin wall, found within a 100 m/s cube's reach over a 1/240 s frame, stood
/// 0.1 m behind the plane of the cube's far face and 0.64 m aside, and their penalties held
/// 4 kJ before the cube moved.
fn beside_the_body(body: &DeformableBody, vertex: DVec3, hit: &TrianglePoint) -> bool {
    let offset = vertex - hit.point;
    let behind = -offset.dot(hit.normal);
    let [a, b, c] = hit.triangle.map(|n| body.positions[n as usize]);
    let size = a.distance(b).max(b.distance(c)).max(c.distance(a));
    behind > 0.0 && (offset + behind * hit.normal).length() > behind + size
}

/// Readies the corner contacts for an explicit substep of `h` (s): each plane moves to its
/// triangle's contact point where the nodes are now.
pub(crate) fn prepare_corners(
    body: &DeformableBody,
    contacts: &mut ContactSet,
    proxies: &[RigidProxy],
    h: f64,
) {
    let depenetration = contacts.depenetration();
    for contact in &mut contacts.corners {
        if let Some((point, normal)) = contact.on_triangle.plane(&body.positions) {
            contact.point = point;
            if contact.follows_face {
                contact.normal = normal;
            }
        }
        let gap = (contact.vertex - contact.point).dot(contact.normal);
        let normal_speed = || {
            let vertex_velocity = contact
                .proxy
                .map_or(DVec3::ZERO, |p| proxies[p].velocity_at(contact.vertex));
            (vertex_velocity - contact.on_triangle.velocity(&body.velocities)).dot(contact.normal)
        };
        contact.constraint = VelocityConstraint::new(gap, h, depenetration).bounce(
            gap,
            h,
            normal_speed,
            contact.coefficients.restitution,
        );
    }
}

/// Moves the corners with their rigid bodies' velocities for `h` (s), as the body's nodes move
/// at the end of an explicit substep: the gaps then follow both sides.
pub(crate) fn advance_corners(contacts: &mut ContactSet, proxies: &[RigidProxy], h: f64) {
    for contact in &mut contacts.corners {
        if let Some(p) = contact.proxy {
            contact.vertex += proxies[p].velocity_at(contact.vertex) * h;
        }
    }
}

/// One sweep over the corner contacts (see [`VelocityConstraint`]).
pub(crate) fn solve_corners(
    body: &mut DeformableBody,
    contacts: &mut ContactSet,
    proxies: &mut [RigidProxy],
) {
    let DeformableBody {
        velocities,
        masses,
        pinned,
        ..
    } = body;
    for contact in &mut contacts.corners {
        let mut sides = Corner {
            rigid: contact.proxy.map(|p| &mut proxies[p]),
            at: contact.point,
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
    /// Where the rigid body's side acts (m): the triangle's contact point, where the soft side's
    /// opposite impulse acts too, so that the exchange keeps angular momentum exactly (the
    /// vertex lies off it by the gap, and a friction impulse's moment would differ by it).
    at: DVec3,
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
            .map_or(DVec3::ZERO, |r| r.velocity_at(self.at));
        vertex - self.on_triangle.velocity(self.velocities)
    }

    fn inverse_mass_along(&self, direction: DVec3) -> f64 {
        self.rigid
            .as_ref()
            .map_or(0.0, |r| r.inverse_mass_along(self.at, direction))
            + self.on_triangle.inverse_mass(self.masses, self.pinned)
    }

    fn exchange(&mut self, impulse: DVec3) {
        if let Some(rigid) = self.rigid.as_mut() {
            rigid.apply(impulse, self.at);
        }
        self.on_triangle
            .apply(-impulse, self.velocities, self.masses, self.pinned);
    }
}

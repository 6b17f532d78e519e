//! Rigid corners against soft faces: the vertices of a collider's polyhedral shape (cuboid,
//! convex polyhedron, triangle mesh), and the closest points of a rounded one (ball, capsule,
//! cylinder, cone, see [`super::support`]), alone or within compounds, against the soft body's
//! boundary triangles, so that a corner, a small box or a small ball pressing between the nodes
//! of a coarse mesh is held by the face rather than sinking in until its faces meet nodes.
//!
//! A vertex within reach of a boundary triangle facing it (see [`SurfaceTree`]) gets a contact
//! plane through the triangle's nearest point, with the triangle's outward normal. A vertex
//! behind that plane but outside the body (above a block's top and behind the plane of its side
//! face, [`SurfaceTree::outside_point`]) by more than a quarter of the triangle's longest edge
//! instead gets the plane through the body's nearest point normal to the line from it to the
//! vertex: the side face's plane would put it deep in the body and push it out sideways (a 27 g
//! box resting across a block's edge, its top vertices found 17 to 36 mm deep while a fast box
//! passed, was pushed off the block). Nearer, the facing plane stands for the rigid face through
//! the vertex resting across the body's edge, which no node meets (a box overhanging a block by
//! a millimetre or two is held level by its corners past the edges as by its face on them), an
//! error of the vertex's distance from the body, within the mesh's resolution. The explicit
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

/// The share of its facing triangle's longest edge beyond which a vertex outside the body, behind
/// the triangle's plane, takes its contact with the body's nearest point (see [`overhanging`]).
const OVERHANG_SHARE: f64 = 0.25;

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
/// `tree`: its vertices' if it has corners (against the nearest facing triangle, or the body's
/// nearest point for a vertex overhanging the body, see [`overhanging`]), its closest points'
/// if it is rounded (see [`super::support`]), part by part in a compound; skipping triangles
/// with a node glued to the collider's rigid body; their proxy is left for the caller to set.
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
                let Some(hit) = tree.nearest_facing(body, vertex, outward, reach, skipped) else {
                    return;
                };
                match overhanging(body, tree, (vertex, &hit), reach) {
                    Some(outside) if !skipped(&outside.triangle) => {
                        found.push(contact(vertex, outside, (false, feature)));
                    }
                    Some(_) => {}
                    None => found.push(contact(vertex, hit, (true, feature))),
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

/// The body's nearest point to `vertex` (m), if the vertex lies behind the plane of its nearest
/// facing triangle `hit` but outside the body (see [`SurfaceTree::outside_point`], within
/// `reach`, m) by more than [`OVERHANG_SHARE`] of that triangle's longest edge: the point to
/// take its contact with instead of the triangle's plane.
fn overhanging(
    body: &DeformableBody,
    tree: &SurfaceTree,
    (vertex, hit): (DVec3, &TrianglePoint),
    reach: f64,
) -> Option<TrianglePoint> {
    if (vertex - hit.point).dot(hit.normal) >= 0.0 {
        return None;
    }
    let [a, b, c] = hit.triangle.map(|n| body.positions[n as usize]);
    let size = a.distance(b).max(b.distance(c)).max(c.distance(a));
    (tree.outside_point(body, vertex, reach))
        .filter(|outside| outside.point.distance(vertex) > OVERHANG_SHARE * size)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::detect::{ColliderView, detect};
    use crate::contact::{ContactSettings, KeptTree, SurfaceCoefficients};
    use crate::prelude::{DeformableBodyBuilder, Material, MaterialModel, mesh};
    use rapier3d::geometry::{InteractionGroups, SharedShape};

    #[test]
    fn a_box_resting_across_a_blocks_corner_is_found_only_as_deep_as_it_sank() {
        // A 3 cm box resting on the top of a 10 cm block of 3³ cells (top triangles' longest
        // edge 4.7 cm), its centre 8 mm in from the top's corner (x, z = 0.05): 7 mm over each
        // side, its bottom 0.5 mm into the top. Detected within the 5 cm a fast striker widens
        // the reach to, its top vertices (3 cm above the top, behind the side faces' planes)
        // lie outside the block by more than a quarter of that edge and get contacts with the
        // top below them, at 3 cm; its overhanging bottom vertices, 7 mm out, keep the top's
        // plane, 0.5 mm deep, as its face resting on the edges would be. No contact may be
        // deeper than the box sank: the side faces' planes put the top vertices 23 mm deep and
        // pushed the box sideways off the block.
        let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
        let block =
            DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [3; 3]).unwrap(), material)
                .build()
                .unwrap();
        let sunk = 5e-4;
        let centre = DVec3::new(0.042, 0.05 + 0.015 - sunk, 0.042);
        let shape = SharedShape::cuboid(0.015, 0.015, 0.015);
        let pose = Pose::from_translation(centre.as_vec3());
        let view = ColliderView {
            handle: ColliderHandle::from_raw_parts(0, 0),
            shape,
            pose,
            bounds: (centre - 0.015, centre + 0.015),
            groups: InteractionGroups::all(),
            coefficients: SurfaceCoefficients::of_body(&block),
            parent: None,
            travel: 0.05,
        };
        let previous = ContactSet::default();
        let found = detect(
            (&block, &mut KeptTree::default()),
            (&[], (&previous, &[])),
            (&[view], 0.0),
            1.0 / 240.0,
            DVec3::new(0.0, -9.81, 0.0),
            &ContactSettings::default(),
        )
        .unwrap();
        let depths: Vec<f64> = found
            .corners
            .iter()
            .map(CornerContact::depth_found)
            .collect();
        let deepest = depths.iter().copied().fold(f64::MIN, f64::max);
        assert!((deepest - sunk).abs() < 1e-6, "{depths:?}");
        // The four bottom vertices held by the top's plane (one over the top, three past its
        // edges), 0.5 mm deep to f32 rounding.
        let held = depths.iter().filter(|d| (**d - sunk).abs() < 1e-6).count();
        assert_eq!(held, 4, "{depths:?}");
    }
}

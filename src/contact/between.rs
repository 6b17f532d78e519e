//! Contact between soft bodies: the surface nodes of one against the boundary triangles of
//! another, for bodies stepped together.
//!
//! Detection finds, for every pair of bodies whose collision groups interact and whose
//! surfaces come within reach, each surface node's nearest facing triangle of the other body
//! (see [`SurfaceTree`]), both ways. The bodies a contact links are then stepped together by the
//! explicit integrator, whose sweeps solve these contacts with both bodies' nodes: the node takes
//! the impulse, the triangle's corners its opposite by the contact point's barycentric weights,
//! so momentum is exchanged exactly, and the plane follows the triangle through the step.

use super::surface_tree::SurfaceTree;
use super::{
    BodyPoint, Coefficients, ContactSettings, ContactSides, ContactTarget, Depenetration,
    NodeContact, Obstacle, SoftPoint, SurfaceCoefficients, VelocityConstraint,
};
use crate::body::DeformableBody;
use crate::stencil::node_inverse_mass;
use rapier3d::glamx::DVec3;

/// A surface node of one soft body touching a boundary triangle of another.
#[derive(Debug, Clone)]
pub(crate) struct BetweenContact {
    /// The node's body (an index into the bodies stepped together) and the node.
    pub(crate) node_body: usize,
    pub(crate) node: u32,
    /// The triangle's body and the contact point on the triangle.
    pub(crate) triangle_body: usize,
    on_triangle: SoftPoint,
    /// The contact plane: a point (m) and the triangle's outward unit normal.
    point: DVec3,
    normal: DVec3,
    /// The two bodies' coefficients, combined.
    coefficients: Coefficients,
    /// How it is pushed out when found inside: at most at the detection's
    /// [`ContactSettings::depenetration_speed`], over its step.
    depenetration: Depenetration,
    constraint: VelocityConstraint,
}

/// The contacts between the soft `bodies` for a step of `dt` (s) under `gravity` (m/s²): the
/// surface nodes of each body within reach (`settings.margin` plus twice the distance the two
/// bodies' fastest nodes can travel in the step) of a facing boundary triangle of another whose
/// collision groups interact with its own. Indices in the contacts are positions in `bodies`.
pub(crate) fn detect_between(
    bodies: &[&DeformableBody],
    settings: &ContactSettings,
    dt: f64,
    gravity: DVec3,
) -> Vec<BetweenContact> {
    let mut contacts = Vec::new();
    if bodies.len() < 2 {
        return contacts;
    }
    // The trees are built only for bodies another one comes near.
    let mut trees: Vec<Option<SurfaceTree>> = bodies.iter().map(|_| None).collect();
    let bounds: Vec<(DVec3, DVec3)> = bodies.iter().map(|body| body.position_bounds()).collect();
    let fastest: Vec<f64> = bodies
        .iter()
        .map(|body| body.fastest_node_speed())
        .collect();
    for (a, body) in bodies.iter().enumerate() {
        let mut normals = None;
        for (b, other) in bodies.iter().enumerate() {
            let reach =
                settings.margin + 2.0 * (fastest[a] + fastest[b] + gravity.length() * dt) * dt;
            let ((lo_a, hi_a), (lo_b, hi_b)) = (bounds[a], bounds[b]);
            if a == b
                || !body.collision_groups.test(other.collision_groups)
                || (hi_a + DVec3::splat(reach)).cmplt(lo_b).any()
                || (lo_a - DVec3::splat(reach)).cmpgt(hi_b).any()
            {
                continue;
            }
            let tree = trees[b].get_or_insert_with(|| SurfaceTree::of(other));
            let normals = normals.get_or_insert_with(|| body.surface_node_normals());
            let coefficients =
                SurfaceCoefficients::of_body(body).combine(SurfaceCoefficients::of_body(other));
            for &node in &body.surface.nodes {
                let n = node as usize;
                if body.pinned[n] {
                    continue;
                }
                if let Some(hit) =
                    tree.nearest_facing(other, body.positions[n], normals[n], reach, |_| false)
                {
                    contacts.push(BetweenContact {
                        node_body: a,
                        node,
                        triangle_body: b,
                        on_triangle: hit.soft_point(),
                        point: hit.point,
                        normal: hit.normal,
                        coefficients,
                        depenetration: Depenetration {
                            speed: settings.depenetration_speed,
                            time: dt,
                        },
                        constraint: VelocityConstraint::default(),
                    });
                }
            }
        }
    }
    contacts
}

impl BetweenContact {
    /// The contact in the numbering of a group whose body `k` has its first node at
    /// `offsets[k]`: the node against the other body's triangle point, as a self-contact of the
    /// group (see [`super::joint`]).
    pub(super) fn in_group(&self, offsets: &[u32]) -> NodeContact {
        let triangle_offset = offsets[self.triangle_body];
        let triangle = self.on_triangle.nodes.map(|n| n + triangle_offset);
        NodeContact::new(
            BodyPoint::Node(self.node + offsets[self.node_body]),
            ContactTarget::OwnSurface { triangle },
            self.point,
            self.normal,
            self.coefficients,
            Obstacle::OwnTriangle(SoftPoint {
                nodes: triangle,
                weights: self.on_triangle.weights,
            }),
        )
    }
}

/// The two bodies `i` and `j` (distinct) of `bodies`, both mutable.
fn two_bodies<'a>(
    bodies: &'a mut [&mut DeformableBody],
    i: usize,
    j: usize,
) -> (&'a mut DeformableBody, &'a mut DeformableBody) {
    if i < j {
        let (low, high) = bodies.split_at_mut(j);
        (&mut *low[i], &mut *high[0])
    } else {
        let (low, high) = bodies.split_at_mut(i);
        (&mut *high[0], &mut *low[j])
    }
}

/// Readies the contacts for an explicit substep of `h` (s): each plane moves to its triangle's
/// contact point where the corners are now, and the velocity constraint is set from the node's
/// distance to it.
pub(crate) fn prepare_between(
    contacts: &mut [BetweenContact],
    bodies: &[&mut DeformableBody],
    h: f64,
) {
    for contact in contacts {
        let triangle_body = &bodies[contact.triangle_body];
        if let Some((point, normal)) = contact.on_triangle.plane(&triangle_body.positions) {
            contact.point = point;
            contact.normal = normal;
        }
        let node_body = &bodies[contact.node_body];
        let n = contact.node as usize;
        let gap = (node_body.positions[n] - contact.point).dot(contact.normal);
        let normal_speed = || {
            (node_body.velocities[n] - contact.on_triangle.velocity(&triangle_body.velocities))
                .dot(contact.normal)
        };
        contact.constraint = VelocityConstraint::new(gap, h, contact.depenetration).bounce(
            gap,
            h,
            normal_speed,
            contact.coefficients.restitution,
        );
    }
}

/// One sweep over the contacts between `bodies` (see [`VelocityConstraint`]).
pub(crate) fn solve_between(contacts: &mut [BetweenContact], bodies: &mut [&mut DeformableBody]) {
    for contact in contacts {
        let (node_body, triangle_body) =
            two_bodies(bodies, contact.node_body, contact.triangle_body);
        let mut sides = Between {
            node_body,
            node: contact.node as usize,
            triangle_body,
            on_triangle: contact.on_triangle,
        };
        contact
            .constraint
            .correct(contact.normal, contact.coefficients.friction, &mut sides);
    }
}

/// A node of one body and a triangle of another, within a sweep.
struct Between<'a> {
    node_body: &'a mut DeformableBody,
    node: usize,
    triangle_body: &'a mut DeformableBody,
    on_triangle: SoftPoint,
}

impl ContactSides for Between<'_> {
    fn relative_velocity(&self) -> DVec3 {
        self.node_body.velocities[self.node]
            - self.on_triangle.velocity(&self.triangle_body.velocities)
    }

    fn inverse_mass_along(&self, _direction: DVec3) -> f64 {
        let (node, triangle) = (&self.node_body, &self.triangle_body);
        node_inverse_mass(node.masses[self.node], node.pinned[self.node])
            + self
                .on_triangle
                .inverse_mass(&triangle.masses, &triangle.pinned)
    }

    fn exchange(&mut self, impulse: DVec3) {
        let node = &mut self.node_body;
        node.velocities[self.node] +=
            impulse * node_inverse_mass(node.masses[self.node], node.pinned[self.node]);
        let triangle = &mut self.triangle_body;
        self.on_triangle.apply(
            -impulse,
            &mut triangle.velocities,
            &triangle.masses,
            &triangle.pinned,
        );
    }
}

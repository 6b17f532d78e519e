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
use super::{Coefficients, ContactSettings, ContactSides, SurfaceCoefficients, VelocityConstraint};
use crate::body::SoftBody;
use rapier3d::glamx::DVec3;
use rapier3d::parry::bounding_volume::BoundingVolume;

/// A surface node of one soft body touching a boundary triangle of another.
#[derive(Debug, Clone)]
pub(crate) struct BetweenContact {
    /// The node's body (an index into the bodies stepped together) and the node.
    pub(crate) node_body: usize,
    pub(crate) node: u32,
    /// The triangle's body and nodes, and the contact point's barycentric weights.
    pub(crate) triangle_body: usize,
    triangle: [u32; 3],
    weights: [f64; 3],
    /// The contact plane: a point (m) and the triangle's outward unit normal.
    point: DVec3,
    normal: DVec3,
    /// The two bodies' coefficients, combined.
    coefficients: Coefficients,
    constraint: VelocityConstraint,
}

/// The contacts between the soft `bodies` for a step of `dt` (s) under `gravity` (m/s²): the
/// surface nodes of each body within reach (`settings.margin` plus twice the distance the two
/// bodies' fastest nodes can travel in the step) of a facing boundary triangle of another whose
/// collision groups interact with its own. Indices in the contacts are positions in `bodies`.
pub(crate) fn detect_between(
    bodies: &[&SoftBody],
    settings: &ContactSettings,
    dt: f64,
    gravity: DVec3,
) -> Vec<BetweenContact> {
    let mut contacts = Vec::new();
    if bodies.len() < 2 {
        return contacts;
    }
    let trees: Vec<SurfaceTree> = bodies.iter().map(|body| SurfaceTree::of(body)).collect();
    let fastest: Vec<f64> = bodies
        .iter()
        .map(|body| body.fastest_node_speed())
        .collect();
    for (a, body) in bodies.iter().enumerate() {
        let mut normals = None;
        for (b, other) in bodies.iter().enumerate() {
            let reach =
                settings.margin + 2.0 * (fastest[a] + fastest[b] + gravity.length() * dt) * dt;
            if a == b
                || !body.collision_groups.test(other.collision_groups)
                || !trees[a]
                    .bounds
                    .loosened(reach as f32)
                    .intersects(&trees[b].bounds)
            {
                continue;
            }
            let normals = normals.get_or_insert_with(|| body.surface_node_normals());
            let coefficients =
                SurfaceCoefficients::of_body(body).combine(SurfaceCoefficients::of_body(other));
            for &node in &body.surface_nodes {
                let n = node as usize;
                if body.pinned[n] {
                    continue;
                }
                if let Some(hit) =
                    trees[b].nearest_facing(other, body.positions[n], normals[n], reach, |_| false)
                {
                    contacts.push(BetweenContact {
                        node_body: a,
                        node,
                        triangle_body: b,
                        triangle: hit.triangle,
                        weights: hit.weights,
                        point: hit.point,
                        normal: hit.normal,
                        coefficients,
                        constraint: VelocityConstraint::default(),
                    });
                }
            }
        }
    }
    contacts
}

/// The two bodies `i` and `j` (distinct) of `bodies`, both mutable.
fn two_bodies<'a>(
    bodies: &'a mut [&mut SoftBody],
    i: usize,
    j: usize,
) -> (&'a mut SoftBody, &'a mut SoftBody) {
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
pub(crate) fn prepare_between(contacts: &mut [BetweenContact], bodies: &[&mut SoftBody], h: f64) {
    for contact in contacts {
        let triangle_body = &bodies[contact.triangle_body];
        let at = contact
            .triangle
            .map(|c| triangle_body.positions[c as usize]);
        let normal = (at[1] - at[0]).cross(at[2] - at[0]).normalize_or_zero();
        if normal != DVec3::ZERO {
            contact.point = at[0] * contact.weights[0]
                + at[1] * contact.weights[1]
                + at[2] * contact.weights[2];
            contact.normal = normal;
        }
        let node_body = &bodies[contact.node_body];
        let n = contact.node as usize;
        let gap = (node_body.positions[n] - contact.point).dot(contact.normal);
        let face_velocity: DVec3 = contact
            .triangle
            .iter()
            .zip(contact.weights)
            .map(|(&c, w)| triangle_body.velocities[c as usize] * w)
            .sum();
        let normal_speed = (node_body.velocities[n] - face_velocity).dot(contact.normal);
        contact.constraint = VelocityConstraint::new(
            gap,
            h,
            node_body.contact_settings.depenetration_speed,
        )
        .bounce(gap, h, normal_speed, contact.coefficients.restitution);
    }
}

/// One sweep over the contacts between `bodies` (see [`VelocityConstraint`]).
pub(crate) fn solve_between(contacts: &mut [BetweenContact], bodies: &mut [&mut SoftBody]) {
    for contact in contacts {
        let (node_body, triangle_body) =
            two_bodies(bodies, contact.node_body, contact.triangle_body);
        let mut sides = Between {
            node_body,
            node: contact.node as usize,
            triangle_body,
            triangle: contact.triangle,
            weights: contact.weights,
        };
        contact
            .constraint
            .correct(contact.normal, contact.coefficients.friction, &mut sides);
    }
}

/// A node of one body and a triangle of another, within a sweep.
struct Between<'a> {
    node_body: &'a mut SoftBody,
    node: usize,
    triangle_body: &'a mut SoftBody,
    triangle: [u32; 3],
    weights: [f64; 3],
}

/// The inverse mass (1/kg) of `body`'s node `n`: zero when pinned.
fn inverse_mass(body: &SoftBody, n: usize) -> f64 {
    if body.pinned[n] {
        0.0
    } else {
        1.0 / body.masses[n]
    }
}

impl ContactSides for Between<'_> {
    fn relative_velocity(&self) -> DVec3 {
        let triangle: DVec3 = self
            .triangle
            .iter()
            .zip(self.weights)
            .map(|(&c, w)| self.triangle_body.velocities[c as usize] * w)
            .sum();
        self.node_body.velocities[self.node] - triangle
    }

    fn inverse_mass_along(&self, _direction: DVec3) -> f64 {
        inverse_mass(self.node_body, self.node)
            + self
                .triangle
                .iter()
                .zip(self.weights)
                .map(|(&c, w)| w * w * inverse_mass(self.triangle_body, c as usize))
                .sum::<f64>()
    }

    fn exchange(&mut self, impulse: DVec3) {
        let own = inverse_mass(self.node_body, self.node);
        self.node_body.velocities[self.node] += impulse * own;
        for (&c, w) in self.triangle.iter().zip(self.weights) {
            let c = c as usize;
            let corner = inverse_mass(self.triangle_body, c);
            self.triangle_body.velocities[c] -= impulse * (w * corner);
        }
    }
}

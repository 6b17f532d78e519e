//! Nodes of 2D bodies glued to rapier2d rigid bodies (feature `dim2`): each glued node is held
//! to a point fixed in its rigid body by a damped spring of the body's contact stiffness `k`
//! ([`super::coupling`]), `f = k (a − x) + c (v_a − v)` with `a` the anchor's position and
//! `v_a` its velocity, `c = 2 √(k m)` the node's critical damping; the rigid body takes `−f` at
//! the anchor. The spring holds a load `W` on `n` glued nodes stretched by `W / (n k)`.

use super::body::PlanarBody;
use crate::Error;
use rapier2d::dynamics::RigidBodyHandle;
use rapier2d::glamx::DVec2;
use rapier2d::pipeline::PhysicsWorld;

/// A node glued to a point fixed in a rigid body.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct GluedNode {
    /// The body (index into the coupling's bodies) and its node.
    pub(super) body: usize,
    pub(super) node: usize,
    pub(super) rigid: RigidBodyHandle,
    /// The anchor in the rigid body's frame (m).
    anchor: DVec2,
}

impl GluedNode {
    /// Glues `nodes` of `body` (index `index`) where they are to `rigid` of `world`.
    ///
    /// # Errors
    /// [`Error::UnknownRigidBody`], [`Error::NodeOutOfRange`].
    pub(super) fn new_all(
        world: &PhysicsWorld,
        (index, body): (usize, &PlanarBody),
        nodes: &[usize],
        rigid: RigidBodyHandle,
    ) -> Result<Vec<Self>, Error> {
        let pose = *world
            .bodies
            .get(rigid)
            .ok_or(Error::UnknownRigidBody)?
            .position();
        let node_count = body.positions().len();
        (nodes.iter())
            .map(|&node| {
                let x = body
                    .positions()
                    .get(node)
                    .ok_or(Error::NodeOutOfRange { node, node_count })?;
                let anchor = pose.inverse_transform_point(x.as_vec2()).as_dvec2();
                Ok(Self {
                    body: index,
                    node,
                    rigid,
                    anchor,
                })
            })
            .collect()
    }
}

/// A glued node as a soft step sees its anchor: where it is (m), how it moves (m/s), the rigid
/// body's centre of mass (m), and whether that body is dynamic and its mass (kg).
#[derive(Debug, Clone, Copy)]
pub(super) struct GlueView {
    pub(super) body: usize,
    pub(super) node: usize,
    pub(super) rigid: RigidBodyHandle,
    anchor: DVec2,
    velocity: DVec2,
    pub(super) centre: DVec2,
    pub(super) dynamic: bool,
    pub(super) mass: f64,
}

impl GlueView {
    /// The glued nodes `glued` as `world` holds their rigid bodies now (those whose rigid body
    /// is gone are left out).
    pub(super) fn all(glued: &[GluedNode], world: &PhysicsWorld) -> Vec<Self> {
        (glued.iter())
            .filter_map(|g| {
                let rigid = world.bodies.get(g.rigid)?;
                let anchor = rigid
                    .position()
                    .transform_point(g.anchor.as_vec2())
                    .as_dvec2();
                let centre = rigid.center_of_mass().as_dvec2();
                let velocity = rigid.linvel().as_dvec2()
                    + (anchor - centre).perp() * f64::from(rigid.angvel());
                Some(Self {
                    body: g.body,
                    node: g.node,
                    rigid: g.rigid,
                    anchor,
                    velocity,
                    centre,
                    dynamic: rigid.is_dynamic(),
                    mass: if rigid.is_dynamic() {
                        f64::from(rigid.mass())
                    } else {
                        f64::INFINITY
                    },
                })
            })
            .collect()
    }

    /// Where the anchor will be (m) after `h` (s), moving as it moves now.
    pub(super) fn anchor_after(&self, h: f64) -> DVec2 {
        self.anchor + self.velocity * h
    }

    /// The force (N) on the node of `body` with stiffness `k` (N/m), and the point where the
    /// rigid body takes its opposite.
    pub(super) fn force(&self, body: &PlanarBody, k: f64) -> (DVec2, DVec2) {
        let (x, v) = (body.positions()[self.node], body.velocities()[self.node]);
        let damping = 2.0 * (k * body.masses()[self.node]).sqrt();
        (
            (self.anchor - x) * k + (self.velocity - v) * damping,
            self.anchor,
        )
    }
}

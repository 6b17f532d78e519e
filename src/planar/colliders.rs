//! The colliders of a rapier2d world as a 2D body's step sees them (feature `dim2`): shape,
//! pose, bounding box, corners and the motion of the rigid body carrying each, frozen at the
//! step's start; how deep a point lies inside one and along which outward normal (in f64 for
//! rectangles, disks and half-spaces, through parry's f32 projection for other shapes).

use super::corners::corners_of;
use rapier2d::dynamics::RigidBodyHandle;
use rapier2d::geometry::{ColliderHandle, SharedShape};
use rapier2d::glamx::DVec2;
use rapier2d::math::Pose;
use rapier2d::pipeline::PhysicsWorld;

/// A collider as a soft step sees it.
pub(super) struct ColliderView {
    pub(super) handle: ColliderHandle,
    pub(super) shape: SharedShape,
    pub(super) pose: Pose,
    /// Its rigid body: handle, centre of mass (m), velocity (m/s) and angular velocity (rad/s).
    pub(super) parent: Option<(RigidBodyHandle, DVec2, DVec2, f64)>,
    /// Whether that body is dynamic.
    pub(super) dynamic: bool,
    /// Its rigid body's mass (kg), infinite if not dynamic.
    pub(super) mass: f64,
    /// Its bounding box (m): nodes outside it are not tested.
    pub(super) bounds: (DVec2, DVec2),
    /// Its vertices (m) if it is polygonal ([`super::corners`]).
    pub(super) corners: Vec<DVec2>,
    /// Its shape in f64 where it is one of the simple ones, with its pose: centre (m) and the
    /// cosine and sine of its angle.
    exact: Option<(ExactShape, DVec2, (f64, f64))>,
}

/// A rectangle (half extents, m), a disk (radius, m) or a half-space (outward normal) whose
/// penetration is computed in f64 rather than through parry's f32 projection, whose rounding
/// (60 nm at a metre) would make the contact forces of an implicit step noisy at the scale
/// Newton's method resolves.
#[derive(Debug, Clone, Copy)]
enum ExactShape {
    Rectangle(DVec2),
    Disk(f64),
    HalfSpace(DVec2),
}

impl ExactShape {
    /// The simple shape `shape` is, if it is one.
    fn of(shape: &SharedShape) -> Option<Self> {
        if let Some(cuboid) = shape.as_cuboid() {
            Some(Self::Rectangle(cuboid.half_extents.as_dvec2()))
        } else if let Some(ball) = shape.as_ball() {
            Some(Self::Disk(f64::from(ball.radius)))
        } else {
            (shape.as_halfspace()).map(|h| Self::HalfSpace(h.normal.as_dvec2().normalize()))
        }
    }

    /// The depth (m) and outward normal (local axes) of the local point `q` (m) if inside.
    fn penetration(self, q: DVec2) -> Option<(f64, DVec2)> {
        let (depth, normal) = match self {
            Self::Rectangle(half) => {
                let room = half - q.abs();
                if room.x < room.y {
                    (room.x, DVec2::new(q.x.signum(), 0.0))
                } else {
                    (room.y, DVec2::new(0.0, q.y.signum()))
                }
            }
            Self::Disk(radius) => {
                let distance = q.length();
                (radius - distance, q / distance)
            }
            Self::HalfSpace(normal) => (-q.dot(normal), normal),
        };
        (depth > 0.0 && normal.is_finite()).then_some((depth, normal))
    }
}

impl ColliderView {
    /// How deep (m) `x` (m) lies inside the collider and the outward normal there, or `None`
    /// outside it (or outside its bounding box).
    pub(super) fn penetration(&self, x: DVec2) -> Option<(f64, DVec2)> {
        let (low, high) = self.bounds;
        if x.cmplt(low).any() || x.cmpgt(high).any() {
            return None;
        }
        if let Some((shape, centre, (cos, sin))) = self.exact {
            let d = x - centre;
            let q = DVec2::new(cos * d.x + sin * d.y, -sin * d.x + cos * d.y);
            return shape.penetration(q).map(|(depth, n)| {
                (
                    depth,
                    DVec2::new(cos * n.x - sin * n.y, sin * n.x + cos * n.y),
                )
            });
        }
        let projection = self.shape.project_point(&self.pose, x.as_vec2(), false);
        let push = projection.point.as_dvec2() - x;
        let depth = push.length();
        (projection.is_inside && depth > 0.0).then(|| (depth, push / depth))
    }

    /// The velocity (m/s) of the collider's material at `x` (m).
    pub(super) fn velocity_at(&self, x: DVec2) -> DVec2 {
        self.parent
            .map_or(DVec2::ZERO, |(_, com, v, w)| v + (x - com).perp() * w)
    }
}

/// The colliders of `world`, as seen now.
pub(super) fn colliders_of(world: &PhysicsWorld) -> Vec<ColliderView> {
    (world.colliders.iter())
        .filter(|(_, c)| !c.is_sensor())
        .map(|(handle, collider)| {
            let body = collider
                .parent()
                .and_then(|h| world.bodies.get(h).map(|b| (h, b)));
            ColliderView {
                handle,
                bounds: {
                    let aabb = collider.compute_aabb();
                    (aabb.mins.as_dvec2(), aabb.maxs.as_dvec2())
                },
                corners: corners_of(collider.shared_shape(), collider.position()),
                exact: ExactShape::of(collider.shared_shape()).map(|shape| {
                    let pose = collider.position();
                    let angle = f64::from(pose.rotation.angle());
                    (
                        shape,
                        pose.translation.as_dvec2(),
                        (angle.cos(), angle.sin()),
                    )
                }),
                shape: collider.shared_shape().clone(),
                pose: *collider.position(),
                parent: body.map(|(h, b)| {
                    let com = b.center_of_mass().as_dvec2();
                    (h, com, b.linvel().as_dvec2(), f64::from(b.angvel()))
                }),
                dynamic: body.is_some_and(|(_, b)| b.is_dynamic()),
                mass: body.map_or(f64::INFINITY, |(_, b)| {
                    if b.is_dynamic() {
                        f64::from(b.mass())
                    } else {
                        f64::INFINITY
                    }
                }),
            }
        })
        .collect()
}

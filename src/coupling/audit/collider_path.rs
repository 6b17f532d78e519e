//! The path of a contact point in the frame of a collider that moved over the frame, for the
//! audit's crossing check.
//!
//! Over a frame the point moves straight from where it was to where it is (world frame), and
//! the collider from its pose then to its pose now, its origin straight and its rotation at a
//! steady rate (spherical interpolation). In the collider's frame the point describes a curve:
//! a straight chord there cuts across the arc the collider's turning gives it. A 3 cm box
//! turning 2.2 rad about its centre in a frame carries a still point 28 mm from its axis along
//! an arc that never comes nearer than 28 mm (outside the box, whose corners are 21 mm from the
//! axis), whose chord passes 12.7 mm from the centre, through the box; boxes tumbling as they
//! land in the game scene turn 1.4-1.8 rad in a 1/60 s frame. So the path is the polyline
//! through the point's places in the collider's frame now at `n + 1` evenly spaced instants
//! (both ends included), each segment turning the collider by at most [`MAX_TURN`]: a segment's
//! chord lies within `r δ²/8` of its arc (`δ` the segment's turn, `r` the point's distance from
//! the axis), under 0.32 mm at `r = 1 m`. A collider that turns less is followed by the one
//! straight chord, and a ball's turning, which moves no point of its shape, not at all. The
//! turning keeps a point's distance from the collider's origin: a point whose distance from the
//! moving origin stays beyond the shape's reach is passed over without its path
//! ([`ColliderMotion::may_meet`]).

use rapier3d::geometry::Collider;
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;

/// The largest turn (rad) of a collider over one segment of a point's path in its frame.
const MAX_TURN: f32 = 0.05;

/// The most segments a path has (a half turn in [`MAX_TURN`]s is 63).
const MAX_SEGMENTS: usize = 64;

/// A collider's motion over a frame: its poses at the instants the path of a point in its frame
/// is taken at, the first its pose then, the last its pose now.
pub(super) struct ColliderMotion {
    poses: Vec<Pose>,
    /// The first and last of them.
    then: Pose,
    now: Pose,
    /// The radius (m) about the collider's origin of a ball holding its shape.
    reach: f64,
}

impl ColliderMotion {
    /// The motion of `collider` from its pose `then` to its pose now, in as many segments as its
    /// turn needs. A ball's turning moves no point of its shape: its motion is its centre's
    /// alone (the pose `then` taken with the ball's rotation now), whose straight relative path
    /// is exact.
    pub(super) fn new(then: &Pose, collider: &Collider) -> Self {
        let now = collider.position();
        let then = match collider.shape().as_ball() {
            Some(_) => Pose::from_parts(then.translation, now.rotation),
            None => *then,
        };
        let turn = then.rotation.angle_between(now.rotation);
        let segments = ((turn / MAX_TURN).ceil() as usize).clamp(1, MAX_SEGMENTS);
        let poses = (0..=segments)
            .map(|k| match k {
                0 => then,
                k if k == segments => *now,
                k => {
                    let s = k as f32 / segments as f32;
                    let translation = then.translation.lerp(now.translation, s);
                    Pose::from_parts(translation, then.rotation.slerp(now.rotation, s))
                }
            })
            .collect();
        let sphere = collider.shape().compute_local_bounding_sphere();
        let reach = f64::from(sphere.center.length() + sphere.radius);
        Self {
            poses,
            then,
            now: *now,
            reach,
        }
    }

    /// Whether the path in the collider's frame of a point that moved from `from` to `to` (m,
    /// world frame) can come within `tolerance` (m) of the collider's shape. The collider's
    /// turning keeps the point's distance from its origin, so the path is as far from the origin
    /// as the point is from the moving origin, the nearest of which is found in closed form (both
    /// move straight); the segments cut inside their arcs by at most `r δ²/8`.
    pub(super) fn may_meet(&self, (from, to): (DVec3, DVec3), tolerance: f64) -> bool {
        let (then, now) = (self.then, self.now);
        let start = from - then.translation.as_dvec3();
        let change = (to - now.translation.as_dvec3()) - start;
        let along = if change.length_squared() > 0.0 {
            (-start.dot(change) / change.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let nearest = (start + change * along).length();
        let farthest = start.length().max((start + change).length());
        let sagitta = farthest * f64::from(MAX_TURN).powi(2) / 8.0;
        nearest <= self.reach + tolerance + sagitta
    }

    /// Writes into `path` (emptied first) the path (m, in the world as the collider is now) of a
    /// point that moved straight from `from` to `to` (m, world frame): where it was relative to
    /// the collider at each instant, carried with the collider to its pose now; the last is `to`.
    pub(super) fn path_into(&self, (from, to): (DVec3, DVec3), path: &mut Vec<DVec3>) {
        let (now, segments) = (self.now, self.poses.len() - 1);
        path.clear();
        path.extend(self.poses.iter().enumerate().map(|(k, pose)| {
            if k == segments {
                return to;
            }
            let at = from.lerp(to, k as f64 / segments as f64);
            now.transform_point(pose.inverse_transform_point(at.as_vec3()))
                .as_dvec3()
        }));
    }

    /// The farthest (m) the collider's motion from any of its instants to now carries a point of
    /// the box `(lo, hi)` (m): at each instant, its largest at one of the box's corners (the
    /// carrying is affine, its length convex).
    pub(super) fn longest_carry(&self, (lo, hi): (DVec3, DVec3)) -> f64 {
        let now = self.now;
        let corners: [DVec3; 8] = std::array::from_fn(|corner| {
            let pick = |bit: usize, l: f64, h: f64| if corner >> bit & 1 == 0 { l } else { h };
            DVec3::new(
                pick(0, lo.x, hi.x),
                pick(1, lo.y, hi.y),
                pick(2, lo.z, hi.z),
            )
        });
        // From the last instant, now, nothing is carried.
        (self.poses.iter().take(self.poses.len() - 1))
            .flat_map(|pose| {
                corners.iter().map(move |x| {
                    let carried = now.transform_point(pose.inverse_transform_point(x.as_vec3()));
                    (carried.as_dvec3() - *x).length()
                })
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::geometry::ColliderBuilder;
    use rapier3d::glamx::{Quat, Vec3};

    /// A 3 cm box collider at `pose`.
    fn cuboid_at(pose: Pose) -> Collider {
        ColliderBuilder::cuboid(0.015, 0.015, 0.015)
            .position(pose)
            .build()
    }

    #[test]
    fn a_point_is_passed_over_when_it_keeps_away_from_the_collider() {
        // A 3 cm box (its corners 26 mm from its centre) moved 10 cm along x and turned 1 rad.
        let then = Pose::IDENTITY;
        let now = Pose::from_parts(Vec3::new(0.1, 0.0, 0.0), Quat::from_rotation_z(1.0));
        let motion = ColliderMotion::new(&then, &cuboid_at(now));
        // A still point 4 cm above the box's path keeps 40 mm from its centre: out of reach.
        let above = DVec3::new(0.05, 0.04, 0.0);
        assert!(!motion.may_meet((above, above), 0.001));
        // 2 cm above, it comes within 20 mm of the centre, inside the corners' reach.
        let nearer = DVec3::new(0.05, 0.02, 0.0);
        assert!(motion.may_meet((nearer, nearer), 0.001));
        // A point moving with the box's centre, 4 cm off it, stays out of reach.
        let (from, to) = (DVec3::new(0.0, 0.04, 0.0), DVec3::new(0.1, 0.04, 0.0));
        assert!(!motion.may_meet((from, to), 0.001));
    }

    #[test]
    fn a_balls_turning_is_not_followed() {
        // Turned 1.8 rad and moved 5 cm: the still point's start is carried by the move alone.
        let then = Pose::IDENTITY;
        let now = Pose::from_parts(Vec3::new(0.05, 0.0, 0.0), Quat::from_rotation_z(1.8));
        let ball = ColliderBuilder::ball(0.015).position(now).build();
        let motion = ColliderMotion::new(&then, &ball);
        let point = DVec3::new(0.0, 0.028, 0.0);
        let mut path = Vec::new();
        motion.path_into((point, point), &mut path);
        assert_eq!(path.len(), 2);
        assert!(
            (path[0] - DVec3::new(0.05, 0.028, 0.0)).length() < 1e-7,
            "{path:?}"
        );
    }

    #[test]
    fn a_still_point_beside_a_turning_collider_keeps_its_distance_from_the_axis() {
        // A collider at the origin turning 1.8 rad about z over the frame, and a still point
        // 28 mm from the axis: its path in the collider's frame stays on that circle to within
        // the segments' sagitta bound, 0.028 × 0.05² / 8 = 8.75e-6 m (each vertex on the
        // circle up to f32 rounding, about 1e-8 m here).
        let then = Pose::IDENTITY;
        let now = Pose::from_parts(Vec3::ZERO, Quat::from_rotation_z(1.8));
        let motion = ColliderMotion::new(&then, &cuboid_at(now));
        let point = DVec3::new(0.028, 0.0, 0.0);
        let mut path = Vec::new();
        motion.path_into((point, point), &mut path);
        assert_eq!(path.len(), 37, "1.8 rad in segments of at most 0.05 rad");
        for vertex in &path {
            assert!((vertex.length() - 0.028).abs() < 1e-7, "{vertex:?}");
        }
        for pair in path.windows(2) {
            let middle = 0.5 * (pair[0] + pair[1]);
            assert!(0.028 - middle.length() < 8.75e-6 + 1e-7, "{middle:?}");
        }
        // The collider turned the point's start 1.8 rad back about the axis with it.
        let start = path[0];
        let expected = DVec3::new(0.028 * 1.8f64.cos(), 0.028 * 1.8f64.sin(), 0.0);
        assert!((start - expected).length() < 1e-7, "{start:?}");
    }

    #[test]
    fn a_collider_that_does_not_turn_is_followed_by_one_chord() {
        // Moved 5 cm along x without turning: the point's start carried 5 cm along with it.
        let then = Pose::IDENTITY;
        let now = Pose::from_parts(Vec3::new(0.05, 0.0, 0.0), Quat::IDENTITY);
        let motion = ColliderMotion::new(&then, &cuboid_at(now));
        let (from, to) = (DVec3::new(0.0, 0.1, 0.0), DVec3::new(0.0, 0.1, 0.02));
        let mut path = vec![DVec3::ZERO; 5];
        motion.path_into((from, to), &mut path);
        assert_eq!(path.len(), 2);
        assert!((path[0] - DVec3::new(0.05, 0.1, 0.0)).length() < 1e-7);
        assert_eq!(path[1], to);
        // Every point of the box is carried the same 5 cm.
        let carry = motion.longest_carry((DVec3::splat(-1.0), DVec3::splat(1.0)));
        assert!((carry - 0.05).abs() < 1e-7, "{carry}");
    }
}

//! How far things reach over a step: the bounds of a body's nodes widened by what they can travel,
//! the fastest point of a rigid body, and whether two bounds overlap.

use crate::body::DeformableBody;
use crate::rigid::coming_velocity;
use rapier3d::dynamics::RigidBody;
use rapier3d::geometry::ColliderSet;
use rapier3d::glamx::DVec3;

/// An axis-aligned box, minimum and maximum corners (m).
pub(crate) type Bounds = (DVec3, DVec3);

/// `bounds` widened by `by` (m) on every side.
pub(crate) fn widen((low, high): Bounds, by: f64) -> Bounds {
    (low - DVec3::splat(by), high + DVec3::splat(by))
}

/// Whether two boxes overlap.
pub(crate) fn overlap(a: Bounds, b: Bounds) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

/// The fastest a point of `body` moves (m/s) over a step of `dt` (s), bounded by its centre of
/// mass's speed plus its turn rate times the farthest corner of its colliders' bounds.
pub(crate) fn fastest_point(body: &RigidBody, colliders: &ColliderSet, dt: f64) -> f64 {
    let (linvel, angvel) = coming_velocity(body, dt);
    let com = body.mass_properties().world_com.as_dvec3();
    let reach = (body.colliders().iter())
        .filter_map(|&handle| colliders.get(handle))
        .map(|collider| {
            let aabb = collider.compute_aabb();
            let centre = (aabb.mins.as_dvec3() + aabb.maxs.as_dvec3()) / 2.0;
            (centre - com).length() + f64::from(aabb.half_extents().length())
        })
        .fold(0.0, f64::max);
    linvel.length() + turning_speed(angvel.length(), reach)
}

/// The speed (m/s) of a point `radius` (m) from the axis of a turn of `rate` (rad/s): none
/// without a turn, even at an unbounded radius (a half-space's bounds are infinite), where the
/// product would be NaN and, through `f64::min`, reach as far as the largest reach allowed.
pub(crate) fn turning_speed(rate: f64, radius: f64) -> f64 {
    if rate == 0.0 { 0.0 } else { rate * radius }
}

/// The bounds of `body`'s nodes widened by `margin` (m) and by twice what its fastest node can
/// travel over a step of `dt` (s) under `gravity` (m/s²), `2 (|v|max + |g| dt) dt`: the reach of
/// its contact detection.
pub(crate) fn body_reach(body: &DeformableBody, margin: f64, dt: f64, gravity: DVec3) -> Bounds {
    widen(
        body.position_bounds(),
        margin + body_travel(body, dt, gravity),
    )
}

/// Twice what `body`'s fastest node can travel over a step of `dt` (s) under `gravity` (m/s²),
/// `2 (|v|max + |g| dt) dt` (m).
pub(crate) fn body_travel(body: &DeformableBody, dt: f64, gravity: DVec3) -> f64 {
    2.0 * (body.fastest_node_speed() + gravity.length() * dt) * dt
}

/// For each of `bodies`, the largest travel ([`body_travel`], m) of the others whose reach
/// ([`body_reach`] with `margin`, m) overlaps its own over a step of `dt` (s) under `gravity`
/// (m/s²): how far a body striking it can drive its nodes towards the colliders.
pub(crate) fn struck_by(
    bodies: &[&DeformableBody],
    margin: f64,
    dt: f64,
    gravity: DVec3,
) -> Vec<f64> {
    let reaches: Vec<(Bounds, f64)> = (bodies.iter())
        .map(|body| {
            let reach = body_reach(body, margin, dt, gravity);
            (reach, body_travel(body, dt, gravity))
        })
        .collect();
    (reaches.iter().enumerate())
        .map(|(i, (reach, _))| {
            (reaches.iter().enumerate())
                .filter(|(j, (other, _))| *j != i && overlap(*reach, *other))
                .map(|(_, (_, travel))| *travel)
                .fold(0.0, f64::max)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::DeformableBodyBuilder;
    use crate::material::{Material, MaterialModel};
    use crate::mesh;

    /// A 10 cm cube centred at `centre` (m), every node moving at `velocity` (m/s).
    fn cube(centre: DVec3, velocity: DVec3) -> DeformableBody {
        let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
        let mut body = DeformableBodyBuilder::new(
            mesh::cuboid(DVec3::splat(0.05), [2, 2, 2]).unwrap(),
            material,
        )
        .translation(centre)
        .build()
        .unwrap();
        body.velocities_mut().fill(velocity);
        body
    }

    #[test]
    fn a_body_is_struck_by_the_fastest_other_that_can_meet_it() {
        // Over 1/240 s without gravity a cube falling at 3 m/s travels 2 x 3 / 240 = 25 mm
        // (twice over): it can meet the cube 20 mm below it, which moves at 0.1 m/s (0.83 mm);
        // the one 0.5 m away meets neither.
        let dt = 1.0 / 240.0;
        let below = cube(DVec3::ZERO, DVec3::new(0.0, 0.1, 0.0));
        let above = cube(DVec3::new(0.0, 0.12, 0.0), DVec3::new(0.0, -3.0, 0.0));
        let far = cube(DVec3::new(0.5, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0));
        let struck = struck_by(&[&below, &above, &far], 1e-3, dt, DVec3::ZERO);
        assert!((struck[0] - 2.0 * 3.0 * dt).abs() < 1e-15, "{struck:?}");
        assert!((struck[1] - 2.0 * 0.1 * dt).abs() < 1e-15, "{struck:?}");
        assert_eq!(struck[2], 0.0);
    }

    #[test]
    fn a_body_that_does_not_turn_gives_no_turning_speed_even_unbounded() {
        // A half-space's bounds are infinite: 0 x infinity would be NaN.
        assert_eq!(turning_speed(0.0, f64::INFINITY), 0.0);
        assert_eq!(turning_speed(2.0, 0.5), 1.0);
    }
}

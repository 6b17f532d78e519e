//! Whether a deformable body may turn rigid now, and its rigid body and collider if so: its
//! strain (see `shape`) and the strain the force on it predicts at most half its tolerance, its
//! convex hull within [`HULL_EXCESS`] of its volume.

use super::shape::{RigidMotion, peak_green_strain, softest};
use super::{StandIn, strain_predicted};
use crate::body::{DeformableBody, RigidStandIn, outer};
use crate::coupling::RapierSets;
use crate::material::polar_rotation;
use rapier3d::dynamics::RigidBodyBuilder;
use rapier3d::geometry::{Collider, ColliderBuilder};
use rapier3d::glamx::{DMat3, DVec3, Vec3};
use rapier3d::prelude::MassProperties;

/// How much the convex hull may exceed the body's volume (dimensionless) for it to stand in.
const HULL_EXCESS: f64 = 0.01;

/// A body ready to turn rigid: its stand-in, its rigid motion, its nodes' offsets (m) from the
/// centre as rapier holds it (f32), that centre, and its collider.
pub(super) struct Ready {
    settings: RigidStandIn,
    motion: RigidMotion,
    origin: Vec3,
    offsets: Vec<DVec3>,
    collider: Collider,
}

/// `body` ready to turn rigid under the force (N) and strike (m/s) `loads`, if its strain,
/// the strain they predict and its hull allow.
pub(super) fn ready(body: &DeformableBody, loads: (f64, f64)) -> Option<Ready> {
    let settings = body.rigid_stand_in?;
    let half = 0.5 * settings.strain_tolerance;
    let within = |strain: f64| strain <= half; // NaN is not
    if !within(strain_predicted(body, loads)) {
        return None;
    }
    let motion = RigidMotion::of(body)?;
    let (_, wave_speed) = softest(body);
    let strain = peak_green_strain(body) + motion.vibration_speed(body) / wave_speed;
    if !within(strain) {
        return None;
    }
    // rapier keeps poses in f32: the nodes are offset from the centre as rapier holds it, so
    // that the body stands where it stood.
    let origin = motion.center.as_vec3();
    let offsets: Vec<DVec3> = (body.positions().iter())
        .map(|&x| x - origin.as_dvec3())
        .collect();
    let collider = hull_collider(body, &rest_hull_points(body, &motion, origin))?;
    Some(Ready {
        settings,
        motion,
        origin,
        offsets,
        collider,
    })
}

/// Turns `body` rigid as `ready`: a rapier dynamic body of its mass, centre, inertia tensor and
/// momentum, with its collider, in `rapier`'s sets; its nodes take the rigid motion.
pub(super) fn stand_in(
    body: &mut DeformableBody,
    ready: Ready,
    rapier: &mut RapierSets<'_>,
) -> StandIn {
    let Ready {
        settings,
        motion,
        origin,
        offsets,
        collider,
    } = ready;
    let mass = MassProperties::with_inertia_matrix(
        Vec3::ZERO,
        motion.mass as f32,
        motion.inertia.as_mat3(),
    );
    let rigid = RigidBodyBuilder::dynamic()
        .translation(origin)
        .linvel(motion.linvel.as_vec3())
        .angvel(motion.angvel.as_vec3())
        .additional_mass_properties(mass)
        .build();
    let rigid = rapier.bodies.insert(rigid);
    let collider = (rapier.colliders).insert_with_parent(collider, rigid, rapier.bodies);
    if let Some(carrier) = rapier.bodies.get(rigid) {
        super::carry(body, &offsets, carrier);
    }
    StandIn {
        rigid,
        collider,
        offsets,
        settings,
        edits: (body.state_edits(), body.load_edits),
        pushed: 0.0,
        elapsed: 0.0,
        overloaded: false,
        released: false,
    }
}

/// The rest shape of `body` turned by the rotation that best fits its nodes (the polar
/// rotation of `Σ mᵢ rᵢ (pᵢ − c₀)ᵀ`, `pᵢ` the rest positions, `c₀` their centre), about its
/// centre, as offsets (m) from `origin`: its faces flat where the rest shape's are. The
/// deformed nodes differ from it by the strain times the size, at most the tolerance; their
/// own hull splits a flat face into facets a few micrometres apart, and rapier, meeting one
/// facet, lets the body pivot into the ground (measured: a brick at rest turning 1 cm into it
/// within a quarter second).
fn rest_hull_points(body: &DeformableBody, motion: &RigidMotion, origin: Vec3) -> Vec<DVec3> {
    let rest = body.mesh().positions();
    let masses = body.masses();
    let rest_center = (rest.iter().zip(masses))
        .map(|(&p, &m)| p * m)
        .sum::<DVec3>()
        / motion.mass;
    let fit = (motion.offsets.iter().zip(rest).zip(masses))
        .map(|((&r, &p), &m)| outer(r, p - rest_center) * m)
        .fold(DMat3::ZERO, |sum, term| sum + term);
    let rotation = polar_rotation(&fit);
    let shift = motion.center - origin.as_dvec3();
    (rest.iter())
        .map(|&p| shift + rotation * (p - rest_center))
        .collect()
}

/// The collider of `body` standing in with its hull through `points` (m, offsets from its
/// centre of mass, its rest shape turned): their convex hull, with the body's contact
/// coefficients and groups; `None` when the hull exceeds the body's rest volume by more than
/// [`HULL_EXCESS`] or cannot be built.
fn hull_collider(body: &DeformableBody, points: &[DVec3]) -> Option<Collider> {
    let points: Vec<_> = points.iter().map(|r| r.as_vec3()).collect();
    // parry's hull must not unwind into the caller: a body it cannot take stays elastic.
    let built = std::panic::catch_unwind(|| ColliderBuilder::convex_hull(&points)).ok()??;
    let collider = built
        .density(0.0)
        .friction(body.friction as f32)
        .friction_combine_rule(body.friction_combine_rule)
        .restitution(body.restitution as f32)
        .restitution_combine_rule(body.restitution_combine_rule)
        .collision_groups(body.collision_groups)
        .build();
    let hull_volume = f64::from(collider.shape().mass_properties(1.0).mass());
    (hull_volume <= (1.0 + HULL_EXCESS) * body.mesh().volume()).then_some(collider)
}

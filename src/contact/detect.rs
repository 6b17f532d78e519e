//! Contact detection against colliders (as the coupling hands them over, [`ColliderView`]s):
//! each surface node is projected onto every collider within reach whose collision groups
//! interact with the body's (parry's point projection, so every shape), and keeps the nearest
//! surface point and outward normal;
//! rigid vertices are tested against the boundary triangles. Also the force the contacts exerted
//! on any collider.

use super::entry::{LastContact, entered_surface_point};
use super::surface_tree::{KeptTree, SurfaceTree};
use super::{
    BodyPoint, Coefficients, ContactSet, ContactSettings, ContactTarget, CornerContact,
    NodeContact, Obstacle, SurfaceCoefficients, corner,
};
use crate::Error;
use crate::body::DeformableBody;
use crate::rigid::RigidProxy;
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::geometry::{ColliderHandle, InteractionGroups, Ray, Shape, SharedShape};
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;
use std::collections::HashMap;

/// A collider as detection sees it, made once per step for every deformable body (by the
/// coupling, from rapier's sets): its shape and pose, bounds, collision groups and coefficients,
/// its rigid body's proxy for the step, and how far its fastest point travels over the step.
pub(crate) struct ColliderView {
    pub(crate) handle: ColliderHandle,
    pub(crate) shape: SharedShape,
    pub(crate) pose: Pose,
    /// Its bounding box (m).
    pub(crate) bounds: (DVec3, DVec3),
    pub(crate) groups: InteractionGroups,
    pub(crate) coefficients: SurfaceCoefficients,
    /// Its rigid body's proxy, fresh for the step; `None` for a collider without a body.
    pub(crate) parent: Option<RigidProxy>,
    /// Twice the distance (m) its fastest point travels over the step.
    pub(crate) travel: f64,
}

/// What one detection found for a body: its surface points' contacts, the rigid vertices
/// against its triangles, the proxies of the rigid bodies they touch, and the reach (m) used.
pub(crate) struct Detection {
    pub(crate) nodes: Vec<NodeContact>,
    pub(crate) corners: Vec<CornerContact>,
    pub(crate) proxies: Vec<RigidProxy>,
    pub(crate) reach: f64,
}

/// Finds the contacts of `body`'s surface points with the `colliders` for a frame of `frame_dt` (s)
/// under `gravity` (m/s²) (see
/// [`BodyConstraints::detect_contacts`](crate::constraint::BodyConstraints::detect_contacts));
/// `struck` (m) is what the fastest other deformable body that can meet it travels over the step
/// (twice its fastest node's distance); `glued` lists the rigid bodies and the nodes glued to them,
/// which do not touch their colliders; `previous` are the contacts of the last detection and the
/// rigid proxies of its step, whose points' paths since then tell the face a point entered a
/// collider by (see [`super::entry`]). `kept` holds the hierarchy over the body's boundary from
/// the last detection that built one, refitted here if rigid corners need it and given back.
///
/// # Errors
/// [`Error::InvalidTimeStep`], [`Error::NonFiniteInput`] or [`Error::InvalidSetting`] for a bad
/// step, gravity or setting.
pub(crate) fn detect(
    (body, kept): (&DeformableBody, &mut KeptTree),
    (glued, previous): (&[(RigidBodyHandle, u32)], LastDetection<'_>),
    (colliders, struck): (&[ColliderView], f64),
    frame_dt: f64,
    gravity: DVec3,
    settings: &ContactSettings,
) -> Result<Detection, Error> {
    Error::check_step(frame_dt, gravity)?;
    settings.check()?;
    let mut nodes = Vec::new();
    let mut proxies: Vec<RigidProxy> = Vec::new();
    // Elastic waves can speed a node up within the frame: reach as far as the body's fastest
    // node, twice over.
    let reach = settings.margin
        + 2.0 * (body.fastest_node_speed() + gravity.length() * frame_dt) * frame_dt;
    let bounds = body.position_bounds();
    // A body striking this one within the step speeds its nodes up towards the others (a box
    // landing on a block drives the block's bottom into the ground): each collider's reach is
    // widened by the travel of the fastest other collider or body that can meet it. Not its own
    // again: a contact plane taken far from a box sliding past would sweep into the body.
    let strikers = Strikers::of(body, colliders, (bounds, reach), struck);
    let mut tree = None;
    let mut corners = Vec::new();
    let contact_points = contact_points(body);
    let point_bounds = crate::mesh::bounding_box((contact_points.iter()).map(|at| {
        at.stencil(body.embedding.as_ref())
            .interpolate(&body.positions)
    }));
    let last = last_contacts(previous);
    let last_corners: HashMap<_, _> = (previous.0.corners.iter())
        .map(|c| (c.key(), c.stiffening))
        .collect();
    for view in colliders {
        if !body.collision_groups.test(view.groups) {
            continue;
        }
        let near = near_collider(body, glued, view, reach + strikers.other_than(view.handle));
        let mut proxy = None;
        // A point is a candidate only within the collider's widened box (`node_contact_with`).
        let candidates = if near.overlaps(point_bounds) {
            contact_points.as_slice()
        } else {
            &[]
        };
        for &at in candidates {
            let Some(contact) = node_contact_with(body, &near, (at, last.get(&(at, view.handle))))
            else {
                continue;
            };
            if proxy.is_none() {
                proxy = near.proxy_in(&mut proxies);
            }
            nodes.push(contact.with_proxy(proxy));
        }
        if near.overlaps(bounds) && corner::meets_faces(near.shape.as_ref()) {
            let tree = tree.get_or_insert_with(|| SurfaceTree::refitted(body, kept.0.take()));
            let mut found = corner::find_corner_contacts(body, tree, &near);
            if !found.is_empty() {
                let proxy = proxy.or_else(|| near.proxy_in(&mut proxies));
                for contact in &mut found {
                    contact.proxy = proxy;
                    let last = last_corners.get(&contact.key());
                    contact.stiffening = last.copied().unwrap_or_default();
                }
            }
            corners.extend(found);
        }
    }
    if let Some(tree) = tree {
        kept.0 = Some(tree.into_kept());
    }
    Ok(Detection {
        nodes,
        corners,
        proxies,
        reach,
    })
}

/// The fastest colliders that can meet a body within a step: the largest travel (m, at most
/// [`MAX_COLLIDER_REACH`]) with its collider, the second largest, and that of the other
/// deformable bodies (which no collider's handle names).
struct Strikers {
    fastest: Option<(ColliderHandle, f64)>,
    second: f64,
    bodies: f64,
}

impl Strikers {
    /// Among the `colliders` `body` interacts with, those whose bounds, widened by `reach` (m)
    /// and their travel, overlap the body's `bounds`; and the other bodies, whose fastest that
    /// can meet it travels `struck` (m).
    fn of(
        body: &DeformableBody,
        colliders: &[ColliderView],
        (bounds, reach): ((DVec3, DVec3), f64),
        struck: f64,
    ) -> Self {
        let mut strikers = Self {
            fastest: None,
            second: 0.0,
            bodies: struck.min(MAX_COLLIDER_REACH),
        };
        for view in colliders {
            let travel = view.travel.min(MAX_COLLIDER_REACH);
            if travel <= 0.0
                || !body.collision_groups.test(view.groups)
                || !overlaps_widened(view.bounds, reach + travel, bounds)
            {
                continue;
            }
            match strikers.fastest {
                Some((_, fastest)) if travel <= fastest => {
                    strikers.second = strikers.second.max(travel);
                }
                _ => {
                    strikers.second = strikers.fastest.map_or(0.0, |(_, t)| t);
                    strikers.fastest = Some((view.handle, travel));
                }
            }
        }
        strikers
    }

    /// The travel (m) of the fastest of them other than `collider`.
    fn other_than(&self, collider: ColliderHandle) -> f64 {
        let colliders = match self.fastest {
            Some((handle, _)) if handle == collider => self.second,
            Some((_, travel)) => travel,
            None => 0.0,
        };
        colliders.max(self.bodies)
    }
}

/// What detection needs of the collider `view` for `body`: the nodes glued to its body (from
/// `glued`), its combined coefficients, and `reach` (m) widened by its own travel.
fn near_collider<'a>(
    body: &DeformableBody,
    glued: &[(RigidBodyHandle, u32)],
    view: &'a ColliderView,
    reach: f64,
) -> NearCollider<'a> {
    let parent = view.parent.as_ref().map(|proxy| proxy.handle);
    NearCollider {
        handle: view.handle,
        shape: &view.shape,
        pose: &view.pose,
        parent: view.parent.as_ref(),
        reach: reach + view.travel.min(MAX_COLLIDER_REACH),
        bounds: view.bounds,
        glued: glued
            .iter()
            .filter(|(rigid, _)| Some(*rigid) == parent)
            .map(|(_, node)| *node)
            .collect(),
        coefficients: SurfaceCoefficients::of_body(body).combine(view.coefficients),
    }
}

/// The contact of `body`'s point `at` with `near`, if it lies within reach of its surface and
/// can move apart from it (not pinned, not glued to the collider's body); its proxy is left for
/// the caller to set.
fn node_contact_with(
    body: &DeformableBody,
    near: &NearCollider<'_>,
    (at, last): (BodyPoint, Option<&LastContact>),
) -> Option<NodeContact> {
    let stencil = at.stencil(body.embedding.as_ref());
    if stencil.nodes.iter().all(|&n| body.pinned[n as usize])
        || stencil.nodes.iter().any(|n| near.glued.contains(n))
    {
        return None;
    }
    let x = stencil.interpolate(&body.positions);
    let reach = DVec3::splat(near.reach);
    let (lo, hi) = near.bounds;
    if (x + reach).cmplt(lo).any() || (x - reach).cmpgt(hi).any() {
        return None;
    }
    let (point, normal, distance) = entered_surface_point(near.shape.as_ref(), near.pose, x, last)?;
    (distance <= near.reach).then(|| {
        let mut contact = NodeContact::new(
            at,
            ContactTarget::Collider(near.handle),
            point,
            normal,
            near.coefficients,
            Obstacle::Collider {
                shape: near.shape.clone(),
                pose: *near.pose,
                proxy: None,
            },
        );
        contact.detected_at = x;
        contact.stiffening = last.map_or_else(Default::default, |last| last.stiffening);
        contact.depth_limit = 0.5 * thickness(near.shape.as_ref(), near.pose, point, normal);
        contact
    })
}

/// The thickness (m) of `shape` at `pose` along the inward normal from its surface `point` with
/// outward unit `normal`: where a ray from there leaves it; infinite when none does (a
/// half-space).
fn thickness(shape: &dyn Shape, pose: &Pose, point: DVec3, normal: DVec3) -> f64 {
    let start = point - normal * ROUND_OFF_DISTANCE;
    let ray = Ray::new(start.as_vec3(), (-normal).as_vec3());
    shape
        .cast_ray(pose, &ray, f32::MAX, false)
        .map_or(f64::INFINITY, |time| f64::from(time) + ROUND_OFF_DISTANCE)
}

/// The contacts of the last detection and the rigid proxies of its step (as the step left
/// them).
type LastDetection<'a> = (&'a ContactSet, &'a [RigidProxy]);

/// What the `contacts` of the last detection saw of each point's contact with each collider
/// (the stiffness its load called for kept), their planes taken back to the colliders' poses at
/// detection from where the explicit substeps carried them with the rigid `proxies` of that step
/// (see [`RigidProxy::carry`]).
fn last_contacts(
    (contacts, proxies): LastDetection<'_>,
) -> HashMap<(BodyPoint, ColliderHandle), LastContact> {
    contacts
        .nodes
        .iter()
        .filter_map(|c| match (&c.target, &c.obstacle) {
            (ContactTarget::Collider(handle), Obstacle::Collider { pose, proxy, .. }) => {
                let motion = proxy.and_then(|p| proxies.get(p));
                Some((
                    (c.at, *handle),
                    LastContact {
                        at: c.detected_at,
                        pose: *pose,
                        point: motion.map_or(c.point, |m| m.carry_back(c.point)),
                        normal: motion.map_or(c.normal, |m| m.turn_back(c.normal)),
                        stiffening: c.stiffening,
                    },
                ))
            }
            _ => None,
        })
        .collect()
}

/// The points contacts with colliders are detected for: the surface vertices of the embedded
/// mesh if `body` has one, else its surface nodes.
fn contact_points(body: &DeformableBody) -> Vec<BodyPoint> {
    match &body.embedding {
        Some(embedding) => embedding
            .surface_vertices()
            .iter()
            .map(|&v| BodyPoint::Embedded(v))
            .collect(),
        None => body
            .surface
            .nodes
            .iter()
            .map(|&n| BodyPoint::Node(n))
            .collect(),
    }
}

/// Where each point contacts are detected for (see [`contact_points`]) is in `positions` (m,
/// one per node of `body`), with the nodes it moves with.
pub(crate) fn contact_point_positions(
    body: &DeformableBody,
    positions: &[DVec3],
) -> Vec<(DVec3, Vec<u32>)> {
    contact_points(body)
        .into_iter()
        .map(|at| {
            let stencil = at.stencil(body.embedding.as_ref());
            (stencil.interpolate(positions), stencil.nodes.to_vec())
        })
        .collect()
}

/// Each contact's collider, the point (m) it acts at, and the mean force (N) it exerted on the
/// collider over the last step of `dt` (s): node contacts at their points' end-of-step
/// positions, rigid vertices at the vertices; nodes first, then vertices, in order.
fn forces_on_colliders<'a>(
    body: &'a DeformableBody,
    contacts: &'a ContactSet,
    dt: f64,
) -> impl Iterator<Item = (ColliderHandle, DVec3, DVec3)> + 'a {
    let from_nodes = contacts.nodes.iter().filter_map(move |c| match c.target {
        ContactTarget::Collider(collider) => {
            let at = c.at.stencil(body.embedding.as_ref());
            Some((collider, at.interpolate(&body.positions), -c.impulse / dt))
        }
        ContactTarget::OwnSurface { .. } => None,
    });
    let from_corners = contacts.corners.iter().map(move |c| {
        let (at, force) = c.force_on_collider(dt);
        (c.collider, at, force)
    });
    from_nodes.chain(from_corners)
}

/// The impulse (N s) and angular impulse about the world origin (N m s) `body`'s `contacts`
/// gave each collider they touch over the last step, one entry per collider.
pub(crate) fn collider_impulses(
    body: &DeformableBody,
    contacts: &ContactSet,
) -> Vec<(ColliderHandle, DVec3, DVec3)> {
    let mut totals: Vec<(ColliderHandle, DVec3, DVec3)> = Vec::new();
    for (collider, at, impulse) in forces_on_colliders(body, contacts, 1.0) {
        let angular = at.cross(impulse);
        match totals.iter_mut().find(|(c, _, _)| *c == collider) {
            Some((_, total, total_angular)) => {
                *total += impulse;
                *total_angular += angular;
            }
            None => totals.push((collider, impulse, angular)),
        }
    }
    totals
}

/// The mean force (N) and torque about the world origin (N m) `body`'s `contacts` exerted on
/// `collider` over the last step, of length `dt` (s).
///
/// # Errors
/// [`Error::InvalidTimeStep`] for a non-positive or non-finite `dt`.
pub(crate) fn force_on_collider(
    body: &DeformableBody,
    contacts: &ContactSet,
    collider: ColliderHandle,
    dt: f64,
) -> Result<(DVec3, DVec3), Error> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::InvalidTimeStep {
            dt,
            reason: "must be positive and finite",
        });
    }
    Ok(forces_on_colliders(body, contacts, dt)
        .filter(|(touched, _, _)| *touched == collider)
        .fold(
            (DVec3::ZERO, DVec3::ZERO),
            |(force, torque), (_, at, on_collider)| {
                (force + on_collider, torque + at.cross(on_collider))
            },
        ))
}

/// A collider as one detection sees it.
pub(super) struct NearCollider<'a> {
    /// Its handle.
    pub(super) handle: ColliderHandle,
    /// Its shape and pose.
    pub(super) shape: &'a SharedShape,
    pub(super) pose: &'a Pose,
    /// Its rigid body's fresh proxy, if it has one.
    parent: Option<&'a RigidProxy>,
    /// How far (m) from its surface a point gets a contact.
    pub(super) reach: f64,
    /// Its bounding box (m).
    bounds: (DVec3, DVec3),
    /// The body's nodes glued to its rigid body, which do not touch it.
    pub(super) glued: Vec<u32>,
    /// The contact's combined coefficients.
    pub(super) coefficients: Coefficients,
}

impl NearCollider<'_> {
    /// The index in `proxies` of the proxy of its body (added if new); `None` for a collider
    /// without a body.
    fn proxy_in(&self, proxies: &mut Vec<RigidProxy>) -> Option<usize> {
        self.parent
            .map(|fresh| RigidProxy::index_in(proxies, fresh))
    }

    /// Whether its bounding box, widened by the reach, overlaps the box `other` (m).
    fn overlaps(&self, other: (DVec3, DVec3)) -> bool {
        overlaps_widened(self.bounds, self.reach, other)
    }
}

/// Whether the box `(lo, hi)` (m), widened by `by` (m) on every side, overlaps the box `other`.
fn overlaps_widened((lo, hi): (DVec3, DVec3), by: f64, other: (DVec3, DVec3)) -> bool {
    let by = DVec3::splat(by);
    !((hi + by).cmplt(other.0).any() || (lo - by).cmpgt(other.1).any())
}

/// The most (m) a rigid collider's own motion widens the detection reach (a body flung across
/// the world in one frame would otherwise make every node a candidate).
pub(super) const MAX_COLLIDER_REACH: f64 = 1.0;

/// Below this distance (m) from a surface, the offset of a node from its projection is f32
/// round-off and gives no direction.
pub(super) const ROUND_OFF_DISTANCE: f64 = 1e-6;
/// How far (m) outside a surface the normal of a node lying on it is probed.
pub(super) const PROBE_DISTANCE: f64 = 1e-4;

/// The point of a shape's surface (at `pose`) nearest to `x` (m), the outward normal there, and
/// the signed distance of `x` (negative inside); `None` where the normal is undefined.
pub(super) fn nearest_surface_point(
    shape: &dyn Shape,
    pose: &Pose,
    x: DVec3,
) -> Option<(DVec3, DVec3, f64)> {
    let (projection, feature) = shape.project_point_and_get_feature(pose, x.as_vec3());
    let point = projection.point.as_dvec3();
    let local = pose.inverse_transform_point(projection.point);
    let feature_normal = shape
        .feature_normal_at_point(projection.subshape, feature, local)
        .map(|n| (pose.rotation * n).as_dvec3());
    let offset = x - point;
    let sign = if projection.is_inside { -1.0 } else { 1.0 };
    // The feature's normal where parry has one (balls, cuboids, convex shapes, meshes), the
    // plane's for half-spaces, else the direction from the surface point to the node; a node
    // exactly on such a surface has no defined normal.
    let normal = match (feature_normal, shape.as_halfspace()) {
        (Some(n), _) if n.is_finite() && n.length() > 0.5 => n.normalize(),
        (_, Some(half_space)) => (pose.rotation * half_space.normal).as_dvec3().normalize(),
        _ if offset.length() > ROUND_OFF_DISTANCE => offset.normalize() * sign,
        _ => {
            // On the surface, where the offset is f32 round-off: probe a little outward from
            // the shape's origin (exact for convex shapes) and take the normal there.
            let outward = (x - pose.translation.as_dvec3()).normalize_or_zero();
            let probe = x + outward * PROBE_DISTANCE;
            let projected = shape.project_point(pose, probe.as_vec3(), false);
            let offset = probe - projected.point.as_dvec3();
            if projected.is_inside || offset.length() <= ROUND_OFF_DISTANCE {
                return None;
            }
            offset.normalize()
        }
    };
    Some((point, normal, sign * offset.length()))
}

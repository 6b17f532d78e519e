//! The constraints acting on one deformable body over the coming step, kept beside the body (by
//! [`SoftCoupling`](crate::coupling::SoftCoupling), per body handle): the contacts the last
//! detection found (its surface against colliders and against itself, rigid vertices against its
//! boundary triangles), the nodes glued to rigid bodies, and the proxies of the rigid bodies
//! they touch (their velocities following the impulses, carried along by the explicit substeps;
//! see [`crate::rigid`]). A step saves what it moves of them and puts it back if it fails.

use crate::Error;
use crate::attachment::{self, Attachment};
use crate::body::DeformableBody;
use crate::contact::{
    self, ColliderView, ContactSet, ContactSettings, ContactTarget, CornerContact, CornerPlace,
    KeptTree, NodeContact,
};
use crate::rigid::RigidProxy;
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::geometry::ColliderHandle;
use rapier3d::glamx::DVec3;
use rapier3d::math::Pose;

/// The contacts and attachments of one deformable body, and the rigid bodies they touch.
///
/// [`SoftCoupling`](crate::coupling::SoftCoupling) keeps one per body and fills it every
/// substep; a program stepping a body alone with an integrator keeps its own and hands it to
/// the step (an empty one for a body touching nothing).
///
/// # Example
/// ```
/// use rapier_fvm::prelude::*;
///
/// let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.4, 1000.0)?;
/// let mut cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [2; 3])?, material).build()?;
/// let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
/// let gravity = DVec3::new(0.0, -9.81, 0.0);
/// ImplicitIntegrator::default().step(&mut cube, &mut constraints, &mut workspace, 0.01, gravity)?;
/// assert!(constraints.contacts().is_empty());
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
///
/// Written (feature `serde-serialize`) as its attachments: the contacts and the rigid bodies'
/// proxies are found again by every detection, before every step.
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct BodyConstraints {
    /// The contacts the integrators enforce, from the last detection.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub(crate) contacts: ContactSet,
    /// The nodes glued to rigid bodies.
    pub(crate) attachments: Vec<Attachment>,
    /// The rigid bodies the contacts and attachments touch, as the soft step sees them.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    pub(crate) rigid_proxies: Vec<RigidProxy>,
    /// What [`BodyConstraints::save`] set aside.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    saved: SavedConstraints,
    /// The hierarchy over the body's boundary the last detection built, for the next to refit.
    #[cfg_attr(feature = "serde-serialize", serde(skip))]
    surface_tree: KeptTree,
}

/// The proxies, attachment anchors (m), contact planes (point and normal) and rigid corners
/// saved with the state before a step: substeps move them, and a refused frame is redone from
/// where it started.
#[derive(Debug, Clone, Default)]
struct SavedConstraints {
    proxies: Vec<RigidProxy>,
    anchors: Vec<DVec3>,
    planes: Vec<(DVec3, DVec3)>,
    corners: Vec<CornerPlace>,
}

impl BodyConstraints {
    /// No contacts and no attachments.
    pub fn new() -> Self {
        Self::default()
    }

    /// [`BodyConstraints::detect_contacts`] against `colliders` as the coupling sees them, with
    /// `rigid` telling an attached rigid body's pose and fresh proxy; `struck` (m) is what the
    /// fastest other deformable body that can meet this one travels over the step.
    ///
    /// # Errors
    /// Those of [`BodyConstraints::detect_contacts`].
    pub(crate) fn detect_among(
        &mut self,
        body: &DeformableBody,
        colliders: (&[ColliderView], f64),
        rigid: &(dyn Fn(RigidBodyHandle) -> Option<(Pose, RigidProxy)> + Sync),
        frame_dt: f64,
        gravity: DVec3,
        settings: &ContactSettings,
    ) -> Result<&[NodeContact], Error> {
        let glued: Vec<(RigidBodyHandle, u32)> =
            self.attachments.iter().map(|a| (a.body, a.node)).collect();
        let found = contact::detect(
            (body, &mut self.surface_tree),
            (&glued, (&self.contacts, &self.rigid_proxies)),
            colliders,
            frame_dt,
            gravity,
            settings,
        )?;
        let mut proxies = found.proxies;
        attachment::ready(&mut self.attachments, &mut proxies, rigid);
        self.rigid_proxies = proxies;
        self.contacts = ContactSet {
            nodes: found.nodes,
            corners: found.corners,
            settings: *settings,
            step: frame_dt,
        };
        if body.self_contact {
            let own = contact::detect_self_contacts(body, found.reach);
            self.contacts.nodes.extend(own);
        }
        Ok(&self.contacts.nodes)
    }

    /// Whether `other` holds the same contacts, attachments and rigid bodies' proxies, bit for
    /// bit: what a step reads of them (the state saved for a refused step's restart is not).
    pub(crate) fn same_as(&self, other: &Self) -> bool {
        self.contacts == other.contacts
            && self.attachments == other.attachments
            && self.rigid_proxies == other.rigid_proxies
    }

    /// The contacts found by the last [`BodyConstraints::detect_contacts`].
    pub fn contacts(&self) -> &[NodeContact] {
        &self.contacts.nodes
    }

    /// Whether a collider pushed the body over the last step: a contact of one of its surface
    /// points with a collider, or of a rigid body's corner with one of its faces, carried an
    /// impulse (a contact merely within reach carries none).
    pub fn pushed_by_collider(&self) -> bool {
        let point = |c: &NodeContact| {
            matches!(c.target, ContactTarget::Collider(_)) && c.impulse != DVec3::ZERO
        };
        self.contacts.nodes.iter().any(point)
            || (self.contacts.corners.iter()).any(|c| c.impulse != DVec3::ZERO)
    }

    /// Removes every contact (the attachments stay).
    pub fn clear_contacts(&mut self) {
        self.contacts.nodes.clear();
        self.contacts.corners.clear();
        self.rigid_proxies.clear();
    }

    /// Adds attachments made by [`BodyConstraints::attach`].
    pub(crate) fn add_attachments(&mut self, added: Vec<Attachment>) {
        self.attachments.extend(added);
    }

    /// The attachments.
    pub fn attachments(&self) -> &[Attachment] {
        &self.attachments
    }

    /// Removes every attachment to the rigid body `rigid`.
    pub fn detach(&mut self, rigid: RigidBodyHandle) {
        self.attachments.retain(|a| a.body != rigid);
    }

    /// The impulse (N s) and angular impulse about the centre of mass (N m s) the body gave each
    /// rigid body it touches or is attached to over the last step, not yet handed to rapier (see
    /// [`BodyConstraints::transfer_contact_impulses`]).
    pub fn rigid_impulses(&self) -> impl Iterator<Item = (RigidBodyHandle, DVec3, DVec3)> + '_ {
        self.rigid_proxies
            .iter()
            .map(|proxy| (proxy.handle, proxy.impulse, proxy.angular_impulse))
    }

    /// The rigid bodies' proxies, whose impulses the coupling hands to rapier.
    pub(crate) fn rigid_proxies_mut(&mut self) -> &mut [RigidProxy] {
        &mut self.rigid_proxies
    }

    /// The mean force (N) and torque about the world origin (N m) `body`'s contacts exerted on
    /// `collider` over the last step, of length `dt` (s): their impulses over `dt` (the torque
    /// taken at the surface points' end-of-step positions, and at the collider's vertices for
    /// its corners pressing on the surface). In an [`FvmWorld`](crate::world::FvmWorld) the last
    /// step is the frame's last coupling substep, or the whole frame for a body that needed no
    /// coupling ([`FvmWorld::contact_force_on`](crate::world::FvmWorld::contact_force_on) knows
    /// which).
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a non-positive or non-finite `dt`.
    pub fn contact_force_on(
        &self,
        body: &DeformableBody,
        collider: ColliderHandle,
        dt: f64,
    ) -> Result<(DVec3, DVec3), Error> {
        contact::force_on_collider(body, &self.contacts, collider, dt)
    }

    /// The impulse (N s) and angular impulse about the world origin (N m s) `body`'s contacts
    /// gave each collider they touch over the last step, one entry per collider.
    pub(crate) fn collider_impulses(
        &self,
        body: &DeformableBody,
    ) -> Vec<(ColliderHandle, DVec3, DVec3)> {
        contact::collider_impulses(body, &self.contacts)
    }

    /// Whether the last detection found contacts an implicit step does not take well: surface
    /// points or rigid corners found deeper behind their contact planes than twice
    /// [`ContactSettings::resting_depth`] (an implicit step itself leaves a loaded point up to
    /// that depth), which an implicit step's penalty pushes out within the step (a 10 cm cube set
    /// 4 cm into the ground left it with 9.4 J, against at most `depenetration_speed` in
    /// explicit substeps; rigid corners found deep gave 0.11 J in a frame of the game scene).
    /// The automatic integrator keeps the explicit one while there are any.
    pub(crate) fn needs_explicit_contacts(&self) -> bool {
        self.contacts.deepest_found() > 2.0 * self.contacts.settings.resting_depth
    }

    /// Whether the constraints are coupled to each other (through a dynamic rigid body's
    /// velocity or the nodes of a self-contact triangle or a rigid corner), so that one explicit
    /// sweep does not solve them.
    pub(crate) fn coupled(&self) -> bool {
        self.touches_dynamic_body() || self.contacts.couples_nodes()
    }

    /// Whether the contacts or attachments touch a dynamic rigid body (as the last detection
    /// found them).
    pub(crate) fn touches_dynamic_body(&self) -> bool {
        self.rigid_proxies.iter().any(RigidProxy::is_dynamic)
    }

    /// The dynamic rigid bodies the contacts and attachments touch (as the last detection found
    /// them).
    pub(crate) fn dynamic_body_count(&self) -> usize {
        (self.rigid_proxies.iter())
            .filter(|proxy| proxy.is_dynamic())
            .count()
    }

    /// Sets aside what a step moves (no allocation after the first call), and starts counting
    /// the contact impulses of a new step.
    pub(crate) fn save(&mut self) {
        self.contacts.clear_impulses();
        self.saved.proxies.clone_from(&self.rigid_proxies);
        self.saved.anchors.clear();
        self.saved
            .anchors
            .extend(self.attachments.iter().map(|a| a.anchor));
        self.saved.planes.clear();
        self.saved
            .planes
            .extend(self.contacts.nodes.iter().map(|c| (c.point, c.normal)));
        self.saved.corners.clear();
        self.saved
            .corners
            .extend(self.contacts.corners.iter().map(CornerContact::place));
    }

    /// Puts back what [`BodyConstraints::save`] set aside.
    pub(crate) fn restore(&mut self) {
        self.contacts.clear_impulses();
        self.rigid_proxies.clone_from(&self.saved.proxies);
        for (attachment, anchor) in self.attachments.iter_mut().zip(&self.saved.anchors) {
            attachment.anchor = *anchor;
        }
        for (contact, (point, normal)) in self.contacts.nodes.iter_mut().zip(&self.saved.planes) {
            contact.point = *point;
            contact.normal = *normal;
        }
        for (corner, place) in self.contacts.corners.iter_mut().zip(&self.saved.corners) {
            corner.set_place(*place);
        }
    }
}

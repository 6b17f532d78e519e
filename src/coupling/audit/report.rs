//! What the audit found in a frame: per deformable body and for the coupled system.

use crate::Error;
use crate::body::DeformableBodyHandle;
use rapier3d::geometry::ColliderHandle;

/// The energy of a set of bodies at the end of a frame against the previous frame's plus the
/// work done on them (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyCheck {
    /// The energy now (J).
    pub energy: f64,
    /// The previous frame's energy plus the work counted (J).
    pub expected: f64,
    /// The work counted: kinematic bodies on the deformable bodies (J).
    pub work: f64,
    /// `energy - expected` (J): positive when energy was gained.
    pub gain: f64,
    /// The gain allowed (J).
    pub tolerance: f64,
}

impl EnergyCheck {
    /// Whether the bodies gained more energy than the tolerance allows (or it is not finite).
    pub fn gained(&self) -> bool {
        self.gain.is_nan() || self.tolerance.is_nan() || self.gain > self.tolerance
    }
}

/// What a contact point lies in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PenetrationTarget {
    /// A collider.
    Collider(ColliderHandle),
    /// Another deformable body.
    SoftBody(DeformableBodyHandle),
}

/// A body's contact points found past a collider or another deformable body after a frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Penetrations {
    /// Points deeper than the tolerance inside a collider or another deformable body (a point
    /// inside two counts twice).
    pub points: usize,
    /// The deepest of them (m); zero if none.
    pub deepest: f64,
    /// What the deepest lies in.
    pub deepest_in: Option<PenetrationTarget>,
    /// Points that went through a collider or another deformable body over the frame.
    pub crossed: usize,
    /// The first collider or deformable body crossed.
    pub first_crossed: Option<PenetrationTarget>,
}

impl Penetrations {
    /// Counts a point `depth` (m) deep in `target`.
    pub(super) fn add_penetration(&mut self, depth: f64, target: PenetrationTarget) {
        self.points += 1;
        if depth > self.deepest {
            self.deepest = depth;
            self.deepest_in = Some(target);
        }
    }
}

/// What the audit found for one deformable body after a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyAudit {
    /// The energy check of the body with the bodies it exchanges energy with (see the module's
    /// documentation); `None` on the first frame seen.
    pub energy: Option<EnergyCheck>,
    /// The depth (m) of penetration and crossing allowed for this body.
    pub penetration_tolerance: f64,
    /// Its contact points past colliders and other deformable bodies.
    pub penetrations: Penetrations,
    /// Elements with zero or negative volume.
    pub inverted_elements: usize,
    /// Elements with a positive volume below the collapse ratio of their rest volume.
    pub collapsed_elements: usize,
    /// The smallest element volume over rest volume (dimensionless).
    pub smallest_volume_ratio: f64,
    /// Implicit substeps of the body's last step whose Newton solve stopped on a round-off stall
    /// (not a failure: see
    /// [`ImplicitReport::stalled_substeps`](crate::integrate::ImplicitReport::stalled_substeps)).
    pub newton_stalled_substeps: u32,
    /// The error the body's step returned this frame, if any: a step refused (a Newton solve
    /// that refinement could not make converge, an element crushed, ...), its state then the one
    /// before the refused substep.
    pub step_error: Option<Error>,
}

impl BodyAudit {
    /// Whether the body and the bodies it exchanges energy with gained energy.
    pub fn energy_gained(&self) -> bool {
        self.energy.is_some_and(|e| e.gained())
    }

    /// Whether a contact point lies deeper than the tolerance in a collider or a deformable body.
    pub fn penetrates(&self) -> bool {
        self.penetrations.points > 0
    }

    /// Whether a contact point went through a collider or another deformable body.
    pub fn crossed(&self) -> bool {
        self.penetrations.crossed > 0
    }

    /// Whether an element is inverted or collapsed.
    pub fn has_bad_elements(&self) -> bool {
        self.inverted_elements > 0 || self.collapsed_elements > 0
    }

    /// Whether none of the checks failed and the step returned no error.
    pub fn is_clean(&self) -> bool {
        !(self.energy_gained()
            || self.penetrates()
            || self.crossed()
            || self.has_bad_elements()
            || self.step_error.is_some())
    }
}

/// What the audit found after a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameAudit {
    /// The energy check of the coupled system: every deformable body and every dynamic rigid
    /// body one of them touched or is glued to in the frame; `None` on the first frame seen.
    pub system: Option<EnergyCheck>,
    /// Each deformable body's findings.
    pub bodies: Vec<(DeformableBodyHandle, BodyAudit)>,
}

impl FrameAudit {
    /// The findings of the deformable body `handle`, if it is in the set.
    pub fn body(&self, handle: DeformableBodyHandle) -> Option<&BodyAudit> {
        self.bodies
            .iter()
            .find(|(h, _)| *h == handle)
            .map(|(_, a)| a)
    }

    /// Whether the coupled system kept its energy and every body is clean.
    pub fn is_clean(&self) -> bool {
        !self.system.is_some_and(|e| e.gained()) && self.bodies.iter().all(|(_, a)| a.is_clean())
    }
}

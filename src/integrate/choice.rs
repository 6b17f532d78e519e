//! What the automatic choice decides a frame on and reports of it: the integrator taken
//! ([`IntegratorKind`]), the predicted cost of a frame with each ([`CostPrediction`], from the
//! [`CostModel`](super::CostModel)), and the frame's report ([`AutomaticReport`]).

use super::{ImplicitReport, NewtonWork, StepReport};

/// Which integrator advanced a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum IntegratorKind {
    /// [`SymplecticEuler`](super::SymplecticEuler).
    Explicit,
    /// [`ImplicitIntegrator`](super::ImplicitIntegrator).
    Implicit,
}

/// The predicted cost of a frame with each integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostPrediction {
    /// Substeps the explicit stability limit requires.
    pub explicit_substeps: f64,
    /// Contact points the explicit substeps sweep (those found at the frame's start).
    pub contact_points: usize,
    /// Dynamic rigid bodies the contacts and attachments touch (found at the frame's start).
    pub rigid_partners: usize,
    /// The work per implicit substep expected (the body's recent means).
    pub newton: NewtonWork,
    /// Predicted time of the explicit frame (s).
    pub explicit_seconds: f64,
    /// Predicted time of the implicit frame (s).
    pub implicit_seconds: f64,
}

/// How many times cheaper the other integrator must be predicted than the one a body's last
/// frame took for the automatic choice to switch (see [`CostPrediction::cheaper_after`]).
pub const SWITCH_MARGIN: f64 = 1.5;

impl CostPrediction {
    /// The cheaper integrator, explicit on a tie.
    pub fn cheaper(&self) -> IntegratorKind {
        if self.explicit_seconds <= self.implicit_seconds {
            IntegratorKind::Explicit
        } else {
            IntegratorKind::Implicit
        }
    }

    /// The integrator for a body whose last frame `last` took: that one unless the other is
    /// predicted [`SWITCH_MARGIN`] times cheaper; [`CostPrediction::cheaper`] before any frame.
    /// Predictions within that margin of each other are within their own error (measured over
    /// predicted from 0.5 to 2 step by step), and a switch costs what the predictions leave out
    /// (the next implicit frame refactors, the contacts settle to the other integrator's
    /// resting depth): near a tie a body switched at every other frame, and a 1 kg block under
    /// a 100 kg box at 1/30 s frames gained 8e-3 J so.
    pub fn cheaper_after(&self, last: Option<IntegratorKind>) -> IntegratorKind {
        let other_is_cheaper = |kind: IntegratorKind, other: IntegratorKind| {
            self.seconds(other) * SWITCH_MARGIN < self.seconds(kind)
        };
        match last {
            None => self.cheaper(),
            Some(kind) => {
                let other = match kind {
                    IntegratorKind::Explicit => IntegratorKind::Implicit,
                    IntegratorKind::Implicit => IntegratorKind::Explicit,
                };
                if other_is_cheaper(kind, other) {
                    other
                } else {
                    kind
                }
            }
        }
    }

    /// The predicted time (s) of the frame with `kind`.
    pub fn seconds(&self, kind: IntegratorKind) -> f64 {
        match kind {
            IntegratorKind::Explicit => self.explicit_seconds,
            IntegratorKind::Implicit => self.implicit_seconds,
        }
    }
}

/// What an automatic frame did and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutomaticReport {
    /// The integrator used.
    pub choice: IntegratorKind,
    /// The prediction the choice was made on.
    pub prediction: CostPrediction,
    /// The explicit frame's report, if explicit.
    pub explicit: Option<StepReport>,
    /// The implicit frame's report, if implicit.
    pub implicit: Option<ImplicitReport>,
    /// Whether the frame was redone with the other integrator than the one chosen: chosen
    /// explicit, because crushed elements lowered the stability limit partway below what
    /// `max_substeps` allows, or the explicit frame produced a non-finite state; chosen
    /// implicit, because its Newton solve failed or it crushed an element even in the most
    /// substeps it may take.
    pub fell_back: bool,
    /// Wall-clock time the frame's integration took (s), prediction and contact detection
    /// excluded; for bodies stepped together, the group's time shared in proportion to each
    /// body's predicted cost with the integrator used. Measured, so it differs from run to run;
    /// nothing in the step depends on it.
    pub seconds: f64,
}

impl AutomaticReport {
    /// The report of a frame predicted as `prediction`, taken by the integrator whose report
    /// `frame` holds (explicit, implicit), redone or not (`fell_back`), in `seconds`.
    pub(super) fn of(
        prediction: CostPrediction,
        (explicit, implicit): (Option<StepReport>, Option<ImplicitReport>),
        fell_back: bool,
        seconds: f64,
    ) -> Self {
        Self {
            choice: if explicit.is_some() {
                IntegratorKind::Explicit
            } else {
                IntegratorKind::Implicit
            },
            prediction,
            explicit,
            implicit,
            fell_back,
            seconds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prediction of `explicit` and `implicit` seconds.
    fn prediction(explicit: f64, implicit: f64) -> CostPrediction {
        CostPrediction {
            explicit_substeps: 1.0,
            contact_points: 0,
            rigid_partners: 0,
            newton: super::super::NewtonWork::default(),
            explicit_seconds: explicit,
            implicit_seconds: implicit,
        }
    }

    #[test]
    fn a_body_switches_integrators_only_for_a_prediction_below_the_margin() {
        // Implicit predicted 1.4 times cheaper: within the margin of 1.5, a body that stepped
        // explicitly stays so; 1.6 times cheaper, it switches; before any frame, the cheaper.
        use IntegratorKind::{Explicit, Implicit};
        assert_eq!(prediction(1.4, 1.0).cheaper_after(Some(Explicit)), Explicit);
        assert_eq!(prediction(1.6, 1.0).cheaper_after(Some(Explicit)), Implicit);
        assert_eq!(prediction(1.0, 1.4).cheaper_after(Some(Implicit)), Implicit);
        assert_eq!(prediction(1.0, 1.6).cheaper_after(Some(Implicit)), Explicit);
        assert_eq!(prediction(1.4, 1.0).cheaper_after(None), Implicit);
    }
}

//! Where a frame's time went: the deformable bodies' steps by integrator and by whether dynamic
//! rigid bodies took part in them, contact detection, and rapier's steps. Wall-clock seconds
//! measured as the frame runs; they describe the machine as much as the scene, and no result
//! depends on them.
//!
//! The soft steps are summed body by body, over whichever threads ran them (bodies step at once
//! on rayon's pool with the `parallel` feature, so their sum can exceed the frame's wall time);
//! a group of touching bodies' time is shared among its bodies as their reports share it. A
//! step that was refused is not counted. Detection and rapier's steps are wall times of the
//! stages that run them.

/// Seconds a frame spent in each part of [`SoftCoupling::step`](super::SoftCoupling::step)
/// (see the module's documentation); [`SoftCoupling::last_frame_timing`](super::SoftCoupling::last_frame_timing).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameTiming {
    /// Implicit steps of bodies touching or glued to a dynamic rigid body (s, summed over bodies).
    pub implicit_with_rigid_partners: f64,
    /// Implicit steps of bodies without dynamic rigid partners (s, summed over bodies).
    pub implicit_without_rigid_partners: f64,
    /// Explicit steps of bodies touching or glued to a dynamic rigid body (s, summed over bodies).
    pub explicit_with_rigid_partners: f64,
    /// Explicit steps of bodies without dynamic rigid partners (s, summed over bodies).
    pub explicit_without_rigid_partners: f64,
    /// Contact detection (s, wall time): over the whole frame, of the bodies that may need no
    /// coupling (each against the colliders), and in each coupling substep (each body against
    /// the colliders, then the bodies against each other).
    pub contact_detection: f64,
    /// rapier's steps of the frame (s, wall time).
    pub rapier_steps: f64,
}

impl FrameTiming {
    /// The soft steps' seconds, both integrators, with and without rigid partners (s).
    pub fn soft_steps(&self) -> f64 {
        self.implicit_with_rigid_partners
            + self.implicit_without_rigid_partners
            + self.explicit_with_rigid_partners
            + self.explicit_without_rigid_partners
    }

    /// Counts a soft step of `seconds` (s), explicit or implicit, with dynamic rigid partners
    /// or without.
    pub(super) fn add_step(&mut self, seconds: f64, explicit: bool, with_partners: bool) {
        let part = match (explicit, with_partners) {
            (false, true) => &mut self.implicit_with_rigid_partners,
            (false, false) => &mut self.implicit_without_rigid_partners,
            (true, true) => &mut self.explicit_with_rigid_partners,
            (true, false) => &mut self.explicit_without_rigid_partners,
        };
        *part += seconds;
    }

    /// Adds `other`'s seconds to these, part by part: a run's totals from its frames'.
    pub fn accumulate(&mut self, other: &FrameTiming) {
        self.implicit_with_rigid_partners += other.implicit_with_rigid_partners;
        self.implicit_without_rigid_partners += other.implicit_without_rigid_partners;
        self.explicit_with_rigid_partners += other.explicit_with_rigid_partners;
        self.explicit_without_rigid_partners += other.explicit_without_rigid_partners;
        self.contact_detection += other.contact_detection;
        self.rapier_steps += other.rapier_steps;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_counted_in_their_part_and_frames_add_up_part_by_part() {
        let mut frame = FrameTiming::default();
        frame.add_step(1.0, false, true);
        frame.add_step(2.0, false, false);
        frame.add_step(4.0, true, true);
        frame.add_step(8.0, true, false);
        frame.add_step(16.0, false, true);
        frame.contact_detection = 32.0;
        assert_eq!(frame.implicit_with_rigid_partners, 17.0);
        assert_eq!(frame.implicit_without_rigid_partners, 2.0);
        assert_eq!(frame.explicit_with_rigid_partners, 4.0);
        assert_eq!(frame.explicit_without_rigid_partners, 8.0);
        assert_eq!(frame.soft_steps(), 31.0);
        let mut run = FrameTiming::default();
        run.accumulate(&frame);
        run.accumulate(&frame);
        assert_eq!(run.soft_steps(), 62.0);
        assert_eq!((run.contact_detection, run.rapier_steps), (64.0, 0.0));
    }
}

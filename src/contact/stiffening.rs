//! A contact's implicit penalty, stiffened by its load beyond the depth it was stiffened from.
//!
//! A point `d` (m) behind its contact plane holds the energy
//! `e(d) = ½ k d² + Σᵢ ½ Δkᵢ (d − aᵢ)₊²` (J), pushed out by the force `e'(d)` (N) with the
//! stiffness `e''(d)` (N/m): `k` is the contact's own penalty (the penalty factor times the
//! point's `m/h²`, `h` the step's penalty step, see `contact::ImplicitStep`), and each `Δkᵢ` a stiffening its load called for when an implicit step left
//! the point deeper than the resting depth `r`
//! ([`ContactSettings::resting_depth`](super::ContactSettings::resting_depth)), acting only
//! beyond `aᵢ`, the depth that step started the point at. It is sized for the load to be held at
//! `r/2`, or, for a point that started deeper than that, a tenth to a half of its sink over the
//! step (up to `r`) beyond its start. `e` is convex and its force continuous, and a stiffening
//! leaves the energy of every depth up to the step's start as it was: a stiffer `k` at the start
//! depth `d₀` would hand the point `½ Δk d₀²` it never stored (a 100 kg box on a 1 kg block, its
//! contacts stiffened so, gained 0.66 J in a frame).

/// The most stiffenings a contact takes; a load that presses it deeper still is held by the
/// last ones' stiffness.
const MAX_STIFFENINGS: usize = 4;

/// The stiffenings a contact's load has called for (see the module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Stiffening {
    /// The depths `aᵢ` (m) and stiffnesses `Δkᵢ` (N/m) of the first `count`.
    hinges: [(f64, f64); MAX_STIFFENINGS],
    count: usize,
}

/// A contact's penalty at a depth behind its plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Penalty {
    /// The energy `e(d)` (J).
    pub(crate) energy: f64,
    /// The force `e'(d)` (N) pushing the point out along the plane's normal.
    pub(crate) push: f64,
    /// The stiffness `e''(d)` (N/m) along the normal.
    pub(crate) stiffness: f64,
}

impl Stiffening {
    /// The penalty of a point `depth` (m) behind its plane (`None` in front of it) on a contact
    /// of own stiffness `base` (N/m).
    pub(crate) fn penalty(&self, base: f64, depth: f64) -> Option<Penalty> {
        (depth > 0.0).then(|| {
            let mut penalty = Penalty {
                energy: 0.5 * base * depth * depth,
                push: base * depth,
                stiffness: base,
            };
            for &(from, stiffness) in self.hinges() {
                let beyond = depth - from;
                if beyond > 0.0 {
                    penalty.energy += 0.5 * stiffness * beyond * beyond;
                    penalty.push += stiffness * beyond;
                    penalty.stiffness += stiffness;
                }
            }
            penalty
        })
    }

    /// The quadratic piece of the penalty (own stiffness `base`, N/m) that holds at the depth
    /// `to` (m), extended to the depth `from` (m): its push (N) and stiffness (N/m) there, or
    /// `None` when `to` is in front of the plane.
    pub(crate) fn piece_towards(&self, base: f64, (from, to): (f64, f64)) -> Option<(f64, f64)> {
        (to > 0.0).then(|| {
            let (mut push, mut stiffness) = (base * from, base);
            for &(at, extra) in self.hinges().iter().filter(|(at, _)| to > *at) {
                push += extra * (from - at);
                stiffness += extra;
            }
            (push, stiffness)
        })
    }

    /// Stiffens a contact of own stiffness `base` (N/m) whose point an implicit step took from
    /// `start` to `end` (depths behind its plane, m), deeper than `resting` (m): beyond the
    /// start, so that the force at the end holds the point at half of `resting`, or no nearer
    /// to the start than a tenth of its sink (up to `resting`), no farther than half. Returns
    /// whether it did (not for a point that did not sink, nor past [`MAX_STIFFENINGS`]).
    pub(crate) fn stiffen(&mut self, base: f64, (start, end): (f64, f64), resting: f64) -> bool {
        let from = start.max(0.0);
        if end <= resting || end <= from || self.count == MAX_STIFFENINGS {
            return false;
        }
        let sink = (end - from).min(resting);
        let held_at = (0.5 * resting).clamp(from + 0.1 * sink, from + 0.5 * sink);
        let push = |depth| self.penalty(base, depth).map_or(0.0, |p| p.push);
        let stiffness = (push(end) - push(held_at)) / (held_at - from);
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return false;
        }
        match self.hinges[..self.count].iter_mut().find(|h| h.0 == from) {
            Some(same) => same.1 += stiffness,
            None => {
                self.hinges[self.count] = (from, stiffness);
                self.count += 1;
            }
        }
        true
    }

    /// The stiffenings so far: depth (m) and stiffness (N/m).
    fn hinges(&self) -> &[(f64, f64)] {
        &self.hinges[..self.count]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stiffening_leaves_the_start_depths_energy_and_holds_the_load_where_it_says() {
        let (base, resting) = (1e3, 1e-3);
        // A load of 10 N held by the base alone at 10 mm, from a start 0.2 mm deep: held at
        // half the resting depth; from 0.8 mm: a tenth of the resting depth beyond the start.
        for (start, held_at) in [(0.2e-3, 0.5e-3), (0.8e-3, 0.9e-3)] {
            let mut stiffening = Stiffening::default();
            let before = stiffening.penalty(base, start).unwrap();
            assert!(stiffening.stiffen(base, (start, 10e-3), resting));
            let after = stiffening.penalty(base, start).unwrap();
            assert_eq!(before, after);
            let held = stiffening.penalty(base, held_at).unwrap();
            assert!((held.push - 10.0).abs() < 1e-12, "{}", held.push);
        }
        let mut stiffening = Stiffening::default();
        assert!(stiffening.stiffen(base, (0.8e-3, 10e-3), resting));
        // Energy is the integral of the push: a central difference agrees to 1e-9 N.
        let d = 1.1e-3;
        let slope = (stiffening.penalty(base, d + 1e-9).unwrap().energy
            - stiffening.penalty(base, d - 1e-9).unwrap().energy)
            / 2e-9;
        assert!((slope - stiffening.penalty(base, d).unwrap().push).abs() < 1e-6);
        // A point no deeper than the resting depth is left alone, as is one that rose.
        assert!(!stiffening.stiffen(base, (0.5e-3, 0.9e-3), resting));
        assert!(!stiffening.stiffen(base, (5e-3, 4e-3), resting));
    }

    #[test]
    fn the_piece_towards_a_depth_is_the_penalty_there_and_extends_it_as_one_quadratic() {
        let (base, resting) = (1e3, 1e-3);
        let mut stiffening = Stiffening::default();
        assert!(stiffening.stiffen(base, (0.2e-3, 10e-3), resting));
        for (from, to) in [
            (-1e-3, 0.1e-3),
            (-1e-3, 3e-3),
            (0.1e-3, 3e-3),
            (0.3e-3, 0.5e-3),
        ] {
            let (push, stiffness) = stiffening.piece_towards(base, (from, to)).unwrap();
            // One quadratic: at `to` its push and stiffness are the penalty's there.
            let there = stiffening.penalty(base, to).unwrap();
            assert!((push + stiffness * (to - from) - there.push).abs() < 1e-12);
            assert_eq!(stiffness, there.stiffness);
        }
        // In front of the plane no piece holds.
        assert!(stiffening.piece_towards(base, (1e-3, -1e-4)).is_none());
    }

    #[test]
    fn a_contact_takes_at_most_its_stiffenings() {
        let mut stiffening = Stiffening::default();
        let mut taken = 0;
        for i in 0..10 {
            let start = 2e-3 * f64::from(i);
            taken += usize::from(stiffening.stiffen(1.0, (start, start + 1.0), 1e-3));
        }
        assert_eq!(taken, MAX_STIFFENINGS);
    }
}

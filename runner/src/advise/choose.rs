//! The choice: a cheap set of changes whose errors, added, stay within the target.
//!
//! Each change was measured alone against the scene as written: its error `eᵢ` (largest
//! probe error) and its time per frame `cᵢ` against the reference's `c₀`. Changes enter
//! greedily, largest saving `c₀ − cᵢ` first, one per [`Group`], while `Σ eᵢ ≤ target` (greedy:
//! not always the cheapest set, which is a knapsack problem): the predicted error of the set is
//! that sum (a bound when the changes' effects on the probes add, by the triangle inequality;
//! changes that act together can exceed it, which the set's run measures), its predicted time
//! per frame `c₀ Π (cᵢ / c₀)` (each change scales the part of the step it touches).

use super::candidates::Group;
use std::collections::HashSet;

/// What a change is held to: the scene as written's time per frame (ms), the smallest relative
/// saving counted, and the target (the largest relative error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// The scene as written's time per frame (ms).
    pub reference_ms: f64,
    /// The smallest saving counted, relative to `reference_ms`.
    pub saving: f64,
    /// The largest probe error allowed (relative).
    pub target: f64,
}

impl Limits {
    /// Whether `ms_per_frame` saves at least the smallest saving counted.
    pub fn cheaper(&self, ms_per_frame: f64) -> bool {
        ms_per_frame < self.reference_ms * (1.0 - self.saving)
    }
}

/// A change measured alone: its group, error and time per frame (ms).
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// What it changes.
    pub group: Group,
    /// Its largest probe error against the reference (relative).
    pub error: f64,
    /// Its time per frame (ms).
    pub ms_per_frame: f64,
    /// Whether its run was the reference's to the bit: the same probes and every soft body's
    /// same peak strain and rotation (a setting the scene does not use).
    pub identical: bool,
}

/// The indices into `changes` of the greedy choice within `limits`: changes at least the
/// smallest saving cheaper than the reference, largest saving first, one per group, while their
/// errors add up to at most the target. A change whose run was the
/// reference's to the bit changed nothing this scene does (a setting its bodies do not use): a
/// time it measured lower is noise, and it is not chosen. (A change to a body no probe watches
/// has zero error too, but its run differs: it is chosen on its saving.)
pub fn choose(changes: &[Option<Measured>], limits: Limits) -> Vec<usize> {
    let mut eligible: Vec<(usize, &Measured)> = (changes.iter().enumerate())
        .filter_map(|(i, m)| Some((i, m.as_ref()?)))
        .filter(|(_, m)| !m.identical && m.error <= limits.target)
        .filter(|(_, m)| limits.cheaper(m.ms_per_frame))
        .collect();
    eligible.sort_by(|a, b| a.1.ms_per_frame.total_cmp(&b.1.ms_per_frame));
    let mut used = HashSet::new();
    let mut budget = limits.target;
    let mut chosen = Vec::new();
    for (i, m) in eligible {
        if m.error <= budget && used.insert(m.group.clone()) {
            budget -= m.error;
            chosen.push(i);
        }
    }
    chosen
}

/// The predicted error (the sum) and time per frame (ms) of the changes `chosen`.
pub fn predict(changes: &[Option<Measured>], chosen: &[usize], reference_ms: f64) -> (f64, f64) {
    let measured = chosen.iter().filter_map(|i| changes[*i].as_ref());
    measured.fold((0.0, reference_ms), |(error, ms), m| {
        (error + m.error, ms * m.ms_per_frame / reference_ms)
    })
}

/// `chosen` without its change of largest `key` (a change not measured counts as infinite):
/// of largest error, or of smallest saving (largest time per frame alone).
pub fn without_largest(
    changes: &[Option<Measured>],
    chosen: &[usize],
    key: impl Fn(&Measured) -> f64,
) -> Vec<usize> {
    let value = |i: &usize| changes[*i].as_ref().map_or(f64::INFINITY, &key);
    let largest = chosen
        .iter()
        .max_by(|a, b| value(a).total_cmp(&value(b)))
        .copied();
    chosen
        .iter()
        .copied()
        .filter(|i| Some(*i) != largest)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(group: Group, error: f64, ms_per_frame: f64) -> Option<Measured> {
        let identical = error == 0.0 && ms_per_frame == 1.0;
        Some(Measured {
            group,
            error,
            ms_per_frame,
            identical,
        })
    }

    #[test]
    fn the_largest_savings_enter_one_per_group_within_the_target() {
        let changes = [
            measured(Group::Model(0), 0.02, 6.0),
            measured(Group::Model(0), 0.001, 8.0),
            measured(Group::Model(1), 0.04, 5.0),
            measured(Group::Integrator, 0.02, 9.0),
            measured(Group::Resolution(1), 0.01, 9.9),
            measured(Group::Tolerance, 0.0, 1.0),
            None,
        ];
        // Cheapest first: Model(1) at 5 ms (0.04), Model(0) at 6 ms would exceed 0.05, the
        // next Model(0) at 8 ms fits (0.041), the integrator at 9 ms does not (0.061); the
        // coarser mesh saves under the 3 % threshold; the tolerance ran the reference's run.
        let limits = Limits {
            reference_ms: 10.0,
            saving: 0.03,
            target: 0.05,
        };
        let chosen = choose(&changes, limits);
        assert_eq!(chosen, [2, 1]);
        let (error, ms) = predict(&changes, &chosen, 10.0);
        assert!(
            (error - 0.041).abs() < 1e-15 && (ms - 4.0).abs() < 1e-12,
            "{error} {ms}"
        );
        assert_eq!(without_largest(&changes, &chosen, |m| m.error), [1]);
        assert_eq!(without_largest(&changes, &chosen, |m| m.ms_per_frame), [2]);
    }
}

//! What a soft body's steps cost, for `report.json`: the automatic integrator's predictions
//! beside the time its steps measured (ms), per integrator in all and as the median of each
//! step's ratio, and what an implicit step did (Newton iterations, factorizations, evaluations
//! of the energy).

use rapier_fvm::integrate::{AutomaticReport, ImplicitReport, IntegratorKind};
use serde::Serialize;

/// What a soft body's coupling substeps cost (the last of each frame, whose report the frame
/// returns), means over the frames in ms: the automatic integrator's predictions
/// ([`rapier_fvm::integrate::CostModel`]) of an explicit and an implicit step, its prediction
/// for the integrator it used, and the time the integration measured; then the same ratio over
/// the steps each integrator took alone (a step redone by the other integrator, which ran both,
/// is in neither).
#[derive(Debug, Clone, Default, Serialize)]
pub struct StepCost {
    /// Predicted explicit step (ms).
    pub predicted_explicit_ms: f64,
    /// Predicted implicit step (ms).
    pub predicted_implicit_ms: f64,
    /// Predicted step of the integrator used (ms).
    pub predicted_ms: f64,
    /// Measured step (ms).
    pub measured_ms: f64,
    /// Measured over predicted.
    pub measured_over_predicted: f64,
    /// The explicit steps: their measured over their predicted time.
    pub explicit: IntegratorCost,
    /// The implicit steps: their measured over their predicted time.
    pub implicit: IntegratorCost,
    /// What an implicit step did, on average: where its time went.
    pub implicit_work: NewtonWork,
    #[serde(skip)]
    steps: f64,
}

/// The steps one integrator took: how many, their measured time over their predicted one, and
/// the median of that ratio step by step (a prediction from the body's recent steps cannot
/// foresee an impact's step, which may cost tens of times its neighbours; the median is what a
/// typical step measured against its prediction).
#[derive(Debug, Clone, Default, Serialize)]
pub struct IntegratorCost {
    /// Steps taken.
    pub steps: u64,
    /// Their measured time over their predicted time (zero without steps).
    pub measured_over_predicted: f64,
    /// The median over the steps of each one's measured over predicted time (zero without
    /// steps).
    pub median_measured_over_predicted: f64,
    #[serde(skip)]
    predicted: f64,
    #[serde(skip)]
    measured: f64,
    /// Each step's measured over predicted time, in increasing order.
    #[serde(skip)]
    ratios: Vec<f64>,
}

impl IntegratorCost {
    /// Takes in a step predicted at `predicted` that took `measured` (s).
    fn record(&mut self, predicted: f64, measured: f64) {
        self.steps += 1;
        self.predicted += predicted;
        self.measured += measured;
        if predicted > 0.0 {
            self.measured_over_predicted = self.measured / self.predicted;
            let ratio = measured / predicted;
            let at = self.ratios.partition_point(|r| *r < ratio);
            self.ratios.insert(at, ratio);
            self.median_measured_over_predicted = median(&self.ratios);
        }
    }
}

/// Means over a body's implicit steps of what each did (see
/// [`rapier_fvm::integrate::ImplicitReport`]).
#[derive(Debug, Clone, Default, Serialize)]
pub struct NewtonWork {
    /// Newton iterations.
    pub newton_iterations: f64,
    /// Numeric Cholesky factorizations.
    pub factorizations: f64,
    /// Evaluations of the energy (each Newton solve's start and its line searches).
    pub energy_evaluations: f64,
    #[serde(skip)]
    steps: f64,
}

impl NewtonWork {
    /// Takes in an implicit step's `report`.
    fn record(&mut self, report: &ImplicitReport) {
        self.steps += 1.0;
        let counts = [
            (&mut self.newton_iterations, report.newton_iterations),
            (&mut self.factorizations, report.factorizations),
            (&mut self.energy_evaluations, report.energy_evaluations),
        ];
        for (mean, count) in counts {
            *mean += (count as f64 - *mean) / self.steps;
        }
    }
}

/// The median of the sorted `values` (the mean of the middle two for an even count).
fn median(values: &[f64]) -> f64 {
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

impl StepCost {
    /// Takes in a step's `report`.
    pub(super) fn record(&mut self, report: &AutomaticReport) {
        let p = &report.prediction;
        let used = p.seconds(report.choice);
        let mean = |mean: &mut f64, seconds: f64, steps: f64| {
            *mean += (seconds * 1e3 - *mean) / steps;
        };
        self.steps += 1.0;
        mean(
            &mut self.predicted_explicit_ms,
            p.explicit_seconds,
            self.steps,
        );
        mean(
            &mut self.predicted_implicit_ms,
            p.implicit_seconds,
            self.steps,
        );
        mean(&mut self.predicted_ms, used, self.steps);
        mean(&mut self.measured_ms, report.seconds, self.steps);
        self.measured_over_predicted = self.measured_ms / self.predicted_ms;
        if !report.fell_back {
            let taken = match report.choice {
                IntegratorKind::Explicit => &mut self.explicit,
                IntegratorKind::Implicit => &mut self.implicit,
            };
            taken.record(used, report.seconds);
        }
        if let Some(implicit) = &report.implicit {
            self.implicit_work.record(implicit);
        }
    }
}

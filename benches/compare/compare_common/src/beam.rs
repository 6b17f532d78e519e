//! The cantilever scenes' measures (1-3): the settled tip against Timoshenko's deflection and
//! the fitted free vibration against his first frequency, from the mean vertical displacement
//! of the tip face after every step.

use crate::fit::fit_damped_oscillation;
use crate::record::{self, Record};
use crate::reference::{
    BEAM_NU, beam_eb_frequency, beam_eb_tip, beam_timoshenko_frequency, beam_timoshenko_tip,
    rel_error,
};
use serde_json::{Value, json};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Simulated time of a static case; the tip is averaged over its last [`TAIL_S`].
pub const SETTLE_S: f64 = 1.5;
/// Averaging window at the end of a static case (s).
pub const TAIL_S: f64 = 0.25;
/// Simulated time of a vibration case (s).
pub const VIBRATION_S: f64 = 2.0;
/// Elements of the Timoshenko frequency reference (converged to ~1e-5).
const TIMOSHENKO_ELEMENTS: usize = 400;

/// A static case's tip, measured over the last [`TAIL_S`] of a run at Poisson's ratio `nu`.
pub struct StaticTip {
    /// The mean tip deflection (downward positive); `None` for a run that did not complete.
    pub tip: Option<f64>,
    /// The tip's drift over the averaging window.
    pub drift: Option<f64>,
    /// Completed, and settled downward within 10x the reference: a physical equilibrium.
    pub stable: bool,
    /// Timoshenko's deflection at `nu`.
    reference: f64,
}

impl StaticTip {
    /// Measures the tip of `us` (displacement at the times `ts`); `completed`: the run reached
    /// [`SETTLE_S`] without a failure.
    pub fn measure(ts: &[f64], us: &[f64], completed: bool, nu: f64) -> Self {
        let reference = beam_timoshenko_tip(nu);
        let tail: Vec<f64> = ts
            .iter()
            .zip(us)
            .filter(|(t, _)| **t > SETTLE_S - TAIL_S + 1e-9)
            .map(|(_, u)| *u)
            .collect();
        let ok = completed && !tail.is_empty();
        let tip = ok.then(|| -tail.iter().sum::<f64>() / tail.len() as f64);
        let drift = (ok && tail.len() > 1).then(|| (tail[tail.len() - 1] - tail[0]).abs());
        // Moved against gravity or ran away: not a physical equilibrium.
        let stable = ok && tip.is_some_and(|t| 0.0 < t && t < 10.0 * reference);
        StaticTip {
            tip,
            drift,
            stable,
            reference,
        }
    }

    /// The line's references and measures; `settled`: the drift is below 1 % of the reference.
    pub fn fields(&self) -> Value {
        let (tip, reference) = (self.tip, self.reference);
        json!({
            "reference": reference,
            "reference_name": "Timoshenko q L^4/(8EI) + q L^2/(2 kappa G A), kappa = 10(1+nu)/(12+11nu)",
            "reference_euler_bernoulli": beam_eb_tip(),
            "tip_deflection": tip,
            "error": if self.stable { rel_error(tip, reference) } else { None },
            "error_vs_euler_bernoulli": if self.stable { rel_error(tip, beam_eb_tip()) } else { None },
            "tip_drift_last_0_25s": self.drift,
            "settled": self.drift.is_some_and(|d| d < 0.01 * reference),
            "stable": self.stable,
        })
    }
}

/// The settings every vibration case adds: no damping, the duration and the excitation.
pub fn vibration_settings() -> Record {
    record::object(json!({
        "damping_beta": 0.0,
        "duration_s": VIBRATION_S,
        "excitation": "released straight under gravity (oscillates about the static deflection)",
    }))
}

/// A vibration case's references and measures: a damped-oscillation fit of `us` (displacement
/// at the times `ts`, fitted only if `completed`) against Timoshenko's first frequency; all the
/// damping is numerical (the beam has none).
pub fn vibration_fields(ts: &[f64], us: &[f64], completed: bool, dt: f64) -> Value {
    let reference = timoshenko_first_frequency();
    let fit = if completed {
        fit_damped_oscillation(ts, us)
    } else {
        None
    };
    let freq = fit.as_ref().map(|f| f.frequency_hz);
    let zeta = fit.as_ref().map(|f| f.damping_ratio);
    json!({
        "reference": reference,
        "reference_name": "Timoshenko first bending frequency (shear + rotary inertia, \
                           400-element solve); Euler-Bernoulli (1.8751^2/(2 pi L^2)) sqrt(EI/(rho A))",
        "reference_euler_bernoulli": beam_eb_frequency(),
        "first_frequency_hz": freq,
        "error": rel_error(freq, reference),
        "damping_ratio": zeta,
        "numerical_damping_ratio": zeta,
        "damping_ratio_omega_dt_over_2": 2.0 * PI * reference * dt / 2.0,
        "fit": fit.as_ref().map(|f| f.to_json()),
        "stable": completed && fit.is_some(),
    })
}

/// Timoshenko's first frequency of the vibration scene's beam (Hz), solved once.
fn timoshenko_first_frequency() -> f64 {
    static HZ: OnceLock<f64> = OnceLock::new();
    *HZ.get_or_init(|| beam_timoshenko_frequency(BEAM_NU, TIMOSHENKO_ELEMENTS))
}

//! Least-squares fit of a damped oscillation `u(t) = c + exp(-s t)(a cos wt + b sin wt)`, the
//! same grid search as `fit_damped_oscillation` in `common.py`.

use nalgebra::{Matrix3, Vector3};
use serde_json::{Value, json};
use std::f64::consts::PI;

/// The fitted oscillation.
pub struct Fit {
    /// Undamped natural frequency `sqrt(w^2 + s^2) / 2 pi` (Hz).
    pub frequency_hz: f64,
    /// Damped frequency `w / 2 pi` (Hz).
    pub damped_frequency_hz: f64,
    /// Damping ratio `s / sqrt(w^2 + s^2)`.
    pub damping_ratio: f64,
    /// The equilibrium `c`.
    pub equilibrium: f64,
    /// RMS residual over the signal's standard deviation.
    pub fit_residual_rel: f64,
}

impl Fit {
    /// The `fit` object of a vibration line.
    pub fn to_json(&self) -> Value {
        json!({
            "frequency_hz": self.frequency_hz,
            "damped_frequency_hz": self.damped_frequency_hz,
            "damping_ratio": self.damping_ratio,
            "equilibrium": self.equilibrium,
            "fit_residual_rel": self.fit_residual_rel,
        })
    }
}

/// Fits `u` sampled at the uniformly spaced times `t`: a coarse search over log-spaced
/// frequencies up to 0.9 Nyquist and damping ratios 0..0.95, then four zooms around the best.
/// `None` for fewer than 8 samples, a non-finite or a constant signal.
pub fn fit_damped_oscillation(t: &[f64], u: &[f64]) -> Option<Fit> {
    let n = u.len();
    let (lo, hi) = u
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if n < 8 || u.iter().any(|v| !v.is_finite()) || hi == lo {
        return None;
    }
    let dt = t[1] - t[0];
    let (wmin, wmax) = (2.0 * PI / (t[n - 1] - t[0]), 0.9 * PI / dt);
    let mut best = Best::default();
    for w in geomspace(wmin, wmax, 120) {
        for z in linspace(0.0, 0.95, 20) {
            best.consider(t, u, w, z * w / (1.0 - z * z).sqrt());
        }
    }
    let (w, s) = (best.w, best.s);
    let (mut wlo, mut whi) = (w / 1.1, w * 1.1);
    let (mut slo, mut shi) = ((s - 0.2 * w).max(0.0), s + 0.2 * w);
    for _ in 0..4 {
        for w in linspace(wlo, whi, 31) {
            for s in linspace(slo, shi, 31) {
                best.consider(t, u, w, s);
            }
        }
        let (w, s) = (best.w, best.s);
        let (dw, ds) = ((whi - wlo) / 10.0, (shi - slo) / 10.0);
        (wlo, whi, slo, shi) = ((w - dw).max(1e-6), w + dw, (s - ds).max(0.0), s + ds);
    }
    let Best { r, w, s, coef } = best;
    let wn = w.hypot(s);
    let mean = u.iter().sum::<f64>() / n as f64;
    let std = (u.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    Some(Fit {
        frequency_hz: wn / (2.0 * PI),
        damped_frequency_hz: w / (2.0 * PI),
        damping_ratio: s / wn,
        equilibrium: coef[0],
        fit_residual_rel: (r / n as f64).sqrt() / (std + 1e-300),
    })
}

/// The best `(w, s)` so far, its residual and coefficients.
struct Best {
    r: f64,
    w: f64,
    s: f64,
    coef: Vector3<f64>,
}

impl Default for Best {
    /// No fit yet: an infinite residual.
    fn default() -> Self {
        Best {
            r: f64::MAX,
            w: 0.0,
            s: 0.0,
            coef: Vector3::zeros(),
        }
    }
}

impl Best {
    /// Keeps `(w, s)` if its fit beats the best so far.
    fn consider(&mut self, t: &[f64], u: &[f64], w: f64, s: f64) {
        let (r, coef) = fit_fixed(t, u, w, s);
        if r < self.r {
            *self = Best { r, w, s, coef };
        }
    }
}

/// Linear least squares for `(c, a, b)` at fixed `w` and `s`: the residual sum of squares and
/// the coefficients (normal equations, solved by SVD so a degenerate basis gives the
/// minimum-norm answer as numpy's `lstsq` does).
fn fit_fixed(t: &[f64], u: &[f64], w: f64, s: f64) -> (f64, Vector3<f64>) {
    let basis = |ti: f64| {
        let e = (-s * ti).exp();
        Vector3::new(1.0, e * (w * ti).cos(), e * (w * ti).sin())
    };
    let mut ata = Matrix3::zeros();
    let mut atu = Vector3::zeros();
    for (&ti, &ui) in t.iter().zip(u) {
        let x = basis(ti);
        ata += x * x.transpose();
        atu += x * ui;
    }
    let coef = ata
        .svd(true, true)
        .solve(&atu, 1e-12 * ata.norm())
        .unwrap_or_else(|_| Vector3::zeros());
    let r = t
        .iter()
        .zip(u)
        .map(|(&ti, &ui)| (ui - basis(ti).dot(&coef)).powi(2))
        .sum();
    (r, coef)
}

/// `n` evenly spaced values from `a` to `b` inclusive.
fn linspace(a: f64, b: f64, n: usize) -> impl Iterator<Item = f64> {
    (0..n).map(move |k| a + (b - a) * k as f64 / (n - 1) as f64)
}

/// `n` log-spaced values from `a` to `b` inclusive.
fn geomspace(a: f64, b: f64, n: usize) -> impl Iterator<Item = f64> {
    linspace(a.ln(), b.ln(), n).map(f64::exp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_damped_oscillation() {
        let t: Vec<f64> = (0..481).map(|k| k as f64 * 2.0 / 480.0).collect();
        let u: Vec<f64> = t
            .iter()
            .map(|&t| 0.3 + (-0.5 * t).exp() * (2.0 * PI * 5.0 * t).cos())
            .collect();
        let fit = fit_damped_oscillation(&t, &u).unwrap();
        let wn = (2.0 * PI * 5.0_f64).hypot(0.5);
        assert!((fit.frequency_hz - wn / (2.0 * PI)).abs() < 1e-3);
        assert!((fit.damping_ratio - 0.5 / wn).abs() < 1e-4);
        assert!((fit.equilibrium - 0.3).abs() < 1e-4);
    }
}

//! The contact scenes' measures (4-5) from what a run records after every frame: the dropped
//! cube's resting height and penetration, and how far the box sinks into the block.

use crate::reference::{BLOCK_SIZE, BOX_SIZE, drop_rest_centroid, rel_error};
use crate::stats::{mean, min, std};
use serde_json::{Value, json};

/// Frame step of both scenes (s).
pub const DT: f64 = 1.0 / 240.0;
/// The last half second is the resting window.
pub const REST_S: f64 = 0.5;

/// Where the resting window starts in a trace of `frames` frames.
fn rest_start(frames: usize) -> usize {
    frames.saturating_sub((REST_S / DT).round() as usize)
}

/// The dropped cube's lowest and mean node (particle) height after every frame.
#[derive(Default)]
pub struct DropTrace {
    lowest: Vec<f64>,
    centroid: Vec<f64>,
}

impl DropTrace {
    /// Records a frame's node heights (not empty).
    pub fn push(&mut self, heights: &[f64]) {
        self.lowest
            .push(heights.iter().copied().fold(f64::MAX, f64::min));
        self.centroid
            .push(heights.iter().sum::<f64>() / heights.len() as f64);
    }

    /// The lowest height over the run.
    pub fn lowest(&self) -> f64 {
        min(&self.lowest)
    }

    /// The line's reference and measures; all null but `stable` for an unstable run.
    pub fn fields(&self, stable: bool) -> Value {
        let rest = rest_start(self.lowest.len());
        let reference = drop_rest_centroid();
        let h = stable.then(|| mean(&self.centroid[rest..]));
        json!({
            "reference": reference,
            "reference_name": "resting centroid height H/2 - rho g H^2/(3E) (uniaxial, frictionless ground)",
            "resting_centroid_height": h,
            "error": rel_error(h, reference),
            "centroid_rest_std": stable.then(|| std(&self.centroid[rest..])),
            "peak_penetration": stable.then(|| (-self.lowest()).max(0.0)),
            "resting_penetration": stable.then(|| -mean(&self.lowest[rest..])),
            "stable": stable,
        })
    }
}

/// The box's height and vertical velocity after every frame, how far it is below the highest
/// block node under it, and how far those nodes sank on average.
#[derive(Default)]
pub struct BoxTrace {
    height: Vec<f64>,
    velocity: Vec<f64>,
    penetration: Vec<f64>,
    dent: Vec<f64>,
}

impl BoxTrace {
    /// Records a frame: the box centre's `height` and vertical `velocity`, and the heights of
    /// the block's top nodes under the box, `top`, now and at the start, `top0`.
    pub fn push(&mut self, height: f64, velocity: f64, top: &[f64], top0: &[f64]) {
        let hb = BOX_SIZE / 2.0;
        self.height.push(height);
        self.velocity.push(velocity);
        self.penetration
            .push(top.iter().fold(f64::MIN, |m, t| m.max(t - (height - hb))));
        self.dent
            .push(top0.iter().zip(top).map(|(a, b)| a - b).sum::<f64>() / top.len() as f64);
    }

    /// The line's measures (no closed form); all null but `stable` for an unstable run.
    pub fn fields(&self, stable: bool) -> Value {
        let rest = rest_start(self.height.len());
        let (top, hb) = (BLOCK_SIZE[2], BOX_SIZE / 2.0);
        json!({
            "reference": null, "error": null,
            "sink": stable.then(|| top - (mean(&self.height[rest..]) - hb)),
            "penetration": stable.then(|| mean(&self.penetration[rest..])),
            "surface_sink": stable.then(|| mean(&self.dent[rest..])),
            "vertical_velocity_std": stable.then(|| std(&self.velocity[rest..])),
            "stable": stable,
        })
    }
}

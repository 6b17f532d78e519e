//! The element side of the audit: each element's volume ratio after a frame
//! ([`DeformableBody::element_volume_ratios`]: `J = V / V₀` for a linear tetrahedron, the
//! smallest `det F` at the quadrature points of a quadratic element). An element is *inverted*
//! at `J ≤ 0` and *collapsed* at `0 < J < J_min`
//! ([`AuditSettings::collapse_ratio`](super::AuditSettings::collapse_ratio)).

use crate::body::DeformableBody;

/// What the elements of a body look like after a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ElementState {
    pub(super) inverted: usize,
    pub(super) collapsed: usize,
    pub(super) smallest_ratio: f64,
}

/// The inverted and collapsed (`0 < J < collapse_ratio`) elements of `body`, and its smallest
/// volume ratio `J`.
pub(super) fn element_state(body: &DeformableBody, collapse_ratio: f64) -> ElementState {
    let mut state = ElementState {
        inverted: 0,
        collapsed: 0,
        smallest_ratio: f64::INFINITY,
    };
    for ratio in body.element_volume_ratios() {
        state.smallest_ratio = state.smallest_ratio.min(ratio);
        if ratio <= 0.0 || ratio.is_nan() {
            state.inverted += 1;
        } else if ratio < collapse_ratio {
            state.collapsed += 1;
        }
    }
    state
}

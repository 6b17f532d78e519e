//! The element side of the audit: each tetrahedron's volume after a frame over its rest volume,
//! `J = V / V₀`. An element is *inverted* at `J ≤ 0` and *collapsed* at `0 < J < J_min`
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
    let mesh = body.mesh();
    let mut state = ElementState {
        inverted: 0,
        collapsed: 0,
        smallest_ratio: f64::INFINITY,
    };
    for (t, tet) in mesh.tets().iter().enumerate() {
        let ratio = crate::mesh::signed_volume(body.positions(), tet) / mesh.tet_volume(t);
        state.smallest_ratio = state.smallest_ratio.min(ratio);
        if ratio <= 0.0 || ratio.is_nan() {
            state.inverted += 1;
        } else if ratio < collapse_ratio {
            state.collapsed += 1;
        }
    }
    state
}

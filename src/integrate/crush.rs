//! Crushed elements: an element is *crushed* when its volume ratio is below [`COLLAPSE_RATIO`],
//! `J < J_min` (inverted at `J ≤ 0`, collapsed at `0 < J < J_min`), with `J = V / V₀` for a
//! linear tetrahedron and the smallest `det F` at its quadrature points for a quadratic element
//! ([`DeformableBody::element_volume_ratios`]).
//! No solid is compressed so far; a step that leaves an element so has carried the body past what
//! its material model describes (a soft body struck faster than its material can stop it: the
//! stable Neo-Hookean energy is finite at zero volume, so such an impact flattens elements and
//! turns them inside out). Contract: a step that crushes an element which was not crushed when
//! the step began is refused with [`Error::ElementCrushed`] and the state before it kept.
//! Elements already crushed at the start (a state set so by the user) are left to the
//! inversion-robust models to recover.

use crate::Error;
use crate::body::DeformableBody;

/// The volume ratio `J_min` below which an element is crushed (dimensionless): 1 % of the rest
/// volume.
pub const COLLAPSE_RATIO: f64 = 1e-2;

/// Each element's volume ratio `J` at the body's positions
/// ([`DeformableBody::element_volume_ratios`]), with its index.
fn volume_ratios(body: &DeformableBody) -> impl Iterator<Item = (usize, f64)> {
    body.element_volume_ratios().into_iter().enumerate()
}

/// Whether the volume ratio `ratio` is crushed (a NaN is).
fn crushed(ratio: f64) -> bool {
    ratio.is_nan() || ratio < COLLAPSE_RATIO
}

/// The elements crushed when a step began, to tell the step's own crushing from them.
pub(crate) struct CrushWatch {
    /// Indices of the elements crushed at the start, ascending.
    crushed_at_start: Vec<usize>,
}

impl CrushWatch {
    /// Notes the elements of `body` crushed now, before a step.
    pub(crate) fn new(body: &DeformableBody) -> Self {
        Self {
            crushed_at_start: volume_ratios(body)
                .filter(|&(_, ratio)| crushed(ratio))
                .map(|(t, _)| t)
                .collect(),
        }
    }

    /// After the step: the number of inverted elements (`J ≤ 0`) of `body`.
    ///
    /// # Errors
    /// [`Error::ElementCrushed`] for the first element crushed now that was not at the start.
    pub(crate) fn check(&self, body: &DeformableBody) -> Result<usize, Error> {
        let mut inverted = 0;
        for (t, ratio) in volume_ratios(body) {
            inverted += usize::from(ratio.is_nan() || ratio <= 0.0);
            if crushed(ratio) && self.crushed_at_start.binary_search(&t).is_err() {
                return Err(Error::ElementCrushed {
                    element: t,
                    volume_ratio: ratio,
                });
            }
        }
        Ok(inverted)
    }
}

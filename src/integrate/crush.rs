//! Crushed elements: a tetrahedron is *crushed* when its volume is below [`COLLAPSE_RATIO`] of its
//! rest volume, `J = V / V₀ < J_min` (inverted at `J ≤ 0`, collapsed at `0 < J < J_min`).
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

/// Each tetrahedron's volume over its rest volume, `J = V / V₀`, at the body's positions.
fn volume_ratios(body: &DeformableBody) -> impl Iterator<Item = (usize, f64)> + '_ {
    let mesh = body.mesh();
    mesh.tets().iter().enumerate().map(move |(t, tet)| {
        let ratio = crate::mesh::signed_volume(body.positions(), tet) / mesh.tet_volume(t);
        (t, ratio)
    })
}

/// Whether the volume ratio `ratio` is crushed (a NaN is).
fn crushed(ratio: f64) -> bool {
    ratio.is_nan() || ratio < COLLAPSE_RATIO
}

/// The elements crushed when a step began, to tell the step's own crushing from them.
pub(crate) struct CrushWatch {
    /// Indices of the tetrahedra crushed at the start, ascending.
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

    /// After the step: the number of inverted tetrahedra (`J ≤ 0`) of `body`.
    ///
    /// # Errors
    /// [`Error::ElementCrushed`] for the first tetrahedron crushed now that was not at the start.
    pub(crate) fn check(&self, body: &DeformableBody) -> Result<usize, Error> {
        let mut inverted = 0;
        for (t, ratio) in volume_ratios(body) {
            inverted += usize::from(ratio.is_nan() || ratio <= 0.0);
            if crushed(ratio) && self.crushed_at_start.binary_search(&t).is_err() {
                return Err(Error::ElementCrushed {
                    tet: t,
                    volume_ratio: ratio,
                });
            }
        }
        Ok(inverted)
    }
}

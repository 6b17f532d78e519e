//! The numeric bounds every mesh and every nodal state stays within: coordinates within
//! ±[`MAX_COORDINATE`] m, so that no product of an element's computations can overflow `f64`,
//! and speeds below [`SPEED_OF_LIGHT`], beyond which the step's Newtonian mechanics means
//! nothing. Meshes are checked when built, states when set and before every step; the errors
//! name these bounds.

/// The largest coordinate magnitude a mesh or a body may have (m).
///
/// Reason: the element computations multiply up to three coordinate differences (volumes,
/// `(b - a) × (c - a) · (d - a)`; an edge cubed in the degeneracy test), then scale them by
/// material constants and densities. Two nodes within ±1e100 m are at most `2√3·1e100 ≈ 3.5e100`
/// m apart, so a product of three such lengths stays below `4.2e301`, seven orders of magnitude
/// under `f64::MAX ≈ 1.8e308`, which leaves room for the constants. A node at `-9e307` m, by
/// contrast, overflows the first difference and makes its tetrahedron's volume NaN.
pub const MAX_COORDINATE: f64 = 1e100;

/// The speed of light in vacuum (m/s): no node may move faster.
///
/// Reason: no material point does, and the Newtonian mechanics the step integrates has lost its
/// meaning long before. Such a speed is not a state the step can resolve: on a 10 cm rubber cube
/// under the default `FvmWorld`, one node at 1e10 m/s (or 1e30 m/s)
/// overflowed the explicit attempt, and the implicit fallback ended its frame at rest, the speed
/// gone without an error.
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;

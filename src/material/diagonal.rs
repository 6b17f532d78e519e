//! Diagonalization of the deformation gradient for models written in its singular values: the
//! sign-fixed singular value decomposition `F = U diag(σ̂) Vᵀ` of Irving, Teran and Fedkiw
//! (2004), in which `U` and `V` are rotations and the smallest singular value is negated when
//! `det F < 0`, and the stress differential of an energy `ψ(σ̂)` that is a symmetric function of
//! the signed singular values (Teran, Sifakis, Irving and Fedkiw 2005).

use rapier3d::glamx::DMat3;
use rapier3d::na;

/// `F = U diag(σ̂) Vᵀ` with `U`, `V` proper rotations and `σ̂` the signed singular values
/// (dimensionless); only the smallest in magnitude may be negative.
pub(crate) struct SignedSvd {
    /// `U`, a rotation.
    pub u: na::Matrix3<f64>,
    /// `σ̂`, the singular values with the sign of `det F` on the smallest.
    pub sigma: na::Vector3<f64>,
    /// `Vᵀ`, a rotation.
    pub v_t: na::Matrix3<f64>,
}

/// The sign-fixed singular value decomposition of `f`. `None` only if the decomposition does not
/// provide `U` or `V`, which it always does when asked (as here).
pub(crate) fn signed_svd(f: &DMat3) -> Option<SignedSvd> {
    let m = na::Matrix3::from_column_slice(&f.to_cols_array());
    let svd = m.svd(true, true);
    let (Some(mut u), Some(mut v_t)) = (svd.u, svd.v_t) else {
        return None;
    };
    let mut sigma = svd.singular_values;
    let smallest = sigma.imin();
    if u.determinant() < 0.0 {
        u.column_mut(smallest).neg_mut();
        sigma[smallest] = -sigma[smallest];
    }
    if v_t.determinant() < 0.0 {
        v_t.row_mut(smallest).neg_mut();
        sigma[smallest] = -sigma[smallest];
    }
    Some(SignedSvd { u, sigma, v_t })
}

/// Below this gap (dimensionless) between two signed singular values, `(p_i - p_j)/(σ_i - σ_j)`
/// is taken from the Hessian instead, and sums `σ_i + σ_j` closer to zero are clamped to it: the
/// direct quotient would lose `ε/gap` of its digits, the Hessian form `gap²` (balanced near
/// `ε^(1/3)`, about 6e-6).
const REPEATED_GAP: f64 = 1e-5;

/// The stress `P = U diag(p) Vᵀ` (Pa) of an energy whose gradient in the signed singular values is
/// `p = ∂ψ/∂σ̂` (Pa).
pub(crate) fn diagonal_stress(svd: &SignedSvd, p: [f64; 3]) -> DMat3 {
    let scaled = svd.u * na::Matrix3::from_diagonal(&na::Vector3::from(p));
    DMat3::from_cols_slice((scaled * svd.v_t).as_slice())
}

/// `dP = (∂P/∂F) : dF` (Pa) of the stress of [`diagonal_stress`], given the gradient
/// `p = ∂ψ/∂σ̂` (Pa) and the Hessian `h[i][j] = ∂²ψ/∂σ̂_i∂σ̂_j` (Pa) of the symmetric energy.
///
/// With `M = Uᵀ dF V`, `dP = U dP̂ Vᵀ` where `dP̂_ii = Σ_j h_ij M_jj` and each off-diagonal pair
/// `(dP̂_ij, dP̂_ji)` is `[[a, b], [b, a]] (M_ij, M_ji)` with `a = (d + s)/2`, `b = (d - s)/2`,
/// `d = (p_i - p_j)/(σ_i - σ_j)` and `s = (p_i + p_j)/(σ_i + σ_j)`. For repeated singular values
/// `d` tends to `(h_ii + h_jj)/2 - h_ij`; `s` has no limit where `σ_i = -σ_j` (an inverted
/// element with its two smallest stretches equal), so its denominator is kept away from zero.
pub(crate) fn diagonal_stress_differential(
    svd: &SignedSvd,
    p: [f64; 3],
    h: [[f64; 3]; 3],
    df: &DMat3,
) -> DMat3 {
    let sigma = svd.sigma;
    let df = na::Matrix3::from_column_slice(&df.to_cols_array());
    let m = svd.u.transpose() * df * svd.v_t.transpose();
    let mut dp_hat = na::Matrix3::zeros();
    for i in 0..3 {
        dp_hat[(i, i)] = (0..3).map(|j| h[i][j] * m[(j, j)]).sum();
    }
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let gap = sigma[i] - sigma[j];
        let difference = if gap.abs() > REPEATED_GAP {
            (p[i] - p[j]) / gap
        } else {
            0.5 * (h[i][i] + h[j][j]) - h[i][j]
        };
        let total = sigma[i] + sigma[j];
        let total = if total.abs() > REPEATED_GAP {
            total
        } else {
            REPEATED_GAP.copysign(total)
        };
        let sum = (p[i] + p[j]) / total;
        let (a, b) = (0.5 * (difference + sum), 0.5 * (difference - sum));
        dp_hat[(i, j)] = a * m[(i, j)] + b * m[(j, i)];
        dp_hat[(j, i)] = b * m[(i, j)] + a * m[(j, i)];
    }
    DMat3::from_cols_slice((svd.u * dp_hat * svd.v_t).as_slice())
}

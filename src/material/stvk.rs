//! St. Venant–Kirchhoff: the linear law on the Green strain `G = (FᵀF - I)/2`,
//! `S = λ tr(G) I + 2 μ G`, `P = F S`, `Ψ = μ G:G + λ/2 tr(G)²`.
//!
//! In the signed singular values `σ̂` of `F` (see [`super::diagonal`]) the energy is
//! `Ψ = μ Σ g_i² + λ/2 (Σ g_i)²` with the principal Green strains `g_i = (σ̂_i² - 1)/2`. Each is
//! even in its stretch, so the stress of a strongly compressed element fades (`dg/dσ = σ`) and
//! an inverted one feels no restoring force. As proposed by Irving, Teran and Fedkiw (2004), every
//! principal strain below the stretch `c` ([`COMPRESSION_THRESHOLD`]) is replaced by a `C²`
//! continuation `ĝ` whose slope stays positive, so that the principal stresses keep pushing
//! toward positive volume at any compression and through inversion. Where every `σ̂_i > c`
//! (`det F > 0` and `FᵀF - c² I` positive definite, a cheap exact test) the closed form above is
//! evaluated unchanged; elsewhere energy, stress and differential come from the singular value
//! decomposition, and all three stay consistent derivatives of the one continued energy.

use super::diagonal::{SignedSvd, diagonal_stress, diagonal_stress_differential, signed_svd};
use super::{
    HyperelasticModel, LameParameters, double_dot, linear_law_lanes, symmetric_part, trace,
};
use crate::lanes::{LANES, Mat3x4, f64x4};
use rapier3d::glamx::DMat3;

/// Stretch `c` (dimensionless) below which a principal Green strain is continued. It lies above
/// `1/√3 ≈ 0.577`, where the uniaxial compressive stress of the plain model peaks and then
/// falls: with the continuation the stress along one stretch, the others at rest, grows
/// monotonically however far that stretch shrinks or inverts (its stiffness never drops below
/// `0.04 (λ + 2μ)`, the value at `c`).
const COMPRESSION_THRESHOLD: f64 = 0.6;

/// Decay length `k` (dimensionless) of the continuation
/// `ĝ(σ) = g(c) + (c - k)(σ - c) + k² (e^((σ - c)/k) - 1)` for `σ < c`, which matches `g` to the
/// second derivative at `c` and whose slope falls from `c` to `c - k = 0.45` under deep
/// compression, keeping the principal stress growing (see [`COMPRESSION_THRESHOLD`]).
const CONTINUATION_DECAY: f64 = COMPRESSION_THRESHOLD / 4.0;

/// St. Venant–Kirchhoff material with the given Lamé parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct StVenantKirchhoff(pub LameParameters);

/// The continued energy at given signed singular values: density, gradient and Hessian.
struct Diagonal {
    /// Energy density `ψ` (J/m^3).
    energy: f64,
    /// Gradient `∂ψ/∂σ̂_i` (Pa), the principal first Piola–Kirchhoff stresses.
    gradient: [f64; 3],
    /// Hessian `∂²ψ/∂σ̂_i∂σ̂_j` (Pa).
    hessian: [[f64; 3]; 3],
}

impl StVenantKirchhoff {
    /// Second Piola–Kirchhoff stress `S` (Pa) of a symmetric Green strain.
    #[inline(always)]
    fn second_piola(&self, green: &DMat3) -> DMat3 {
        let LameParameters { lambda, mu } = self.0;
        DMat3::IDENTITY * (lambda * trace(green)) + *green * (2.0 * mu)
    }

    /// `P(F) + F S_extra` (Pa) of each lane with the scalar stress, for blocks with a lane below
    /// the threshold. Out of line and on arrays built at the call, so that the hot SIMD path keeps
    /// its matrices in registers (a reference to them would pin them in memory).
    #[cold]
    #[inline(never)]
    fn first_piola_plus_by_lane(
        &self,
        f: &[DMat3; LANES],
        s_extra: &[DMat3; LANES],
    ) -> [DMat3; LANES] {
        std::array::from_fn(|l| self.first_piola(&f[l]) + f[l] * s_extra[l])
    }

    /// The continued energy at the signed singular values `sigma`: with the principal strains
    /// `ĝ_i` and stresses `S_i = 2μ ĝ_i + λ Σ ĝ`, `ψ = μ Σ ĝ_i² + λ/2 (Σ ĝ)²`,
    /// `∂ψ/∂σ̂_i = S_i ĝ'_i` and `∂²ψ/∂σ̂_i∂σ̂_j = (2μ δ_ij + λ) ĝ'_i ĝ'_j + δ_ij S_i ĝ''_i`.
    fn diagonal(&self, sigma: [f64; 3]) -> Diagonal {
        let LameParameters { lambda, mu } = self.0;
        let [g, dg, ddg] = {
            let principal = sigma.map(continued_green);
            [0, 1, 2].map(|k| principal.map(|p| p[k]))
        };
        let dilatation: f64 = g.iter().sum();
        let stress = g.map(|g| 2.0 * mu * g + lambda * dilatation);
        let energy = mu * g.iter().map(|g| g * g).sum::<f64>() + 0.5 * lambda * dilatation.powi(2);
        let hessian = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let diagonal = if i == j { 2.0 * mu } else { 0.0 };
                let curvature = if i == j { stress[i] * ddg[i] } else { 0.0 };
                (diagonal + lambda) * dg[i] * dg[j] + curvature
            })
        });
        Diagonal {
            energy,
            gradient: std::array::from_fn(|i| stress[i] * dg[i]),
            hessian,
        }
    }
}

/// A principal Green strain `ĝ(σ)` (dimensionless) of a signed stretch `σ`, with its first and
/// second derivatives: `(σ² - 1)/2` from [`COMPRESSION_THRESHOLD`] up, the continuation below.
#[inline]
fn continued_green(sigma: f64) -> [f64; 3] {
    let c = COMPRESSION_THRESHOLD;
    if sigma >= c {
        return [0.5 * (sigma * sigma - 1.0), sigma, 1.0];
    }
    let k = CONTINUATION_DECAY;
    let t = (sigma - c) / k;
    [
        0.5 * (c * c - 1.0) + (c - k) * (sigma - c) + k * k * t.exp_m1(),
        (c - k) + k * t.exp(),
        t.exp(),
    ]
}

/// Whether every signed singular value of `F` exceeds [`COMPRESSION_THRESHOLD`], so that the
/// closed form applies, from `ftf = FᵀF`: `det F > 0` and `FᵀF - c² I` positive definite (its
/// leading principal minors positive). False for a non-finite `F`.
#[inline(always)]
fn above_threshold(f: &DMat3, ftf: &DMat3) -> bool {
    let d = *ftf - DMat3::IDENTITY * (COMPRESSION_THRESHOLD * COMPRESSION_THRESHOLD);
    f.determinant() > 0.0 && super::is_positive_definite(&d)
}

/// The sign-fixed decomposition of `F` when the continued energy differs from the closed form
/// (some `σ̂_i <= c`); `None` when the closed form applies, including for a non-finite `F`, whose
/// closed form propagates the non-finite values.
#[inline(always)]
fn continued(f: &DMat3, ftf: &DMat3) -> Option<SignedSvd> {
    if above_threshold(f, ftf) || !f.is_finite() {
        None
    } else {
        signed_svd(f)
    }
}

/// Green strain `G = (FᵀF - I)/2`.
#[inline(always)]
pub(crate) fn green_strain(f: &DMat3) -> DMat3 {
    (f.transpose() * *f - DMat3::IDENTITY) * 0.5
}

impl HyperelasticModel for StVenantKirchhoff {
    fn energy_density(&self, f: &DMat3) -> f64 {
        let ftf = f.transpose() * *f;
        if let Some(svd) = continued(f, &ftf) {
            return self.diagonal(svd.sigma.into()).energy;
        }
        let g = (ftf - DMat3::IDENTITY) * 0.5;
        let LameParameters { lambda, mu } = self.0;
        mu * double_dot(&g, &g) + 0.5 * lambda * trace(&g).powi(2)
    }

    #[inline(always)]
    fn first_piola(&self, f: &DMat3) -> DMat3 {
        let ftf = f.transpose() * *f;
        if let Some(svd) = continued(f, &ftf) {
            return diagonal_stress(&svd, self.diagonal(svd.sigma.into()).gradient);
        }
        *f * self.second_piola(&((ftf - DMat3::IDENTITY) * 0.5))
    }

    fn first_piola_differential(&self, f: &DMat3, df: &DMat3) -> DMat3 {
        let ftf = f.transpose() * *f;
        if let Some(svd) = continued(f, &ftf) {
            let diagonal = self.diagonal(svd.sigma.into());
            return diagonal_stress_differential(&svd, diagonal.gradient, diagonal.hessian, df);
        }
        let s = self.second_piola(&((ftf - DMat3::IDENTITY) * 0.5));
        let ds = self.second_piola(&symmetric_part(&(f.transpose() * *df)));
        *df * s + *f * ds
    }

    /// `F (S + S_extra)`: one product for the elastic and the extra stress. A block with any
    /// lane at or below the compression threshold is evaluated lane by lane with the scalar
    /// methods.
    #[inline(always)]
    fn first_piola_plus_lanes(&self, f: &Mat3x4, s_extra: &Mat3x4) -> Mat3x4 {
        let ftf = f.transpose_mul(f);
        if !above_threshold_lanes(f, &ftf) {
            let lanes = self.first_piola_plus_by_lane(&f.to_lanes(), &s_extra.to_lanes());
            return Mat3x4::from_lanes(lanes);
        }
        let green = ftf.add_diagonal(f64x4::splat(-1.0)) * f64x4::splat(0.5);
        *f * (linear_law_lanes(self.0, &green) + *s_extra)
    }
}

/// [`above_threshold`] for all four lanes at once, with a cheaper sufficient test first from
/// `J = det F` and `I₁ = tr(FᵀF)`: the other two eigenvalues of `FᵀF` have the sum `I₁ - x` and
/// the product `J²/x <= ((I₁ - x)/2)²`, where `x` is the smallest, so `4 J² <= x (I₁ - x)²`, whose
/// right side increases up to `x = I₁/3 >= x`; hence `2 J > c (I₁ - c²)` with `I₁ >= 3 c²` means
/// `x > c²`. It is exact when the two larger stretches are equal (uniaxial compression); the
/// leading minors decide the blocks it cannot.
#[inline(always)]
fn above_threshold_lanes(f: &Mat3x4, ftf: &Mat3x4) -> bool {
    let c = COMPRESSION_THRESHOLD;
    let zero = f64x4::ZERO;
    let j = f.determinant();
    let i1 = ftf.trace();
    let cheap = (j * f64x4::splat(2.0)).simd_gt((i1 - f64x4::splat(c * c)) * f64x4::splat(c))
        & i1.simd_ge(f64x4::splat(3.0 * c * c));
    if cheap.all() {
        return true;
    }
    let d = ftf.add_diagonal(f64x4::splat(-c * c));
    let d00 = d.cols[0].x;
    let minor = d00 * d.cols[1].y - d.cols[1].x * d.cols[0].y;
    (j.simd_gt(zero) & d00.simd_gt(zero) & minor.simd_gt(zero) & d.determinant().simd_gt(zero))
        .all()
}

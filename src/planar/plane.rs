//! Why a 2D body is flat, and the in-plane law that follows from each 3D material model.
//!
//! The in-plane deformation gradient `F` (2×2) is embedded in 3D as `F₃ = [[F, 0], [0, s]]`,
//! `s` the stretch across the plane, and the 3D model gives `P₃(F₃)`:
//! - **plane strain** (a thick body, `ε₃ⱼ = 0`): `s = 1`; the in-plane stress is `P₃`'s upper
//!   block and `P₃₃` is the stress that holds the body flat (for the linear law
//!   `σ₃₃ = λ tr ε = ν (σ₁₁ + σ₂₂)`);
//! - **plane stress** (a thin sheet, `σ₃ⱼ = 0`): `s` solves `P₃₃(F, s) = 0` (Newton in one
//!   unknown), and the tangent is condensed, `dP = A dF − b (c : dF)/d` with `A`, `b`, `c`, `d`
//!   the blocks of `∂P₃/∂F₃`. For the linear law this is `σ = λ* tr ε I + 2 μ ε` with
//!   `λ* = 2 λ μ / (λ + 2 μ)`, derived here rather than assumed (tests check it), and finite as
//!   `ν → 1/2`.
//!
//! Stresses are first Piola–Kirchhoff, per unit rest area of a section of unit rest thickness,
//! so that for plane stress the thinning `s` is in them.

use crate::damping::RayleighDamping;
use crate::material::{HyperelasticModel, VolumetricTerm};
use rapier3d::glamx::{DMat2, DMat3, DVec2, DVec3};

/// Iterations allowed to the out-of-plane stretch of plane stress.
const STRETCH_ITERATIONS: usize = 60;

/// Which assumption makes the body two-dimensional.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum PlaneModel {
    /// A thin sheet, free across its thickness: `σ₃ⱼ = 0`.
    PlaneStress,
    /// A thick body held flat: `ε₃ⱼ = 0`.
    PlaneStrain,
}

/// The in-plane stress of a deformation: `P` (Pa, the in-plane block of the 3D first
/// Piola–Kirchhoff stress), the stretch `s` across the plane (dimensionless) and the stress
/// `P₃₃` (Pa) across it (zero for plane stress, to round-off).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarStress {
    /// The in-plane first Piola–Kirchhoff stress (Pa).
    pub p: DMat2,
    /// The stretch across the plane (dimensionless).
    pub stretch: f64,
    /// The stress across the plane (Pa).
    pub p33: f64,
}

impl PlanarStress {
    /// The Cauchy (true) stress (Pa, world axes, `σ₃₃` across the plane) of this stress at the
    /// in-plane deformation gradient `f` it was evaluated at: `σ = P₃ F₃ᵀ / det F₃` with
    /// `F₃ = [[f, 0], [0, s]]`, so `σ₃₃ = P₃₃ / det f` (zero for plane stress).
    pub fn cauchy(&self, f: &DMat2) -> DMat3 {
        let j = f.determinant() * self.stretch;
        let in_plane = self.p * f.transpose() * (1.0 / j);
        DMat3::from_cols(
            DVec3::new(in_plane.x_axis.x, in_plane.x_axis.y, 0.0),
            DVec3::new(in_plane.y_axis.x, in_plane.y_axis.y, 0.0),
            DVec3::new(0.0, 0.0, self.p33 * self.stretch / j),
        )
    }
}

/// A 3D hyperelastic model under a [`PlaneModel`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarLaw<M> {
    /// The 3D model.
    pub model: M,
    /// The plane assumption.
    pub plane: PlaneModel,
}

/// `F₃` for the in-plane `f` and the stretch `s` across the plane.
fn embed(f: &DMat2, s: f64) -> DMat3 {
    DMat3::from_cols(
        f.x_axis.extend(0.0),
        f.y_axis.extend(0.0),
        DVec3::new(0.0, 0.0, s),
    )
}

/// The in-plane block of `m`.
fn in_plane(m: &DMat3) -> DMat2 {
    DMat2::from_cols(m.x_axis.truncate(), m.y_axis.truncate())
}

/// The in-plane unit directions `eᵢ ⊗ eⱼ`, in the order `F₁₁, F₂₁, F₁₂, F₂₂` (column-major).
fn in_plane_directions() -> [DMat2; 4] {
    [
        DMat2::from_cols(DVec2::X, DVec2::ZERO),
        DMat2::from_cols(DVec2::Y, DVec2::ZERO),
        DMat2::from_cols(DVec2::ZERO, DVec2::X),
        DMat2::from_cols(DVec2::ZERO, DVec2::Y),
    ]
}

impl<M: HyperelasticModel> PlanarLaw<M> {
    /// The stretch across the plane (dimensionless) for the in-plane `f`: 1 for plane strain;
    /// for plane stress the root of `P₃₃` that Newton's method reaches from 1, kept positive
    /// (halving the stretch where a step would make it negative). Where the model's `∂P₃₃/∂s`
    /// is not positive (none of the crate's models at a non-inverted `F`), the last stretch
    /// reached is kept: a bounded state, never NaN.
    pub fn stretch(&self, f: &DMat2) -> f64 {
        if self.plane == PlaneModel::PlaneStrain {
            return 1.0;
        }
        let across = DMat3::from_cols(DVec3::ZERO, DVec3::ZERO, DVec3::Z);
        let mut s = 1.0;
        for _ in 0..STRETCH_ITERATIONS {
            let f3 = embed(f, s);
            let p33 = self.model.first_piola(&f3).z_axis.z;
            let slope = self.model.first_piola_differential(&f3, &across).z_axis.z;
            if slope.is_nan() || slope <= 0.0 {
                break;
            }
            let step = p33 / slope;
            let next = if s - step > 0.0 { s - step } else { 0.5 * s };
            let converged = (next - s).abs() <= 1e-15 * s;
            s = next;
            if converged {
                break;
            }
        }
        s
    }

    /// The stress for the in-plane deformation gradient `f`.
    pub fn stress(&self, f: &DMat2) -> PlanarStress {
        let stretch = self.stretch(f);
        let p3 = self.model.first_piola(&embed(f, stretch));
        PlanarStress {
            p: in_plane(&p3),
            stretch,
            p33: p3.z_axis.z,
        }
    }

    /// The strain energy density (J/m³ of rest volume) at `f`.
    pub fn energy_density(&self, f: &DMat2) -> f64 {
        self.model.energy_density(&embed(f, self.stretch(f)))
    }

    /// The in-plane stress tangent at `f`: `dP` (Pa) for each of the unit changes of `F`
    /// `F₁₁, F₂₁, F₁₂, F₂₂`, condensed over the stretch for plane stress.
    pub fn tangent(&self, f: &DMat2) -> [DMat2; 4] {
        let s = self.stretch(f);
        let f3 = embed(f, s);
        let directions = in_plane_directions().map(|d| embed(&d, 0.0));
        let columns = self.model.first_piola_differentials(&f3, &directions);
        if self.plane == PlaneModel::PlaneStrain {
            return columns.map(|c| in_plane(&c));
        }
        let across = DMat3::from_cols(DVec3::ZERO, DVec3::ZERO, DVec3::Z);
        let response = self.model.first_piola_differential(&f3, &across);
        let (b, d) = (in_plane(&response), response.z_axis.z);
        columns.map(|c| in_plane(&c) - b * (c.z_axis.z / d))
    }
}

/// The volumetric term `K/2 m(F)²` of plane strain (the stretch across the plane held at 1),
/// for nodal averaging ([`super::PlanarBodyBuilder::volumetric`]).
impl<M: VolumetricTerm> PlanarLaw<M> {
    /// The bulk modulus `K` (Pa).
    pub fn bulk_modulus(&self) -> f64 {
        self.model.volumetric_modulus()
    }

    /// The volume measure `m(F)` (dimensionless).
    pub fn volume_measure(&self, f: &DMat2) -> f64 {
        self.model.volume_measure(&embed(f, 1.0))
    }

    /// Its in-plane gradient `∂m/∂F` (dimensionless).
    pub fn volume_gradient(&self, f: &DMat2) -> DMat2 {
        in_plane(&self.model.volume_measure_gradient(&embed(f, 1.0)))
    }

    /// The component of `∂m/∂F₃` across the plane (dimensionless), at the unit stretch of plane
    /// strain: what an averaged volumetric term adds to `P₃₃` per unit of pressure shift.
    pub fn volume_gradient_across(&self, f: &DMat2) -> f64 {
        self.model.volume_measure_gradient(&embed(f, 1.0)).z_axis.z
    }

    /// The differential of the gradient for an in-plane change `df`.
    pub fn volume_differential(&self, f: &DMat2, df: &DMat2) -> DMat2 {
        in_plane(&(self.model).volume_measure_differential(&embed(f, 1.0), &embed(df, 0.0)))
    }

    /// `Ψ(F) − K/2 m(F)²` (J/m³).
    pub fn energy_without_volumetric(&self, f: &DMat2) -> f64 {
        self.model.energy_density_without_volumetric(&embed(f, 1.0))
    }
}

impl PlaneModel {
    /// The damping as it acts on in-plane rates: the 3D law with `Ġ₃₃ = 0` in plane strain;
    /// in plane stress with the rate across the sheet that leaves no damping stress across it,
    /// which is the 3D law with the reduced volumetric viscosity `φ* = 2φψ/(φ + 2ψ)` and
    /// `Ġ₃₃ = 0` (exactly consistent with the elastic stretch across the sheet for
    /// stiffness-proportional damping at small strain, where both rates are `−ν/(1 − ν) tr ε̇`).
    pub fn in_plane_damping(self, damping: &RayleighDamping) -> RayleighDamping {
        match self {
            PlaneModel::PlaneStrain => *damping,
            PlaneModel::PlaneStress => damping.plane_stress(),
        }
    }

    /// The in-plane damping stress (Pa, first Piola–Kirchhoff) of `damping` for the in-plane
    /// deformation gradient `f` and its rate `f_dot` (1/s) (see
    /// [`PlaneModel::in_plane_damping`]).
    pub fn damping_stress(self, damping: &RayleighDamping, f: &DMat2, f_dot: &DMat2) -> DMat2 {
        let damping = self.in_plane_damping(damping);
        in_plane(&damping.first_piola(&embed(f, 1.0), &embed(f_dot, 0.0)))
    }
}

/// `F₃` for the in-plane `f` with a unit stretch across the plane: the embedding in which the
/// damping's in-plane terms are evaluated.
pub(super) fn embed_flat(f: &DMat2) -> DMat3 {
    embed(f, 1.0)
}

/// A change of `F₃` within the plane: `df` with no change across it.
pub(super) fn embed_change(df: &DMat2) -> DMat3 {
    embed(df, 0.0)
}

/// The in-plane block of a 3D tensor.
pub(super) fn in_plane_block(m: &DMat3) -> DMat2 {
    in_plane(m)
}

/// `dP` (Pa) for a change `df` of `F`, from the `tangent`'s columns.
pub fn apply_tangent(tangent: &[DMat2; 4], df: &DMat2) -> DMat2 {
    tangent[0] * df.x_axis.x
        + tangent[1] * df.x_axis.y
        + tangent[2] * df.y_axis.x
        + tangent[3] * df.y_axis.y
}

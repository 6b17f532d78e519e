//! A liquid-filled chamber ([`Load::Chamber`](super::Load::Chamber)): a closed inner surface of
//! the body (a cavity; its triangles oriented out of the body, so into the cavity) filled with a
//! liquid of bulk modulus `K` (Pa) that a pump holds at the volume `V*` (m³), as a hydraulic
//! actuator is driven by volume. At the cavity's volume `V(x)` the liquid stores
//! `U = K (V − V*)² / (2 V*)` (J) and pushes on the walls with the pressure
//! `p = −dU/dV = K (V* − V)/V*` (Pa): the walls carry the follower pressure `p` (see
//! [`crate::load`]), and the Newton tangent is `∇²U = −p ∇²V + (K/V*) g gᵀ` with `g = ∇V` (m² per
//! node): the follower pressure's tangent at `p` plus a rank-one term that couples every node
//! of the walls. That term is not assembled (it would fill the factorization among the walls'
//! nodes); a Newton direction takes it in by the Woodbury identity with the factorization of the
//! rest ([`ChamberSolve`]), one more solve per chamber.
//!
//! The volume is held to `p/K` of itself (water, 2.2e9 Pa: 1e-6 at 2.2 kPa): a stiffer liquid
//! holds it closer and stiffens the explicit step, which the stable step counts
//! ([`add_stiffness_bounds`]). The liquid is internal: it exerts no net force or torque.

use super::follower;
use crate::assembly::{Factor, solve_columns};
use rapier3d::glamx::DVec3;
use rapier3d::na::{DMatrix, DVector, Dyn, LU};

/// The bulk modulus of water (Pa) at 20 °C, the default liquid.
pub const WATER_BULK_MODULUS: f64 = 2.2e9;

/// The volume (m³) the closed surface `triangles` encloses at the positions `x` (m), its
/// triangles pointing into it.
pub(super) fn volume(triangles: &[[u32; 3]], x: &[DVec3]) -> f64 {
    -follower::cone_volume(triangles, x, follower::centre(triangles, x))
}

/// The liquid's pressure (Pa) at the cavity's volume `volume` (m³): `K (V* − V)/V*`.
pub(super) fn pressure(volume: f64, (target, bulk_modulus): (f64, f64)) -> f64 {
    bulk_modulus * (target - volume) / target
}

/// The liquid's energy (J) at the cavity's volume `volume` (m³): `K (V − V*)² / (2 V*)`.
pub(super) fn energy(volume: f64, (target, bulk_modulus): (f64, f64)) -> f64 {
    0.5 * bulk_modulus * (volume - target).powi(2) / target
}

/// `g = ∇V` (m² per node) of the volume the closed surface `triangles` encloses at `x` (m).
pub(super) fn volume_gradient(triangles: &[[u32; 3]], x: &[DVec3]) -> Vec<DVec3> {
    let mut gradient = vec![DVec3::ZERO; x.len()];
    // Minus the cone's gradient, as the faces point into the cavity.
    follower::add_cone_forces(
        triangles,
        1.0,
        x,
        follower::centre(triangles, x),
        &mut gradient,
    );
    gradient
}

/// Adds to `rows[n]` the row sums `(K/V*) |g_n| Σ_m |g_m|` (N/m) of the norms of the blocks of
/// the rank-one term `(K/V*) g gᵀ`, for Gershgorin's bound on the highest frequency (the
/// follower pressure's part is the caller's).
pub(super) fn add_stiffness_bounds(
    triangles: &[[u32; 3]],
    (target, bulk_modulus): (f64, f64),
    x: &[DVec3],
    rows: &mut [f64],
) {
    let gradient = volume_gradient(triangles, x);
    let total: f64 = gradient.iter().map(|g| g.length()).sum();
    let weight = bulk_modulus / target;
    for (row, g) in rows.iter_mut().zip(&gradient) {
        *row += weight * g.length() * total;
    }
}

/// The rank-one terms `w g gᵀ` of a body's (or a group's) chambers: per chamber its column `g`
/// (m² per node of the system, zero on pinned nodes) and weight `w = K/V*` (Pa/m³).
#[derive(Debug, Clone, Default)]
pub(crate) struct ChamberTerms {
    pub(crate) columns: Vec<Vec<DVec3>>,
    pub(crate) weights: Vec<f64>,
}

impl ChamberTerms {
    /// Whether there is no chamber.
    pub(crate) fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }
}

/// Solves with the factorization of a tangent `K` assembled without the chambers' rank-one
/// terms `G W Gᵀ` as with `K + G W Gᵀ`, by the Woodbury identity:
/// `(K + G W Gᵀ)⁻¹ b = K⁻¹ b − Z (W⁻¹ + Gᵀ Z)⁻¹ Gᵀ K⁻¹ b` with `Z = K⁻¹ G`, one solve per
/// chamber made once. Without chambers it solves with the factorization alone.
pub(crate) struct ChamberSolve<'a> {
    factor: &'a Factor,
    terms: &'a ChamberTerms,
    /// `Z = K⁻¹ G`, and the LU factors of `W⁻¹ + Gᵀ Z` (`None` when singular to round-off,
    /// where the chambers are left out).
    solved: Vec<Vec<DVec3>>,
    system: Option<LU<f64, Dyn, Dyn>>,
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

impl<'a> ChamberSolve<'a> {
    /// The solves with `factor` (of `K`) that take `terms` in.
    pub(crate) fn new(factor: &'a Factor, terms: &'a ChamberTerms) -> Self {
        let solved = solve_columns(factor, &terms.columns);
        let k = terms.columns.len();
        let system = DMatrix::from_fn(k, k, |i, j| {
            let inverse_weight = if i == j { 1.0 / terms.weights[i] } else { 0.0 };
            inverse_weight + dot(&terms.columns[i], &solved[j])
        });
        let system = Some(system.lu()).filter(|lu| lu.is_invertible());
        Self {
            factor,
            terms,
            solved,
            system,
        }
    }

    /// Whether there is no chamber to take in: the solves are the factorization's.
    pub(crate) fn is_plain(&self) -> bool {
        self.terms.is_empty()
    }

    /// `(K + G W Gᵀ)⁻¹ b` from `solved = K⁻¹ b` (per node).
    fn correct(&self, mut solved: Vec<DVec3>) -> Vec<DVec3> {
        let Some(system) = &self.system else {
            return solved;
        };
        let k = self.terms.columns.len();
        let projection = DVector::from_fn(k, |i, _| dot(&self.terms.columns[i], &solved));
        let Some(weights) = system.solve(&projection) else {
            return solved;
        };
        for (z, weight) in self.solved.iter().zip(weights.iter()) {
            for (d, z) in solved.iter_mut().zip(z) {
                *d -= *z * *weight;
            }
        }
        solved
    }

    /// `(K + G W Gᵀ)⁻¹` applied to each of `columns` (per node).
    pub(crate) fn solve_columns(&self, columns: &[Vec<DVec3>]) -> Vec<Vec<DVec3>> {
        let solved = solve_columns(self.factor, columns);
        if self.is_plain() {
            return solved;
        }
        solved.into_iter().map(|z| self.correct(z)).collect()
    }

    /// `direction` solves `K d = r` (`r` the `residual`, N); this returns `(K + G W Gᵀ)⁻¹ r`,
    /// or `direction` itself when there is no chamber or the result would not descend (round-off
    /// on a nearly singular system).
    pub(crate) fn take_in(&self, residual: &[DVec3], direction: Vec<DVec3>) -> Vec<DVec3> {
        if self.is_plain() {
            return direction;
        }
        let taken = self.correct(direction.clone());
        let finite = taken.iter().all(|d| d.is_finite());
        if finite && dot(residual, &taken) > 0.0 {
            taken
        } else {
            direction
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::assembly::{Stiffness, factorize, perturb_positions, solve};
    use crate::body::{DeformableBody, DeformableBodyBuilder};
    use crate::load::Load;
    use crate::load::follower::tests::{
        assert_forces_and_tangent_derive_from_the_potential, fixed_direction,
    };
    use crate::material::{Material, MaterialModel};
    use crate::mesh;
    use rapier3d::glamx::{DMat3, DVec3};

    /// A 0.2 m cube, deformed, its bottom face pinned, whose whole surface turned inside out is
    /// a chamber (a closed surface) of a liquid of 1e6 Pa pumped 2 % beyond what it encloses:
    /// the liquid pushes at 20 kPa, and its rank-one stiffness is of the elements' order.
    fn cube_with_chamber() -> DeformableBody {
        let mesh = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2]).unwrap();
        let walls: Vec<[u32; 3]> = (mesh.surface_triangles().iter())
            .map(|&[a, b, c]| [a, c, b])
            .collect();
        let base = mesh.nodes_where(|p| p.y < -0.1 + 1e-9);
        let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
        let builder = DeformableBodyBuilder::new(mesh, material).pinned_nodes(base);
        let mut body = builder.build().unwrap();
        perturb_positions(&mut body, 7, 0.01);
        let volume = Load::enclosed_volume_of(&walls, body.positions()).unwrap();
        let chamber = Load::Chamber {
            triangles: walls,
            volume: 1.02 * volume,
            bulk_modulus: 1e6,
        };
        body.add_load(chamber).unwrap();
        body
    }

    /// The liquid's forces and tangent, the pressure's assembled part plus the rank-one
    /// `w g gᵀ`, derive from its energy (see
    /// [`assert_forces_and_tangent_derive_from_the_potential`]); it pushes with `K (V* − V)/V*`.
    #[test]
    fn forces_and_tangent_derive_from_the_liquid_s_energy() {
        let mut body = cube_with_chamber();
        let pressure = body.loads()[0].pressure_at(body.positions()).unwrap();
        // `K (V* − V)/V*` with `V* = 1.02 V`.
        assert!((pressure * 1.02 / 2e4 - 1.0).abs() < 1e-12, "{pressure}");
        assert_forces_and_tangent_derive_from_the_potential(&mut body, |body, d| {
            let (g, w) = body.loads()[0].chamber_term(body.positions()).unwrap();
            let g_d: f64 = g.iter().zip(d).map(|(g, d)| g.dot(*d)).sum();
            g.iter().map(|g| *g * (w * g_d)).collect()
        });
    }

    /// The Woodbury direction solves the system with the rank-one term: `(K + w g gᵀ) d = r` to
    /// 1e-10 of `|r|` (the factorization's round-off), while the direction of `K` alone is off
    /// by more than the tolerance.
    #[test]
    fn the_taken_in_direction_solves_the_system_with_the_liquid() {
        let body = cube_with_chamber();
        let mut stiffness = Stiffness::new(&body);
        stiffness.assemble(&body, None, false, |_, _| [DMat3::ZERO; 9]);
        let factor = factorize(&mut stiffness, 0).unwrap();
        // A fixed out-of-balance force on the free nodes.
        let residual = fixed_direction(&body);
        let terms = body.chamber_terms();
        let plain = solve(&factor, &residual);
        let taken = super::ChamberSolve::new(&factor, &terms).take_in(&residual, plain.clone());
        let error = |d: &[DVec3]| -> f64 {
            let mut k_d = stiffness.multiply(d);
            let g_d: f64 = terms.columns[0].iter().zip(d).map(|(g, d)| g.dot(*d)).sum();
            for (k_d, g) in k_d.iter_mut().zip(&terms.columns[0]) {
                *k_d += *g * (terms.weights[0] * g_d);
            }
            let off: f64 = (k_d.iter().zip(&residual))
                .map(|(a, b)| (*a - *b).length_squared())
                .sum();
            let size: f64 = residual.iter().map(|r| r.length_squared()).sum();
            (off / size).sqrt()
        };
        assert!(error(&taken) < 1e-10, "{}", error(&taken));
        assert!(error(&plain) > 1e-2, "{}", error(&plain));
    }
}

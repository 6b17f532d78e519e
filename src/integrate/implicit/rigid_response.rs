//! The dynamic rigid bodies' part of an implicit step: the soft body and the rigid bodies it
//! touches or is glued to are stepped as one system, so that the coupling cannot create energy.
//!
//! A dynamic body's unknown is the impulse `ι` (N s, and N m s about its centre of mass) the
//! step gives it on top of the velocity it starts the step with (gravity included): its velocity
//! becomes `v + W ι` (`W` its inverse mass and world inverse inertia) and it carries each of its
//! points over the step of length `h` by `h (v + W ι)` there (its pose frozen, as everywhere in
//! the soft step). Its part of the incremental potential is `½ ιᵀ W ι`, the kinetic energy of the
//! velocity change (backward Euler for the body), plus the terms that act against it, each a
//! function of its soft point's position relative to the body's point, `x − h J W ι` with
//! `J = [I | −[r]×]` and `r` the point's arm from the centre of mass.
//!
//! For the soft positions `x`, `ι*(x) = argmin ½ ιᵀ W ι + Σ e_c(x_c − h J_c W ι)` is found by
//! Newton's method on six unknowns per body with a line search that finds the lowest energy
//! along a step that overshoots it (the penalties and the lagged friction are convex in the
//! relative position), taking the full step by the residual once the energy's decrease is lost
//! in its round-off. The soft step minimizes `E(x) + min_ι(…)`, whose gradient is the terms'
//! forces at `ι*(x)` (the envelope theorem) and whose Hessian is the tangent with the bodies
//! held less the coupling through them, `U Q Uᵀ` (`U = −Σ P_cᵀ T_c J_c`,
//! `Q = h² (I + h² W A)⁻¹ W`, `A = Σ J_cᵀ T_c J_c`), which the Newton direction takes in by the
//! Woodbury identity with the held tangent's factorization (six solves per body). At `ι*`,
//! `ι = −h Σ J_cᵀ f_c`: exactly the opposite of the impulses the terms give the soft body, which
//! is what the bodies receive when the step's impulses are recorded.

use crate::body::DeformableBody;
use crate::chord::KeptCorrection;
use crate::constraint::{self, BodyConstraints, ImplicitTerm};
use crate::contact::ImplicitStep;
use crate::load::ChamberSolve;
use crate::newton::dot;
use crate::rigid::RigidProxy;
use rapier3d::glamx::{DMat3, DVec3};
use rapier3d::na::{DMatrix, DVector, Matrix3, Matrix6, Vector6};
use std::borrow::Cow;

/// Newton iterations (line-search halvings included) of one body-response solve at most.
const MAX_ITERATIONS: usize = 60;
/// The response is solved when its stationarity residual is below this fraction of the impulses'
/// scale, or below [`FLOOR`] of it when a Newton iteration no longer halves it (its round-off
/// floor, about 1e-11 of the scale for the stiffest springs).
const TOLERANCE: f64 = 1e-12;
const FLOOR: f64 = 1e-8;
/// The line search's sufficient decrease (Armijo) and curvature (Wolfe) fractions, its smallest
/// step, and the width (relative to its high end) to which it narrows the bracket around the
/// lowest energy along a Newton direction.
const ARMIJO: f64 = 1e-4;
const CURVATURE: f64 = 0.9;
const MIN_STEP: f64 = 1e-12;
const BRACKET: f64 = 1e-3;

/// Columns of per-node vectors (a tall matrix, one `Vec` per column).
type Columns = Vec<Vec<DVec3>>;

/// The rigid bodies' response within one implicit substep.
pub(super) struct RigidResponse {
    /// The bodies at the substep's start (gravity included): what the impulses add to.
    base: Vec<RigidProxy>,
    /// The bodies moving with the impulses of the last solve.
    trial: Vec<RigidProxy>,
    /// Per body, the linear (N s) and angular (N m s) impulse of the last solve.
    impulses: Vec<[DVec3; 2]>,
    /// The soft positions of the last solve (m), and its `½ ιᵀ W ι` (J).
    solved_at: Vec<DVec3>,
    kinetic: f64,
    /// Whether some term acts against a dynamic body (none: nothing to solve).
    coupled: bool,
    /// The last Newton direction's columns of `U` and `Z = K⁻¹ U` (see
    /// [`RigidResponse::take_in`]).
    solved_columns: Option<(Columns, Columns)>,
    /// The last call's `S = (I − Q Uᵀ Z)⁻¹ Q` when the direction it returned took the response
    /// in (see [`RigidResponse::kept_correction`]).
    taken_correction: Option<DMatrix<f64>>,
    /// The effective step `ĥ`, the penalty step (see [`ImplicitStep`]) and the step's length
    /// `h` (s).
    effective: f64,
    penalty_step: f64,
    length: f64,
}

/// What the terms against one body add up to at the trial velocities, in 3 x 3 blocks (linear
/// part first, then angular).
#[derive(Clone, Copy)]
struct Gathered {
    /// `Σ J_cᵀ f_c`: the force (N) and its moment about the centre of mass (N m).
    force: [DVec3; 2],
    /// `A = Σ J_cᵀ T_c J_c` (N/m, N, N m).
    stiffness: [[DMat3; 2]; 2],
    /// `Σ |f_c|` (N): the scale of the force.
    magnitude: f64,
}

/// `[r]×`, the matrix of `v ↦ r × v`.
fn cross_matrix(r: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, r.z, -r.y),
        DVec3::new(-r.z, 0.0, r.x),
        DVec3::new(r.y, -r.x, 0.0),
    )
}

impl Gathered {
    fn zero() -> Self {
        Self {
            force: [DVec3::ZERO; 2],
            stiffness: [[DMat3::ZERO; 2]; 2],
            magnitude: 0.0,
        }
    }

    /// Adds `term`, whose point is at `arm` (m) from the body's centre of mass: with
    /// `J = [I | −[r]×]`, `Jᵀ f = (f, r × f)` and `Jᵀ T J` has the blocks `T`, `−T [r]×`,
    /// `[r]× T` and `−[r]× T [r]×`.
    fn add(&mut self, term: &ImplicitTerm, arm: DVec3) {
        let (t, c) = (term.tangent, cross_matrix(arm));
        self.force[0] += term.force;
        self.force[1] += arm.cross(term.force);
        let tc = t * c;
        self.stiffness[0][0] += t;
        self.stiffness[0][1] -= tc;
        self.stiffness[1][0] += c * t;
        self.stiffness[1][1] -= c * tc;
        self.magnitude += term.force.length();
    }

    fn force(&self) -> Vector6<f64> {
        vector6(self.force)
    }

    fn stiffness(&self) -> Matrix6<f64> {
        let mut a = Matrix6::zeros();
        for (i, row) in self.stiffness.iter().enumerate() {
            for (j, block) in row.iter().enumerate() {
                a.fixed_view_mut::<3, 3>(3 * i, 3 * j)
                    .copy_from(&matrix(block));
            }
        }
        a
    }
}

/// The response's energy (J) and what the terms add up to per body, at some impulses.
struct Evaluation {
    energy: f64,
    gathered: Vec<Option<Gathered>>,
}

fn matrix(m: &DMat3) -> Matrix3<f64> {
    Matrix3::from_column_slice(&m.to_cols_array())
}

fn vector6(v: [DVec3; 2]) -> Vector6<f64> {
    Vector6::new(v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z)
}

fn pair(v: &Vector6<f64>) -> [DVec3; 2] {
    [DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5])]
}

/// The body's `W` (6 x 6): inverse mass per axis and world inverse inertia.
fn inverse_mass(proxy: &RigidProxy) -> Matrix6<f64> {
    let (mass, inertia) = proxy.inverse_mass_and_inertia();
    let mut w = Matrix6::zeros();
    w.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::from_diagonal(&mass.to_array().into()));
    w.fixed_view_mut::<3, 3>(3, 3).copy_from(&matrix(&inertia));
    w
}

impl RigidResponse {
    /// The response of the bodies `base` (at the substep's start) in a step of effective length,
    /// penalty step and length `(effective, penalty_step, length)` (s).
    pub(super) fn new(
        base: Vec<RigidProxy>,
        (effective, penalty_step, length): (f64, f64, f64),
    ) -> Self {
        Self {
            trial: base.clone(),
            impulses: vec![[DVec3::ZERO; 2]; base.len()],
            coupled: base.iter().any(RigidProxy::is_dynamic),
            base,
            solved_at: Vec::new(),
            kinetic: 0.0,
            solved_columns: None,
            taken_correction: None,
            effective,
            penalty_step,
            length,
        }
    }

    /// The step as the terms see it, the bodies at their start.
    pub(super) fn start(&self) -> ImplicitStep<'_> {
        self.step_with(&self.base)
    }

    /// The step as the terms see it, the bodies moving as the last solve left them.
    pub(super) fn step(&self) -> ImplicitStep<'_> {
        self.step_with(&self.trial)
    }

    fn step_with<'a>(&self, rigid: &'a [RigidProxy]) -> ImplicitStep<'a> {
        ImplicitStep {
            effective: self.effective,
            penalty_step: self.penalty_step,
            length: self.length,
            rigid,
            partners_only: false,
        }
    }

    /// [`RigidResponse::step`] for the terms against a dynamic body only: all the response's
    /// own evaluations need.
    fn partner_step(&self) -> ImplicitStep<'_> {
        ImplicitStep {
            partners_only: true,
            ..self.step()
        }
    }

    /// Forgets where the response was last solved: the potential changed (a contact stiffened),
    /// so the next evaluation solves it again even at the same positions.
    pub(super) fn forget_solution(&mut self) {
        self.solved_at.clear();
    }

    /// Solves the bodies' response to the soft body at its positions (unless solved there
    /// already) and returns its `½ ιᵀ W ι` (J).
    pub(super) fn solve(&mut self, body: &DeformableBody, constraints: &BodyConstraints) -> f64 {
        if !self.coupled || self.solved_at == body.positions {
            return self.kinetic;
        }
        let mut at = self.evaluate(body, constraints);
        let mut previous = f64::INFINITY;
        for _ in 0..MAX_ITERATIONS {
            let residuals = self.residuals(&at.gathered);
            let largest = residuals.iter().map(|r| r.norm()).fold(0.0, f64::max);
            // Solved, or on its round-off floor: small, and Newton no longer halves it.
            let scale = self.scale(&at.gathered);
            if largest <= TOLERANCE * scale
                || (largest <= FLOOR * scale && largest > 0.5 * previous)
            {
                break;
            }
            previous = largest;
            let directions = self.newton_directions(&at.gathered, &residuals);
            let slope = self.slope(&residuals, &directions);
            if slope.is_nan() || slope >= 0.0 {
                break;
            }
            let start = self.impulses.clone();
            let next = self
                .line_search(body, constraints, (&start, &directions), (at.energy, slope))
                .or_else(|| self.closer(body, constraints, (&start, &directions), largest));
            match next {
                Some(next) => at = next,
                None => {
                    self.move_to(&start, &directions, 0.0);
                    break;
                }
            }
        }
        self.kinetic = self.kinetic_energy();
        self.solved_at.clone_from(&body.positions);
        self.kinetic
    }

    /// Moves the impulses from `start`, where the response's energy is `energy` (J) and falls at
    /// `slope` (J per unit step), along `directions` to a point of sufficient decrease and
    /// flattened slope (the strong Wolfe conditions): the full step if it is one, else the
    /// lowest point on the line, found by the sign of the slope (the energy is convex along it:
    /// the kinetic part is quadratic and every term convex in the relative position) in the
    /// bracket `[0, 1]`, narrowed tenfold while its low end is the start (a Newton step from
    /// where no term acts yet, or not yet stiffly, can overshoot the point where one comes in
    /// by orders of magnitude, and a backtracking search would creep toward it by a fraction of
    /// the step each iteration), by halves after, to [`BRACKET`] of its width. Returns the lowest
    /// point it met if below `energy`, `None` (the impulses left anywhere) if none is.
    fn line_search(
        &mut self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        (start, directions): (&[[DVec3; 2]], &[Vector6<f64>]),
        (energy, slope): (f64, f64),
    ) -> Option<Evaluation> {
        let mut lowest: Option<(f64, Evaluation)> = None;
        let (mut low, mut high, mut step) = (0.0, 1.0, 1.0);
        loop {
            self.move_to(start, directions, step);
            let next = self.evaluate(body, constraints);
            let slope_here = self.slope(&self.residuals(&next.gathered), directions);
            let decrease = next.energy <= energy + ARMIJO * step * slope;
            if decrease && slope_here.abs() <= -CURVATURE * slope {
                return Some(next);
            }
            if slope_here < 0.0 {
                low = step;
            } else {
                high = step;
            }
            if next.energy < lowest.as_ref().map_or(energy, |(_, e)| e.energy) {
                lowest = Some((step, next));
            }
            step = if low == 0.0 {
                0.1 * high
            } else if high - low > BRACKET * high {
                0.5 * (low + high)
            } else {
                break;
            };
            if step < MIN_STEP {
                break;
            }
        }
        let (step, found) = lowest?;
        self.move_to(start, directions, step);
        Some(found)
    }

    /// The slope (J per unit step) of the response's energy along `directions` where the
    /// stationarity residuals are `residuals`: its gradient is `W G` per body.
    fn slope(&self, residuals: &[Vector6<f64>], directions: &[Vector6<f64>]) -> f64 {
        (0..self.base.len())
            .map(|p| (inverse_mass(&self.base[p]) * residuals[p]).dot(&directions[p]))
            .sum()
    }

    /// The full Newton step from the impulses `start` along `directions` if it brings the largest
    /// stationarity residual below `largest` (N s): close to the solution the energy's decrease,
    /// `½ Gᵀ W (I + h² A W)⁻¹ G`, falls below the round-off of the terms' energies (each a
    /// penalty on a gap of micrometres between coordinates of decimetres), and the line search
    /// can no longer see it, while the residual still falls quadratically. `None` if it does not.
    fn closer(
        &mut self,
        body: &DeformableBody,
        constraints: &BodyConstraints,
        (start, directions): (&[[DVec3; 2]], &[Vector6<f64>]),
        largest: f64,
    ) -> Option<Evaluation> {
        self.move_to(start, directions, 1.0);
        let next = self.evaluate(body, constraints);
        let after = (self.residuals(&next.gathered).iter())
            .map(|r| r.norm())
            .fold(0.0, f64::max);
        (after < largest).then_some(next)
    }

    /// `½ Σ ιᵀ W ι` (J) over the bodies.
    fn kinetic_energy(&self) -> f64 {
        self.base
            .iter()
            .zip(&self.impulses)
            .map(|(proxy, impulse)| proxy.kinetic_energy_of(*impulse))
            .sum()
    }

    /// The impulses `start + step direction`, and the bodies moving with them.
    fn move_to(&mut self, start: &[[DVec3; 2]], direction: &[Vector6<f64>], step: f64) {
        for p in 0..self.base.len() {
            let next = vector6(start[p]) + direction[p] * step;
            self.impulses[p] = pair(&next);
            self.trial[p].nudge_from(&self.base[p], self.impulses[p]);
        }
    }

    /// The response's energy and, per body, what the terms against it add up to, at the trial
    /// velocities (`None` for a body no term acts against).
    fn evaluate(&self, body: &DeformableBody, constraints: &BodyConstraints) -> Evaluation {
        let mut energy = self.kinetic_energy();
        let mut gathered = vec![None; self.base.len()];
        constraint::for_each_implicit_term(body, constraints, self.partner_step(), &mut |term| {
            if let Some(partner) = term.partner {
                energy += term.energy;
                let arm = partner.point - self.base[partner.proxy].center_of_mass();
                let sum = gathered[partner.proxy].get_or_insert_with(Gathered::zero);
                sum.add(&term, arm);
            }
        });
        Evaluation { energy, gathered }
    }

    /// Per body, the stationarity residual `G = ι + h Σ J_cᵀ f_c` (N s, N m s).
    fn residuals(&self, gathered: &[Option<Gathered>]) -> Vec<Vector6<f64>> {
        (0..self.base.len())
            .map(|p| {
                let force = gathered[p].map_or(Vector6::zeros(), |g| g.force());
                vector6(self.impulses[p]) + force * self.length
            })
            .collect()
    }

    /// The impulses' scale (N s): the largest of every body's `|ι| + h Σ |f_c|`.
    fn scale(&self, gathered: &[Option<Gathered>]) -> f64 {
        (0..self.base.len())
            .map(|p| {
                let magnitude = gathered[p].map_or(0.0, |g| g.magnitude);
                vector6(self.impulses[p]).norm() + magnitude * self.length
            })
            .fold(f64::MIN_POSITIVE, f64::max)
    }

    /// Per body, the Newton direction `−(I + h² A W)⁻¹ G`.
    fn newton_directions(
        &self,
        gathered: &[Option<Gathered>],
        residuals: &[Vector6<f64>],
    ) -> Vec<Vector6<f64>> {
        let h2 = self.length * self.length;
        (0..self.base.len())
            .map(|p| {
                let stiffness = gathered[p].map_or(Matrix6::zeros(), |g| g.stiffness());
                let system = Matrix6::identity() + stiffness * inverse_mass(&self.base[p]) * h2;
                system
                    .lu()
                    .solve(&(-residuals[p]))
                    .unwrap_or_else(|| -residuals[p])
            })
            .collect()
    }
}

impl RigidResponse {
    /// The soft body's Newton direction (m per node) with the bodies' response taken in:
    /// `direction` solves `K d = r` (`r` the `residual`, `N`) with `solver`, the tangent `K` with
    /// the bodies held (the chambers' liquids taken in); this returns `(K − U Q Uᵀ)⁻¹ r` by the
    /// Woodbury identity, `d + Z (I − Q Uᵀ Z)⁻¹ Q Uᵀ d` with `Z = K⁻¹ U` solved by the same
    /// `solver`, or `direction` itself when no term acts against a dynamic body or the result
    /// would not descend.
    ///
    /// `Z` is kept for the next call: when that one solves with the same factorization
    /// (`same_factor`, a reused one) and no chamber, and finds the same `U`, it skips the
    /// solves.
    ///
    /// In a group of bodies solved as one system, `residual`, `direction` and the factorization
    /// are the system's, and `placement` says where the body's nodes sit among its nodes: the
    /// correction then moves every body of the group, as the system couples them.
    pub(super) fn take_in(
        &mut self,
        (body, constraints): (&DeformableBody, &BodyConstraints),
        (solver, same_factor): (&ChamberSolve, bool),
        placement: Placement,
        residual: &[DVec3],
        direction: Vec<DVec3>,
    ) -> Vec<DVec3> {
        self.taken_correction = None;
        if !self.coupled {
            return direction;
        }
        let coupling = self.coupling(body, constraints);
        if coupling.columns.is_empty() {
            return direction;
        }
        // With chambers `Z` depends on their gradients, which move with the body.
        let solved = match self.solved_columns.take() {
            Some((columns, solved))
                if same_factor && solver.is_plain() && columns == coupling.columns =>
            {
                solved
            }
            _ => solver.solve_columns(&placement.embed(&coupling.columns)),
        };
        let m = coupling.columns.len();
        let q = self.compliance(&coupling);
        // `U` is zero outside the body's own nodes.
        let own = placement.offset..placement.offset + body.positions.len();
        let u_z = DMatrix::from_fn(m, m, |i, j| {
            dot(&coupling.columns[i], &solved[j][own.clone()])
        });
        let u_d = DVector::from_fn(m, |i, _| dot(&coupling.columns[i], &direction[own.clone()]));
        let system = DMatrix::identity(m, m) - &q * u_z;
        let lu = system.lu();
        let Some(weights) = lu.solve(&(&q * u_d)) else {
            self.solved_columns = Some((coupling.columns, solved));
            return direction;
        };
        let mut taken = direction.clone();
        for (z, weight) in solved.iter().zip(weights.iter()) {
            for (d, z) in taken.iter_mut().zip(z) {
                *d += *z * *weight;
            }
        }
        self.solved_columns = Some((coupling.columns, solved));
        let finite = taken.iter().all(|d| d.is_finite());
        if finite && dot(residual, &taken) > 0.0 {
            self.taken_correction = lu.solve(&q);
            taken
        } else {
            direction
        }
    }

    /// The correction the last [`RigidResponse::take_in`] took into the direction it returned,
    /// for a factorization kept with that direction ([`KeptCorrection`]); `None` if it returned
    /// the direction as solved.
    pub(super) fn kept_correction(&self) -> Option<KeptCorrection> {
        let s = self.taken_correction.as_ref()?;
        let (u, z) = self.solved_columns.as_ref()?;
        Some(KeptCorrection {
            u: u.clone(),
            z: z.clone(),
            s: s.as_slice().to_vec(),
        })
    }

    /// The columns of `U = −Σ P_cᵀ T_c J_c` (N/m per node, six per body some term acts against)
    /// and each such body's `A = Σ J_cᵀ T_c J_c`, at the trial velocities.
    fn coupling(&self, body: &DeformableBody, constraints: &BodyConstraints) -> Coupling {
        let n = body.positions.len();
        let mut coupling = Coupling {
            bodies: Vec::new(),
            columns: Vec::new(),
        };
        let mut slot_of: Vec<Option<usize>> = vec![None; self.base.len()];
        constraint::for_each_implicit_term(body, constraints, self.partner_step(), &mut |term| {
            let Some(partner) = term.partner else {
                return;
            };
            let slot = *slot_of[partner.proxy].get_or_insert_with(|| {
                coupling.bodies.push((partner.proxy, Gathered::zero()));
                coupling
                    .columns
                    .extend(std::iter::repeat_with(|| vec![DVec3::ZERO; n]).take(6));
                coupling.bodies.len() - 1
            });
            let arm = partner.point - self.base[partner.proxy].center_of_mass();
            coupling.bodies[slot].1.add(&term, arm);
            // −T J = [−T | T [r]×], column by column.
            let tc = term.tangent * cross_matrix(arm);
            let block: [DVec3; 6] = std::array::from_fn(|k| {
                if k < 3 {
                    -term.tangent.col(k)
                } else {
                    tc.col(k - 3)
                }
            });
            for (&node, &w) in term.at.nodes.iter().zip(term.at.weights) {
                if body.pinned[node as usize] {
                    continue;
                }
                for (k, column) in block.iter().enumerate() {
                    coupling.columns[6 * slot + k][node as usize] += *column * w;
                }
            }
        });
        coupling
    }

    /// `Q` (block diagonal, six rows per body of `coupling`): each body's
    /// `h² (I + h² W A)⁻¹ W`, its displacement over the step per unit force.
    fn compliance(&self, coupling: &Coupling) -> DMatrix<f64> {
        let m = coupling.columns.len();
        let h2 = self.length * self.length;
        let mut q = DMatrix::zeros(m, m);
        for (slot, (proxy, gathered)) in coupling.bodies.iter().enumerate() {
            let w = inverse_mass(&self.base[*proxy]);
            let system = Matrix6::identity() + w * gathered.stiffness() * h2;
            if let Some(block) = system.lu().solve(&(w * h2)) {
                q.view_mut((6 * slot, 6 * slot), (6, 6)).copy_from(&block);
            }
        }
        q
    }
}

/// Where a body's nodes sit among the nodes of the system a Newton direction solves: from node
/// `offset` on, of `total` (the body alone: `0` of its own count).
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    pub(super) offset: usize,
    pub(super) total: usize,
}

impl Placement {
    /// The body's `columns` (per node of the body) as columns of the system, zero elsewhere.
    pub(super) fn embed<'c>(&self, columns: &'c [Vec<DVec3>]) -> Cow<'c, [Vec<DVec3>]> {
        if columns.iter().all(|column| column.len() == self.total) {
            return Cow::Borrowed(columns);
        }
        Cow::Owned(
            columns
                .iter()
                .map(|column| {
                    let mut embedded = vec![DVec3::ZERO; self.total];
                    embedded[self.offset..self.offset + column.len()].copy_from_slice(column);
                    embedded
                })
                .collect(),
        )
    }
}

/// How the soft body's nodes couple through the dynamic bodies: per body its index among the
/// proxies and what its terms add up to (its `A`), and the columns of `U` (N/m per node), six per
/// body.
struct Coupling {
    bodies: Vec<(usize, Gathered)>,
    columns: Columns,
}

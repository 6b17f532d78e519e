//! Implicit dynamics of a 2D body: backward Euler on the incremental potential, as the 3D
//! implicit integrator ([`crate::integrate`]) steps a tetrahedral body:
//!
//! `x₊ = argmin Φ(x)`, `Φ = Σ m |x − x̂|²/(2h²) + E(x) + D(x) − Σ (m g + f)·(x − x₀)`,
//! `x̂ = x₀ + h v₀`, then `v₊ = (x₊ − x₀)/h`,
//!
//! with `E` the elastic energy and `D` the damping's dissipation potential over the step
//! (the in-plane law of [`PlaneModel::in_plane_damping`](super::PlaneModel::in_plane_damping)).
//! Newton's method with the exact tangent `M/h² + K + K_D` and the shared line search
//! ([`crate::newton`]). Stable at any step.
//!
//! Backward Euler keeps linear momentum but drains angular momentum by `h Σ m v₀ × v₊`, a
//! numerical torque that would stop a spinning body. It is given back as a rigid rotation of
//! the nodes, `Δv = δω (x₊ − c)^⊥`, the velocities changed and the positions kept, so that the
//! angular momentum ends where the external loads' angular impulse takes it:
//! - a free body, about its centre of mass `c`: its spin `Σ m (x − c) × (v − v_c)` changes by
//!   `h Σ (x₊ − c₊) × f` (uniform gravity has no torque there); linear momentum is unchanged;
//! - a body held at a single node `p` (a hinge), about `p`: `Σ m (x − p) × v` changes by the
//!   torque of gravity and the loads at the step's start, `h Σ (x₀ − p) × (m g + f)`, which
//!   advances the swing as symplectic Euler does and keeps its energy;
//! - a body held elsewhere has no rigid rotation to keep.
//!
//! The numerical damping of deformation, about `ωh/2` for a mode of angular frequency `ω`, is
//! backward Euler's and is kept.

use super::body::PlanarBody;
use super::dynamics::check_step;
use super::plane::{embed_change, embed_flat, in_plane_block};
use super::unknowns::{Entry, Minimized, Placed, Unknowns, minimize};
use crate::Error;
use crate::damping::RayleighDamping;
use crate::material::green_strain;
use crate::newton::{check_tolerance, norm};
use crate::statics::StaticSettings;
use faer::sparse::Triplet;
use rapier3d::glamx::{DMat2, DMat3, DVec2};

/// What [`step_implicit`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarImplicitReport {
    /// Newton iterations.
    pub newton_iterations: usize,
    /// The final out-of-balance force over its reference (dimensionless).
    pub relative_residual: f64,
    /// The angular momentum given back (kg m²/s; see the module's documentation).
    pub angular_momentum_given_back: f64,
}

/// Terms of `Φ` that act on nodes one at a time, such as contacts with colliders
/// (`planar::coupling`, feature `dim2`): at positions `x` (m), their energy (J), the forces
/// they put on the nodes (N, `−∂/∂x`) and each touched node's 2×2 stiffness (N/m, `∂²/∂x²`,
/// symmetric and positive semi-definite).
pub(super) trait NodePotential {
    /// The energy (J) at `x`.
    fn energy(&self, x: &[DVec2]) -> f64;
    /// Adds the forces (N) at `x` to `forces`.
    fn add_forces(&self, x: &[DVec2], forces: &mut [DVec2]);
    /// The nodes the terms touch at `x`, with their stiffness (N/m).
    fn stiffness(&self, x: &[DVec2]) -> Vec<(usize, DMat2)>;
}

/// One backward Euler step: where it starts, what it predicts, what acts.
struct Step<'a> {
    /// Per-node terms besides the body's own (contacts).
    nodal: Option<&'a dyn NodePotential>,
    h: f64,
    start: Vec<DVec2>,
    predicted: Vec<DVec2>,
    /// `m g + f` per node (N).
    external: Vec<DVec2>,
    unknowns: Unknowns,
    /// The in-plane damping, and each triangle's Green strain at the start (embedded in 3D).
    damping: Option<(RayleighDamping, Vec<DMat3>)>,
    body: &'a PlanarBody,
}

impl Minimized for Step<'_> {
    /// `Φ` (J) where `placed` is.
    fn potential(&self, placed: &Placed<'_>) -> f64 {
        let body = self.body;
        let x = &placed.positions;
        let inertia: f64 = (body.masses().iter().zip(x).zip(&self.predicted))
            .map(|((m, x), p)| 0.5 * m * (*x - *p).length_squared())
            .sum::<f64>()
            / (self.h * self.h);
        let work: f64 = (x.iter().zip(&self.start).zip(&self.external))
            .map(|((x, x0), f)| (*x - *x0).dot(*f))
            .sum();
        let points = body.points();
        let dissipation = self.damping.as_ref().map_or(0.0, |(damping, previous)| {
            (0..points.len())
                .map(|q| {
                    let f = embed_flat(&points.gradient(q, x));
                    damping.step_potential(&f, &previous[q], self.h) * points.weight(q)
                })
                .sum::<f64>()
                * body.thickness()
        });
        let nodal = self.nodal.map_or(0.0, |n| n.energy(x));
        inertia + body.elastic_energy_at(x) + dissipation + nodal - work
    }

    /// `−∂Φ/∂x` (N per node) where `placed` is, zero along held axes.
    fn residual(&self, placed: &Placed<'_>) -> Vec<DVec2> {
        let body = self.body;
        let x = &placed.positions;
        let mut forces = body.internal_forces_at(x);
        if let Some((damping, previous)) = &self.damping {
            let points = body.points();
            for (q, previous) in previous.iter().enumerate() {
                let f = embed_flat(&points.gradient(q, x));
                let p = in_plane_block(&damping.step_first_piola(&f, previous, self.h));
                points.add_forces(q, &p, body.thickness(), &mut forces);
            }
        }
        if let Some(nodal) = self.nodal {
            nodal.add_forces(x, &mut forces);
        }
        let inverse_h2 = 1.0 / (self.h * self.h);
        let total = (forces.iter().enumerate()).map(|(i, f)| {
            *f + self.external[i] - (x[i] - self.predicted[i]) * (body.masses()[i] * inverse_h2)
        });
        self.unknowns.free_part(total)
    }

    /// The Newton direction (m per node) for `residual` where `placed` is.
    fn direction(
        &self,
        placed: &Placed<'_>,
        residual: &[DVec2],
        iteration: usize,
    ) -> Result<Vec<DVec2>, Error> {
        let mut entries = self.unknowns.elastic_entries(self.body, &placed.positions);
        self.damping_entries(placed, &mut entries);
        self.nodal_entries(placed, &mut entries);
        let inverse_h2 = 1.0 / (self.h * self.h);
        for (slots, m) in self.unknowns.index.iter().zip(self.body.masses()) {
            for k in slots.iter().flatten() {
                entries.push(Triplet::new(*k, *k, m * inverse_h2));
            }
        }
        self.unknowns.solve(&entries, residual, iteration)
    }
}

impl Step<'_> {
    /// The per-node terms' tangent entries where `placed` is.
    fn nodal_entries(&self, placed: &Placed<'_>, entries: &mut Vec<Entry>) {
        let Some(nodal) = self.nodal else {
            return;
        };
        for (node, k) in nodal.stiffness(&placed.positions) {
            let slots = self.unknowns.index[node];
            for (a, row) in slots.iter().enumerate() {
                for (b, col) in slots.iter().enumerate() {
                    if let (Some(row), Some(col)) = (row, col) {
                        entries.push(Triplet::new(*row, *col, k.col(b)[a]));
                    }
                }
            }
        }
    }

    /// The damping's tangent entries where `placed` is.
    fn damping_entries(&self, placed: &Placed<'_>, entries: &mut Vec<Entry>) {
        let Some((damping, previous)) = &self.damping else {
            return;
        };
        let body = self.body;
        let index = &self.unknowns.index;
        let points = body.points();
        for (q, previous) in previous.iter().enumerate() {
            let f = embed_flat(&points.gradient(q, &placed.positions));
            let nodes = points.nodes(q);
            let changes: Vec<DMat3> = (0..2 * nodes.len())
                .map(|k| {
                    embed_change(&points.gradient_change(q, k / 2, [DVec2::X, DVec2::Y][k % 2]))
                })
                .collect();
            for (k, change) in changes.iter().enumerate() {
                let Some(col) = index[nodes[k / 2] as usize][k % 2] else {
                    continue;
                };
                let [dp] = damping.step_first_piola_differentials(&f, previous, self.h, &[*change]);
                let dp = in_plane_block(&dp);
                for (i, &node_i) in nodes.iter().enumerate() {
                    let value = (-points.force(q, i, &dp, body.thickness())).to_array();
                    for (a, row) in index[node_i as usize].iter().enumerate() {
                        if let Some(row) = row {
                            entries.push(Triplet::new(*row, col, value[a]));
                        }
                    }
                }
            }
        }
    }
}

/// Advances `body` by one backward Euler step of `dt` (s) under `gravity` (m/s²) and the nodal
/// `loads` (N), Newton stopping at `settings.tolerance` of the larger of the external forces'
/// norm and the first out-of-balance force's (or at its round-off floor below 1e-6 of it).
///
/// # Errors
/// [`Error::InvalidTimeStep`], [`Error::NonFiniteInput`], [`Error::WrongNodeCount`],
/// [`Error::InvalidSetting`] for a bad tolerance, [`Error::IndefiniteStiffness`],
/// [`Error::StaticSolveDidNotConverge`] if Newton does not converge (the step's Newton is the
/// static solver's), [`Error::NonFiniteState`]. On error the body is left as it was.
pub fn step_implicit(
    body: &mut PlanarBody,
    dt: f64,
    gravity: DVec2,
    loads: &[DVec2],
    settings: &StaticSettings,
) -> Result<PlanarImplicitReport, Error> {
    step_implicit_with(body, (dt, gravity, loads), settings, None)
}

/// [`step_implicit`] with the per-node terms `nodal` in `Φ`: where the angular momentum is
/// given back, their forces at the step's end count with the external loads, their torque
/// about the centre of mass or about the hinge.
///
/// # Errors
/// Those of [`step_implicit`].
pub(super) fn step_implicit_with(
    body: &mut PlanarBody,
    (dt, gravity, loads): (f64, DVec2, &[DVec2]),
    settings: &StaticSettings,
    nodal: Option<&dyn NodePotential>,
) -> Result<PlanarImplicitReport, Error> {
    check_step(body, dt, gravity, loads)?;
    check_tolerance(settings.tolerance)?;
    let unknowns = Unknowns::new(body.pinned());
    let start = body.positions().to_vec();
    let velocities = unknowns.free_part(body.velocities().iter().copied());
    let predicted: Vec<DVec2> = start
        .iter()
        .zip(&velocities)
        .map(|(x, v)| *x + *v * dt)
        .collect();
    let external: Vec<DVec2> = (body.masses().iter().zip(loads))
        .map(|(m, f)| gravity * *m + *f)
        .collect();
    let damping = body.damping().map(|d| {
        let points = body.points();
        let previous = (0..points.len())
            .map(|q| green_strain(&embed_flat(&points.gradient(q, &start))))
            .collect();
        (body.plane().in_plane_damping(d), previous)
    });
    let step = Step {
        nodal,
        h: dt,
        start,
        predicted,
        external,
        unknowns,
        damping,
        body,
    };
    let (iterations, relative, positions) = newton(&step, settings)?;
    let new_velocities: Vec<DVec2> = positions
        .iter()
        .zip(&step.start)
        .map(|(x, x0)| (*x - *x0) / dt)
        .collect();
    let mut contact = vec![DVec2::ZERO; positions.len()];
    if let Some(nodal) = nodal {
        nodal.add_forces(&positions, &mut contact);
    }
    let (rotation, given) = angular_give_back(
        &step,
        (loads, &contact),
        &velocities,
        &positions,
        &new_velocities,
    );
    let velocities: Vec<DVec2> = (new_velocities.iter().zip(&positions))
        .map(|(v, x)| *v + rotation(*x))
        .collect();
    if let Some(node) =
        (positions.iter().zip(&velocities)).position(|(x, v)| !(x.is_finite() && v.is_finite()))
    {
        return Err(Error::NonFiniteState { node });
    }
    body.positions_mut().copy_from_slice(&positions);
    body.velocities_mut().copy_from_slice(&velocities);
    Ok(PlanarImplicitReport {
        newton_iterations: iterations,
        relative_residual: relative,
        angular_momentum_given_back: given,
    })
}

/// Newton's iterations of a step from the better of the prediction and the start: the
/// iterations, the final relative residual and the positions (m).
fn newton(step: &Step<'_>, settings: &StaticSettings) -> Result<(usize, f64, Vec<DVec2>), Error> {
    let placed_at = |positions: &[DVec2]| Placed {
        body: step.body,
        positions: positions.to_vec(),
    };
    let (predicted, start) = (placed_at(&step.predicted), placed_at(&step.start));
    let mut placed = if step.potential(&start) < step.potential(&predicted) {
        start
    } else {
        predicted
    };
    let (iterations, relative) = minimize(step, &mut placed, norm(&step.external), settings)?;
    Ok((iterations, relative, placed.positions))
}

/// The rigid rotation's velocity field (m/s at a position) that gives back the angular
/// momentum the step took, and that angular momentum (kg m²/s); see the module's documentation.
/// `before` and `after` are the velocities (m/s) at the step's start and end, `positions` its
/// end; `loads` the nodal loads (N) and `contact` the per-node terms' forces (N) at the end.
fn angular_give_back(
    step: &Step<'_>,
    (loads, contact): (&[DVec2], &[DVec2]),
    before: &[DVec2],
    positions: &[DVec2],
    after: &[DVec2],
) -> (impl Fn(DVec2) -> DVec2 + use<>, f64) {
    let body = step.body;
    let masses = body.masses();
    let held: Vec<usize> = (body.pinned().iter().enumerate())
        .filter(|(_, p)| p[0] || p[1])
        .map(|(i, _)| i)
        .collect();
    let hinge = match held[..] {
        [] => None,
        [node] if body.pinned()[node] == [true, true] => Some(node),
        _ => return (rotation_about(DVec2::ZERO, 0.0), 0.0),
    };
    let mass = body.total_mass();
    let centre_of =
        |x: &[DVec2]| (masses.iter().zip(x)).map(|(m, x)| *x * *m).sum::<DVec2>() / mass;
    let (centre, target, actual) = match hinge {
        None => {
            let (c0, c1) = (centre_of(&step.start), centre_of(positions));
            let (v0, v1) = (centre_of(before), centre_of(after));
            let spin = |x: &[DVec2], v: &[DVec2], c: DVec2, vc: DVec2| -> f64 {
                (masses.iter().zip(x).zip(v))
                    .map(|((m, x), v)| m * (*x - c).perp_dot(*v - vc))
                    .sum()
            };
            let torque: f64 = (positions.iter().zip(loads).zip(contact))
                .map(|((x, f), c)| (*x - c1).perp_dot(*f + *c))
                .sum();
            (
                c1,
                spin(&step.start, before, c0, v0) + step.h * torque,
                spin(positions, after, c1, v1),
            )
        }
        Some(node) => {
            let p = step.start[node];
            let about = |x: &[DVec2], v: &[DVec2]| -> f64 {
                (masses.iter().zip(x).zip(v))
                    .map(|((m, x), v)| m * (*x - p).perp_dot(*v))
                    .sum()
            };
            let torque: f64 = (step.start.iter().zip(&step.external))
                .map(|(x, f)| (*x - p).perp_dot(*f))
                .sum::<f64>()
                + (positions.iter().zip(contact))
                    .map(|(x, c)| (*x - p).perp_dot(*c))
                    .sum::<f64>();
            (
                p,
                about(&step.start, before) + step.h * torque,
                about(positions, after),
            )
        }
    };
    let inertia: f64 = (masses.iter().zip(positions))
        .map(|(m, x)| m * (*x - centre).length_squared())
        .sum();
    let given = target - actual;
    (rotation_about(centre, given / inertia), given)
}

/// The velocity field (m/s) of a rotation at `omega` (rad/s) about `centre` (m).
fn rotation_about(centre: DVec2, omega: f64) -> impl Fn(DVec2) -> DVec2 + use<> {
    move |x: DVec2| (x - centre).perp() * omega
}

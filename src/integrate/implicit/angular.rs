//! The angular momentum a backward Euler step takes from a body's motion, given back.
//!
//! Backward Euler keeps linear momentum exactly (internal forces sum to zero) but not angular
//! momentum. With `x₁ = x₀ + h v₁` and `m (v₁ − v₀) = h f` per node, `f` every force at `x₁`,
//! the step ends with `L₁ = Σ m x₁ × v₁ = Σ m x₀ × v₁ = L₀ + h Σ x₀ × f`. The forces' angular
//! impulse at the arms they act at is `h Σ x₁ × f` (the internal and damping forces of an
//! objective material have no torque about the configuration they are evaluated in), so the step
//! falls short by
//!
//! `δL = h Σ (x₁ − x₀) × f = h² Σ v₁ × f = h Σ m v₀ × v₁`,
//!
//! a numerical torque of order `h²` that drains spin: a free cube spinning at 5 rad/s loses two
//! thirds of its angular momentum in 10 s of 1/60 s steps. It does not depend on where angular
//! momentum is measured from, and pinned nodes (at rest) add nothing to it.
//!
//! Contract: after a backward Euler step, `δL` is given back as a rigid rotation of the free
//! nodes, `Δv = δω × (x₁ − c)`, the rotations the pins allow: about the centre of mass `c` with
//! `I_c δω = δL` when nothing is pinned (linear momentum unchanged: `Σ m Δv = 0`); about a single
//! pinned point `c`, `I_c δω = δL`; about the line through collinear pinned nodes (a hinge),
//! `δω = a (a·δL) / I_a`; none when the pins hold every rotation. Nodes glued to rigid bodies
//! that do not move (fixed, or kinematic at rest) count as pins here when their anchors lie at
//! one point or on one line (a body glued by a face is given the drain about its centre of mass,
//! as a free body). The step's positions are kept;
//! only the velocities it ends with change. The deformation's numerical damping is untouched.
//!
//! A pinned body swings under its constant loads `F` (its weight): their torque about the pins
//! stays at the step's start, `L₁ = L₀ + k Σ (x₀ − c) × F` (the load's share of `δL` is not
//! given back), with the kick `k = (h₀ + h)/2` over the last step `h₀` and this one. About the
//! pins the rotation is then stepped as leapfrog steps it (`ω` the velocity of the half step,
//! the angle advanced by `h ω`), which keeps a swing's energy however the substeps' length
//! changes from step to step; with the torque at the step's end, or with `k = h` when the
//! substeps' length follows the swing's speed, the swing loses energy every half period.
//! A body that only its weight and dynamic rigid bodies act on is given, the same way, what makes
//! its angular momentum change by exactly the angular impulse they gave it, counted where the
//! rigid bodies take the opposite ([`keep_exchanged`]): the exchange is then exact, the drain
//! and the Newton tolerance's share included.

use crate::body::{DeformableBody, spin_of};
use rapier3d::glamx::DVec3;

/// Pinned nodes further than this fraction of the body's size from the line through the two
/// furthest apart are not collinear (dimensionless).
const COLLINEAR: f64 = 1e-9;

/// Gives back to `body` the angular momentum a backward Euler step of `h` (s) took, its nodes
/// having started it at `positions` (m) and `velocities` (m/s) under the constant forces `load`
/// (N per node), the step before it `previous` (s) long, glued at the anchors `still` (m) to
/// rigid bodies that do not move; see the module documentation.
pub(super) fn give_back(
    body: &mut DeformableBody,
    (positions, velocities, load): (&[DVec3], &[DVec3], &[DVec3]),
    still: &[DVec3],
    (h, previous): (f64, Option<f64>),
) {
    let Some(pivot) = pivot(body, still) else {
        return;
    };
    let free = |n: &usize| !body.pinned[*n];
    let mut lost: DVec3 = (0..body.positions.len())
        .filter(free)
        .map(|n| velocities[n].cross(body.velocities[n]) * (body.masses[n] * h))
        .sum();
    if let Pivot::Point(centre) | Pivot::Hinge(centre, _) = pivot {
        // A swing: the loads' torque about the pins at the step's start, over the kick.
        let kick = previous.map_or(h, |previous| (previous + h) / 2.0);
        lost += (0..body.positions.len())
            .filter(free)
            .map(|n| {
                (positions[n] - centre).cross(load[n]) * (kick - h)
                    - body.velocities[n].cross(load[n]) * (h * h)
            })
            .sum::<DVec3>();
    }
    turn_about(body, pivot, lost);
}

/// Gives back to `body`, free (nothing pinned, nothing but uniform gravity and its own forces
/// acting on it over the step), the angular momentum about its centre of mass it started the
/// step with at `positions` (m) and `velocities` (m/s): all it has lost, the drain `δL` and
/// what the Newton solve's tolerance left (its residual's torque), so that a free body's spin is
/// kept to round-off however loosely each step is solved.
pub(super) fn keep_free_spin(body: &mut DeformableBody, positions: &[DVec3], velocities: &[DVec3]) {
    let start = momentum_about_centre(positions, velocities, &body.masses);
    let now = body.angular_momentum();
    turn_by(body, start - now);
}

/// Gives `body` what makes its angular momentum about the origin the one it started the step
/// with at `positions` (m) and `velocities` (m/s) plus `received` (N m s), the angular impulse
/// about the origin of everything that acted on it over the step.
pub(super) fn keep_exchanged(
    body: &mut DeformableBody,
    (positions, velocities): (&[DVec3], &[DVec3]),
    received: DVec3,
) {
    let start = momentum_about(DVec3::ZERO, (positions, velocities), &body.masses);
    let now = momentum_about(
        DVec3::ZERO,
        (&body.positions, &body.velocities),
        &body.masses,
    );
    turn_by(body, start + received - now);
}

/// The angular momentum (N m s) of nodes at `positions` (m) moving at `velocities` (m/s) with
/// `masses` (kg) about their centre of mass: [`DeformableBody::angular_momentum`] of a state the
/// body had.
fn momentum_about_centre(positions: &[DVec3], velocities: &[DVec3], masses: &[f64]) -> DVec3 {
    let total: f64 = masses.iter().sum();
    let centre = positions
        .iter()
        .zip(masses)
        .map(|(x, m)| *x * *m)
        .sum::<DVec3>()
        / total;
    momentum_about(centre, (positions, velocities), masses)
}

/// The angular momentum (N m s) about `point` (m) of nodes at `positions` (m) moving at
/// `velocities` (m/s) with `masses` (kg).
fn momentum_about(
    point: DVec3,
    (positions, velocities): (&[DVec3], &[DVec3]),
    masses: &[f64],
) -> DVec3 {
    (positions.iter().zip(velocities).zip(masses))
        .map(|((x, v), m)| (*x - point).cross(*v) * *m)
        .sum()
}

/// Adds to the free nodes of `body` the rotation the pins allow whose angular momentum is `lost`
/// (N m s).
fn turn_by(body: &mut DeformableBody, lost: DVec3) {
    if let Some(pivot) = pivot(body, &[]) {
        turn_about(body, pivot, lost);
    }
}

/// Adds to the free nodes of `body` the rotation about `pivot` whose angular momentum is `lost`
/// (N m s).
fn turn_about(body: &mut DeformableBody, pivot: Pivot, lost: DVec3) {
    if lost == DVec3::ZERO || !lost.is_finite() {
        return;
    }
    let Some((centre, turn)) = pivot.rotation(body, lost) else {
        return;
    };
    for n in 0..body.positions.len() {
        if !body.pinned[n] {
            body.velocities[n] += turn.cross(body.positions[n] - centre);
        }
    }
}

/// How fast `body` turns (rad/s): its angular momentum about its centre of mass over its inertia
/// there, `|I_c⁻¹ L_c|`; zero for a body whose nodes lie on one line.
pub(super) fn spin(body: &DeformableBody) -> f64 {
    let inertia = body.inertia_about(body.center_of_mass());
    spin_of(inertia, body.angular_momentum()).map_or(0.0, |turn| turn.length())
}

/// What the pins of a body leave it free to turn about.
#[derive(Clone, Copy)]
enum Pivot {
    /// Nothing pinned: its centre of mass (m).
    Free(DVec3),
    /// Its pinned nodes all at one point (m).
    Point(DVec3),
    /// Its pinned nodes on one line: a point of it (m) and its direction (unit).
    Hinge(DVec3, DVec3),
}

/// What the pins of `body` and its anchors `still` (m) on rigid bodies that do not move leave it
/// free to turn about, or `None` when pins hold every rotation. Anchors that hold every rotation
/// without pins (a body glued by a face) leave the centre of mass, as a free body's.
fn pivot(body: &DeformableBody, still: &[DVec3]) -> Option<Pivot> {
    let pinned = (0..body.positions.len())
        .filter(|&n| body.pinned[n])
        .map(|n| body.positions[n]);
    let held: Vec<DVec3> = pinned.chain(still.iter().copied()).collect();
    let Some(&first) = held.first() else {
        return Some(Pivot::Free(body.center_of_mass()));
    };
    let far = held.iter().copied().max_by(|a, b| {
        (*a - first)
            .length_squared()
            .total_cmp(&(*b - first).length_squared())
    })?;
    let span = (far - first).length();
    let size = (body.positions.iter())
        .map(|x| (*x - first).length())
        .fold(f64::MIN_POSITIVE, f64::max);
    if span <= COLLINEAR * size {
        return Some(Pivot::Point(first));
    }
    let axis = (far - first) / span;
    let off_line = |p: &DVec3| (*p - first).cross(axis).length() > COLLINEAR * size;
    if !held.iter().any(off_line) {
        Some(Pivot::Hinge(first, axis))
    } else if body.pinned.contains(&true) {
        None
    } else {
        Some(Pivot::Free(body.center_of_mass()))
    }
}

impl Pivot {
    /// The rotation about the pivot (its centre, m, and angular velocity, rad/s) whose angular
    /// momentum is `lost` (N m s), or `None` for a body without inertia about it.
    fn rotation(self, body: &DeformableBody, lost: DVec3) -> Option<(DVec3, DVec3)> {
        match self {
            Pivot::Free(centre) | Pivot::Point(centre) => {
                spin_of(body.inertia_about(centre), lost).map(|turn| (centre, turn))
            }
            Pivot::Hinge(centre, axis) => {
                let about_axis: f64 = (0..body.positions.len())
                    .map(|n| {
                        body.masses[n] * (body.positions[n] - centre).cross(axis).length_squared()
                    })
                    .sum();
                (about_axis > 0.0).then(|| (centre, axis * (axis.dot(lost) / about_axis)))
            }
        }
    }
}

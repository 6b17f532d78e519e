//! Contacts with colliders inside an implicit step (feature `dim2`): the penalty of
//! [`super::coupling`] written as a potential, so that backward Euler takes it with the body's
//! elasticity ([`super::implicit`]'s `Φ`), the colliders frozen where the step starts.
//!
//! - **Normal.** A node `d` (m) inside a collider along its outward normal `n` stores
//!   `k d²/2`: force `k d n`, stiffness `k n nᵀ` (the turning of `n` along the surface left
//!   out, exact on flat faces). `k` is the body's contact stiffness (N/m).
//! - **Friction**, lagged as in incremental-potential contact (Li et al. 2020): a node pressing
//!   at the step's start with `λ = k d₀` along `n₀` resists its sliding over the step,
//!   `u = (x − x₀ − h v_c)·t₀` (`t₀ = n₀⊥`, `v_c` the collider's velocity there), with the
//!   potential `μ λ F(u)`, `F(u) = u²/ε − |u|³/(3ε²) + ε/3` below `ε = STICKING_SPEED h` and
//!   `|u|` above: the friction force `μ λ min(1, 2|u|/ε − u²/ε²)` is Coulomb's above the sliding
//!   speed [`STICKING_SPEED`], as in the explicit step (below it the explicit step's viscous
//!   law has half this one's slope at rest), and its stiffness `μ λ (2/ε − 2|u|/ε²) t₀ t₀ᵀ`
//!   below it.
//!
//! - **Glue** to fixed and kinematic rigid bodies: a glued node is held to where its anchor
//!   will be at the step's end by a spring of the same `k`, `k |x − a|²/2`.
//!
//! No damping term: backward Euler damps the contact's and the glue's own vibration (frequency
//! `√(k/m)`, far above `1/h`) by itself.

use super::body::PlanarBody;
use super::colliders::ColliderView;
use super::coupling::STICKING_SPEED;
use super::dynamics::PlanarStepReport;
use super::glue::GlueView;
use super::implicit::{NodePotential, step_implicit_with};
use crate::Error;
use crate::statics::StaticSettings;
use rapier2d::glamx::{DMat2, DVec2};

/// What an implicit step did: its report, and the impulses (N s) it gave each collider
/// (indexed as the step's colliders) and the rigid body of each glued node (by the glue's
/// index).
type SteppedInContact = (PlanarStepReport, Vec<DVec2>, Vec<(usize, DVec2)>);

/// One backward Euler step of `body` over `h` (s) under `gravity` (m/s²) against `colliders`
/// (frozen where they are) and held by the `glued` nodes (each with its glue's index; their
/// anchors where they will be at the step's end), with contact and glue stiffness `k` (N/m)
/// and friction `mu`: its report, and the impulses it gave the colliders and glued rigid
/// bodies.
///
/// # Errors
/// Those of [`super::step_implicit`]; the body is left as it was.
pub(super) fn step_in_contact(
    body: &mut PlanarBody,
    (colliders, glued): (&[ColliderView], &[(usize, &GlueView)]),
    (k, mu): (f64, f64),
    (h, gravity): (f64, DVec2),
) -> Result<SteppedInContact, Error> {
    let mut potential = ContactPotential::new(colliders, body.positions(), (k, mu), h);
    potential.anchors = (glued.iter())
        .map(|(_, g)| (g.node, g.anchor_after(h)))
        .collect();
    let loads = vec![DVec2::ZERO; body.positions().len()];
    let settings = StaticSettings::default();
    step_implicit_with(body, (h, gravity, &loads), &settings, Some(&potential))?;
    let x = body.positions();
    let mut impulses = vec![DVec2::ZERO; colliders.len()];
    for (c, _, force) in potential.forces_by_collider(x) {
        impulses[c] -= force * h;
    }
    let glue_impulses = (glued.iter().zip(&potential.anchors))
        .map(|((g, _), (node, anchor))| (*g, (x[*node] - *anchor) * (k * h)))
        .collect();
    let report = PlanarStepReport {
        substeps: 1,
        substep_dt: h,
        implicit: true,
    };
    Ok((report, impulses, glue_impulses))
}

/// A node pressing on a collider at the step's start, for the lagged friction.
struct Pressing {
    node: usize,
    /// The collider it presses on (index into the step's colliders).
    collider: usize,
    /// The normal force (N) at the start.
    normal_force: f64,
    /// The sliding direction at the start (unit).
    tangent: DVec2,
    /// Where the collider's material at the node takes it over the step (m), along `tangent`.
    carried: f64,
}

/// The contact terms of one body's implicit step against `colliders`.
pub(super) struct ContactPotential<'a> {
    colliders: &'a [ColliderView],
    /// Contact stiffness (N/m) and friction coefficient.
    stiffness: f64,
    friction: f64,
    /// Where the nodes start (m), and the smoothing width `ε` (m) of friction.
    start: Vec<DVec2>,
    smoothing: f64,
    pressing: Vec<Pressing>,
    /// Glued nodes and where their anchors are at the step's end (m), held by springs of the
    /// contact stiffness.
    anchors: Vec<(usize, DVec2)>,
}

impl<'a> ContactPotential<'a> {
    /// The terms of a step of `h` (s) from `start` (m) against `colliders`, with contact
    /// stiffness `k` (N/m) and friction coefficient `mu`.
    pub(super) fn new(
        colliders: &'a [ColliderView],
        start: &[DVec2],
        (k, mu): (f64, f64),
        h: f64,
    ) -> Self {
        let mut pressing = Vec::new();
        for (node, x) in start.iter().enumerate() {
            for (collider, view) in colliders.iter().enumerate() {
                if let Some((depth, normal)) = view.penetration(*x) {
                    let tangent = normal.perp();
                    pressing.push(Pressing {
                        node,
                        collider,
                        normal_force: k * depth,
                        tangent,
                        carried: view.velocity_at(*x).dot(tangent) * h,
                    });
                }
            }
        }
        Self {
            colliders,
            stiffness: k,
            friction: mu,
            start: start.to_vec(),
            smoothing: STICKING_SPEED * h,
            pressing,
            anchors: Vec::new(),
        }
    }

    /// Each node's penetration into each collider at `x` (m): `(node, collider, depth (m),
    /// outward normal)`.
    fn penetrations<'b>(
        &'b self,
        x: &'b [DVec2],
    ) -> impl Iterator<Item = (usize, usize, f64, DVec2)> + 'b {
        x.iter().enumerate().flat_map(move |(node, x)| {
            (self.colliders.iter().enumerate())
                .filter_map(move |(c, view)| view.penetration(*x).map(|(d, n)| (node, c, d, n)))
        })
    }

    /// A pressing node's sliding `u` (m) over the step at `x`.
    fn sliding(&self, p: &Pressing, x: &[DVec2]) -> f64 {
        (x[p.node] - self.start[p.node]).dot(p.tangent) - p.carried
    }

    /// The contact forces (N) on the nodes at `x` with the collider each comes from:
    /// `(collider, node, force)`.
    fn forces_by_collider(&self, x: &[DVec2]) -> Vec<(usize, usize, DVec2)> {
        let normal = (self.penetrations(x))
            .map(|(node, c, depth, normal)| (c, node, normal * (self.stiffness * depth)));
        let friction =
            (self.pressing.iter()).map(|p| (p.collider, p.node, self.friction_force(p, x)));
        normal.chain(friction).collect()
    }

    /// The friction force (N) on a pressing node at `x`.
    fn friction_force(&self, p: &Pressing, x: &[DVec2]) -> DVec2 {
        let u = self.sliding(p, x);
        let (eps, a) = (self.smoothing, u.abs());
        let scale = if a >= eps {
            1.0
        } else {
            2.0 * a / eps - a * a / (eps * eps)
        };
        -p.tangent * (self.friction * p.normal_force * scale * u.signum())
    }
}

impl NodePotential for ContactPotential<'_> {
    fn energy(&self, x: &[DVec2]) -> f64 {
        let normal: f64 = self
            .penetrations(x)
            .map(|(.., depth, _)| 0.5 * self.stiffness * depth * depth)
            .sum();
        let eps = self.smoothing;
        let friction: f64 = (self.pressing.iter())
            .map(|p| {
                let a = self.sliding(p, x).abs();
                let f = if a >= eps {
                    a
                } else {
                    a * a / eps - a * a * a / (3.0 * eps * eps) + eps / 3.0
                };
                self.friction * p.normal_force * f
            })
            .sum();
        let glue: f64 = (self.anchors.iter())
            .map(|(node, anchor)| 0.5 * self.stiffness * x[*node].distance_squared(*anchor))
            .sum();
        normal + friction + glue
    }

    fn add_forces(&self, x: &[DVec2], forces: &mut [DVec2]) {
        for (node, _, depth, normal) in self.penetrations(x) {
            forces[node] += normal * (self.stiffness * depth);
        }
        for p in &self.pressing {
            forces[p.node] += self.friction_force(p, x);
        }
        for (node, anchor) in &self.anchors {
            forces[*node] += (*anchor - x[*node]) * self.stiffness;
        }
    }

    fn stiffness(&self, x: &[DVec2]) -> Vec<(usize, DMat2)> {
        let outer = |a: DVec2| DMat2::from_cols(a * a.x, a * a.y);
        let mut blocks: Vec<(usize, DMat2)> = self
            .penetrations(x)
            .map(|(node, .., normal)| (node, outer(normal) * self.stiffness))
            .collect();
        let eps = self.smoothing;
        for p in &self.pressing {
            let a = self.sliding(p, x).abs();
            if a < eps {
                let slope = 2.0 / eps - 2.0 * a / (eps * eps);
                let k = self.friction * p.normal_force * slope;
                blocks.push((p.node, outer(p.tangent) * k));
            }
        }
        let glue = DMat2::IDENTITY * self.stiffness;
        blocks.extend(self.anchors.iter().map(|(node, _)| (*node, glue)));
        blocks
    }
}

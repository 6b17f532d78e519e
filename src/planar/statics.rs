//! Static equilibrium of a 2D body: `f_int(x) + f_ext = 0` with the held nodes held, by
//! Newton's method on the total potential energy `Π = E(x) − f_ext · (x − x₀)` with the sparse
//! tangent `K = −∂f_int/∂x` (faer's Cholesky factorization) and the line search, tolerance and
//! round-off floor of the 3D solver ([`crate::statics`], through [`crate::newton`]). The linear
//! law converges in one iteration.

use super::body::PlanarBody;
use super::unknowns::{Minimized, Placed, Unknowns, minimize};
use crate::Error;
use crate::newton::{check_tolerance, norm};
use crate::statics::{StaticReport, StaticSettings};
use rapier3d::glamx::DVec2;

/// The nodal forces (N) of a uniform `traction` along the polyline of `nodes` (in order along
/// the edge, as [`PlanarBody::nodes_on_line`] gives them): N per m of edge length and per m of
/// thickness, or with `total` = true a total load (N) spread evenly along the edge. Each
/// segment's load goes to its ends in halves; on quadratic triangles each element edge (corner,
/// mid-edge node, corner) takes it in the consistent shares 1/6, 2/3, 1/6.
pub fn edge_loads(body: &PlanarBody, nodes: &[usize], traction: DVec2, total: bool) -> Vec<DVec2> {
    let rest = body.rest_positions();
    let mut loads = vec![DVec2::ZERO; rest.len()];
    let distance = |a: usize, b: usize| rest[a].distance(rest[b]);
    let length: f64 = nodes.windows(2).map(|w| distance(w[0], w[1])).sum();
    let per_length = if total {
        traction / length
    } else {
        traction * body.thickness()
    };
    if body.is_quadratic() {
        for edge in nodes.windows(3).step_by(2) {
            let load = per_length * distance(edge[0], edge[2]);
            loads[edge[0]] += load / 6.0;
            loads[edge[1]] += load * (2.0 / 3.0);
            loads[edge[2]] += load / 6.0;
        }
    } else {
        for w in nodes.windows(2) {
            let share = per_length * distance(w[0], w[1]) / 2.0;
            loads[w[0]] += share;
            loads[w[1]] += share;
        }
    }
    loads
}

/// One static problem: the nodal loads (N), the free unknowns, and the positions (m) the
/// loads' work is measured from.
struct Problem<'a> {
    loads: &'a [DVec2],
    unknowns: Unknowns,
    start: Vec<DVec2>,
}

impl Minimized for Problem<'_> {
    /// The out-of-balance force `f_int + f_ext` (N) per node where `placed` is, zero along
    /// held axes.
    fn residual(&self, placed: &Placed<'_>) -> Vec<DVec2> {
        let forces = placed.body.internal_forces_at(&placed.positions);
        (self.unknowns).free_part(forces.iter().zip(self.loads).map(|(f, load)| *f + *load))
    }

    /// The total potential energy `E(x) − f_ext · (x − x₀)` (J) where `placed` is.
    fn potential(&self, placed: &Placed<'_>) -> f64 {
        let work: f64 = (placed.positions.iter().zip(&self.start).zip(self.loads))
            .map(|((x, x0), f)| (*x - *x0).dot(*f))
            .sum();
        placed.body.elastic_energy_at(&placed.positions) - work
    }

    /// The Newton direction `K⁻¹ r` (m per node) for `residual` where `placed` is, at Newton's
    /// `iteration`.
    fn direction(
        &self,
        placed: &Placed<'_>,
        residual: &[DVec2],
        iteration: usize,
    ) -> Result<Vec<DVec2>, Error> {
        let entries = (self.unknowns).elastic_entries(placed.body, &placed.positions);
        self.unknowns.solve(&entries, residual, iteration)
    }
}

/// Checks the `loads` (one per node, finite) and the body's positions (finite).
fn check_input(body: &PlanarBody, loads: &[DVec2]) -> Result<(), Error> {
    let node_count = body.positions().len();
    if loads.len() != node_count {
        return Err(Error::WrongNodeCount {
            given: loads.len(),
            node_count,
        });
    }
    if loads.iter().any(|f| !f.is_finite()) {
        return Err(Error::NonFiniteInput { parameter: "loads" });
    }
    match body.positions().iter().position(|x| !x.is_finite()) {
        Some(node) => {
            let p = body.positions()[node];
            Err(Error::NonFiniteCoordinate {
                node,
                position: [p.x, p.y, 0.0],
            })
        }
        None => Ok(()),
    }
}

/// Moves `body` to static equilibrium under the nodal `loads` (N, one per node) with its held
/// nodes held, as [`crate::statics::solve_equilibrium`] does a 3D body: until the out-of-balance
/// force is below `settings.tolerance` times the larger of the loads' norm and the first
/// out-of-balance force's (so that a body deformed by its held nodes alone converges too), or
/// sits at its round-off floor below 1e-6 of it.
///
/// # Errors
/// [`Error::InvalidSetting`] for a tolerance that is not positive and finite,
/// [`Error::WrongNodeCount`] for loads of the wrong length, [`Error::NonFiniteInput`] for a
/// non-finite load, [`Error::NonFiniteCoordinate`] for a position made non-finite,
/// [`Error::NoFreeNode`], [`Error::AllocationFailed`], [`Error::IndefiniteStiffness`] (too few
/// held nodes), [`Error::StaticSolveDidNotConverge`]. On error the body is left as it was.
pub fn solve_planar_equilibrium(
    body: &mut PlanarBody,
    loads: &[DVec2],
    settings: &StaticSettings,
) -> Result<StaticReport, Error> {
    check_tolerance(settings.tolerance)?;
    check_input(body, loads)?;
    let unknowns = Unknowns::new(&body.pinned);
    if unknowns.count == 0 {
        return Err(Error::NoFreeNode);
    }
    let start = body.positions().to_vec();
    let problem = Problem {
        loads,
        unknowns,
        start: start.clone(),
    };
    let mut placed = Placed {
        body,
        positions: start,
    };
    let (iterations, relative_residual) = minimize(&problem, &mut placed, norm(loads), settings)?;
    let positions = placed.positions;
    body.positions_mut().copy_from_slice(&positions);
    Ok(StaticReport {
        iterations,
        relative_residual,
    })
}

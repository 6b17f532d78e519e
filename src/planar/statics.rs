//! Static equilibrium of a 2D body: `f_int(x) + f_ext = 0` with the pinned nodes held, by
//! Newton's method on the total potential energy `Π = E(x) − f_ext · x` with the sparse tangent
//! `K = −∂f_int/∂x` (faer's Cholesky factorization, as in 3D) and a backtracking line search on
//! `Π`. The linear law converges in one iteration.

use super::body::PlanarBody;
use crate::Error;
use crate::assembly::{Factor, SymbolicFactor};
use crate::statics::{StaticReport, StaticSettings};
use faer::Mat;
use faer::sparse::{SparseColMat, Triplet};
use rapier3d::glamx::DVec2;

/// Halvings allowed to a Newton step before the line search gives up.
const MAX_HALVINGS: usize = 30;

/// The nodal forces (N) of a uniform `traction` (N per m of edge length, per m of thickness
/// times the body's thickness gives N) along the polyline of `nodes` (in order along the edge):
/// each segment's load shared equally by its two ends. With `total` = true the traction is
/// scaled so that the forces sum to `traction` itself (a total load in N).
pub fn edge_loads(body: &PlanarBody, nodes: &[usize], traction: DVec2, total: bool) -> Vec<DVec2> {
    let rest = body.mesh().rest_positions();
    let mut loads = vec![DVec2::ZERO; rest.len()];
    let length: f64 = nodes
        .windows(2)
        .map(|w| rest[w[0]].distance(rest[w[1]]))
        .sum();
    let per_length = if total {
        traction / length
    } else {
        traction * body.thickness()
    };
    for w in nodes.windows(2) {
        let share = per_length * rest[w[0]].distance(rest[w[1]]) / 2.0;
        loads[w[0]] += share;
        loads[w[1]] += share;
    }
    loads
}

/// The free unknowns: for each node and axis, its index among the unknowns, or `None` if held
/// along that axis; and their count.
fn free_unknowns(pinned: &[[bool; 2]]) -> (Vec<[Option<usize>; 2]>, usize) {
    let mut next = 0;
    let mut number = |held: bool| {
        (!held).then(|| {
            next += 1;
            next - 1
        })
    };
    let index = pinned
        .iter()
        .map(|p| [number(p[0]), number(p[1])])
        .collect();
    (index, next)
}

/// The tangent `K = −∂f_int/∂x` (N/m) over the free unknowns at `positions`; `None` if faer
/// cannot hold it (its only failure with indices below `n`: memory).
fn tangent(
    body: &PlanarBody,
    positions: &[DVec2],
    index: &[[Option<usize>; 2]],
    n: usize,
) -> Option<SparseColMat<usize, f64>> {
    let mut triplets = Vec::with_capacity(body.triangle_rest().len() * 36);
    body.with_law(|law| {
        for (t, rest) in body.triangle_rest().iter().enumerate() {
            let f = rest.gradient(&body.corners_in(t, positions));
            let columns = law.tangent(&f);
            let nodes = body.mesh().triangles()[t];
            let normals = rest.normals();
            for (j, &node_j) in nodes.iter().enumerate() {
                for (b, direction) in [DVec2::X, DVec2::Y].into_iter().enumerate() {
                    let Some(col) = index[node_j as usize][b] else {
                        continue;
                    };
                    let df = rest.gradient_change(j, direction);
                    let dp = super::plane::apply_tangent(&columns, &df);
                    for (i, &node_i) in nodes.iter().enumerate() {
                        let k = (-(dp * normals[i]) * body.thickness()).to_array();
                        for (a, row) in index[node_i as usize].iter().enumerate() {
                            if let Some(row) = row {
                                triplets.push(Triplet::new(*row, col, k[a]));
                            }
                        }
                    }
                }
            }
        }
    });
    SparseColMat::try_new_from_triplets(n, n, &triplets).ok()
}

/// Where Newton's method is: the positions (m), the out-of-balance force `f_int + f_ext` (N)
/// over the free unknowns, and the scale (N) it is measured against: the larger of the loads'
/// norm and the internal forces' on every node (the held nodes' are the reactions).
struct Iterate {
    positions: Vec<DVec2>,
    residual: Vec<f64>,
    scale: f64,
}

impl Iterate {
    /// The residual's norm over its scale (dimensionless).
    fn relative_residual(&self) -> f64 {
        self.residual.iter().map(|v| v * v).sum::<f64>().sqrt() / self.scale
    }
}

/// One static problem: the body, its loads (N) and its free unknowns.
struct Problem<'a> {
    body: &'a PlanarBody,
    loads: &'a [DVec2],
    load_norm: f64,
    index: Vec<[Option<usize>; 2]>,
    n: usize,
}

impl Problem<'_> {
    /// The iterate at `positions` (m).
    fn at(&self, positions: Vec<DVec2>) -> Iterate {
        let forces = self.body.internal_forces_at(&positions);
        let internal = forces
            .iter()
            .map(|f| f.length_squared())
            .sum::<f64>()
            .sqrt();
        let mut residual = vec![0.0; self.n];
        for (node, slots) in self.index.iter().enumerate() {
            let f = (forces[node] + self.loads[node]).to_array();
            for (a, slot) in slots.iter().enumerate() {
                if let Some(k) = slot {
                    residual[*k] = f[a];
                }
            }
        }
        let scale = self.load_norm.max(internal).max(f64::MIN_POSITIVE);
        Iterate {
            positions,
            residual,
            scale,
        }
    }

    /// The total potential energy `E(x) − f_ext · x` (J) at `positions` (m).
    fn potential(&self, positions: &[DVec2]) -> f64 {
        let work: f64 = positions
            .iter()
            .zip(self.loads)
            .map(|(x, f)| x.dot(*f))
            .sum();
        self.body.elastic_energy_at(positions) - work
    }

    /// The Newton step `K⁻¹ r` (m) from `iterate`, the `iteration`-th.
    fn newton_step(&self, iterate: &Iterate, iteration: usize) -> Result<Mat<f64>, Error> {
        let k = tangent(self.body, &iterate.positions, &self.index, self.n).ok_or(
            Error::AllocationFailed {
                what: "the tangent of a 2D body",
                bytes: (self.body.triangle_rest().len() as u64).saturating_mul(36 * 24),
            },
        )?;
        let indefinite = Error::IndefiniteStiffness { iteration };
        let symbolic = SymbolicFactor::try_new(k.symbolic()).ok_or(indefinite.clone())?;
        let factor = Factor::try_new(symbolic, k.as_ref()).ok_or(indefinite)?;
        let mut step = Mat::from_fn(self.n, 1, |i, _| iterate.residual[i]);
        factor.solve_in_place(step.as_mut());
        Ok(step)
    }

    /// The first of the step's halvings from `iterate` that lowers the potential or the
    /// out-of-balance force, if one does within [`MAX_HALVINGS`].
    fn line_search(&self, iterate: &Iterate, step: &Mat<f64>) -> Option<Iterate> {
        let start = self.potential(&iterate.positions);
        let mut alpha = 1.0;
        for _ in 0..MAX_HALVINGS {
            let mut trial = iterate.positions.clone();
            for (node, slots) in self.index.iter().enumerate() {
                for (a, slot) in slots.iter().enumerate() {
                    if let Some(k) = slot {
                        trial[node][a] += step[(*k, 0)] * alpha;
                    }
                }
            }
            let lower = self.potential(&trial) <= start;
            let next = self.at(trial);
            if lower
                || next.relative_residual() * next.scale
                    < iterate.relative_residual() * iterate.scale
            {
                return Some(next);
            }
            alpha *= 0.5;
        }
        None
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

/// Moves `body` to static equilibrium under the nodal `loads` (N, one per node) with its pinned
/// nodes held: until the out-of-balance force is below `settings.tolerance` times the larger of
/// the loads' norm and the internal forces' (the reactions of held nodes included), so that a
/// body deformed by its held nodes alone converges too.
///
/// # Errors
/// [`Error::WrongNodeCount`] for loads of the wrong length, [`Error::NonFiniteInput`] for a
/// non-finite load, [`Error::NonFiniteCoordinate`] for a position made non-finite,
/// [`Error::NoFreeNode`], [`Error::AllocationFailed`], [`Error::IndefiniteStiffness`] (too few
/// held nodes), [`Error::StaticSolveDidNotConverge`]. On error the body is left as it was.
pub fn solve_planar_equilibrium(
    body: &mut PlanarBody,
    loads: &[DVec2],
    settings: &StaticSettings,
) -> Result<StaticReport, Error> {
    check_input(body, loads)?;
    let (index, n) = free_unknowns(&body.pinned);
    if n == 0 {
        return Err(Error::NoFreeNode);
    }
    let load_norm = loads.iter().map(|f| f.length_squared()).sum::<f64>().sqrt();
    let problem = Problem {
        body,
        loads,
        load_norm,
        index,
        n,
    };
    let mut iterate = problem.at(body.positions().to_vec());
    let mut iterations = 0;
    while iterate.relative_residual() > settings.tolerance {
        if iterations == settings.max_iterations {
            return Err(Error::StaticSolveDidNotConverge {
                iterations,
                residual: iterate.relative_residual(),
            });
        }
        let step = problem.newton_step(&iterate, iterations)?;
        iterations += 1;
        iterate = problem
            .line_search(&iterate, &step)
            .ok_or(Error::StaticSolveDidNotConverge {
                iterations,
                residual: iterate.relative_residual(),
            })?;
    }
    let relative_residual = iterate.relative_residual();
    body.positions_mut().copy_from_slice(&iterate.positions);
    Ok(StaticReport {
        iterations,
        relative_residual,
    })
}

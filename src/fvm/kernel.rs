//! The force kernel: `f_i = P b_i` per tetrahedron, and the loop that sums it over a mesh into
//! nodal forces without allocating.
//!
//! [`tet_forces`] is the scalar reference. The mesh loop evaluates four tetrahedra at once, one
//! per SIMD lane ([`crate::lanes`]), with the same formulas, and adds each tetrahedron's forces to
//! its nodes in ascending tetrahedron order. Each tetrahedron's forces are weighted by its
//! [stiffness weight](FvmMesh::tet_weight), its rest volume unless the body's materials differ
//! by region (then the reference's forces times the tetrahedron's `E_e/E`).
//!
//! Large meshes are cut into fixed chunks of consecutive tetrahedra. Each chunk adds its forces
//! into a window of its own covering the nodes it touches (small for meshes numbered in spatial
//! order, as the generators' are), so chunks run in parallel without sharing writes; the windows
//! are then added into the result in chunk order. The chunking depends only on the mesh, so the
//! forces are bit-identical whatever the number of threads. A mesh numbered without spatial order
//! would need windows as large as the whole mesh for every chunk; it is summed serially instead.

use super::TetRest;
use crate::damping::{RayleighDamping, StepDamping};
use crate::lanes::{LANES, Mat3x4, Vec3x4, f64x4};
use crate::material::HyperelasticModel;
use crate::mesh::TetMesh;
use rapier3d::glamx::{DMat3, DVec3};

/// Tetrahedra per chunk (a multiple of [`LANES`]); meshes of one chunk are summed directly.
const CHUNK_TETS: usize = 8192;
/// The chunks' windows may together span at most this many times the node count.
const MAX_WINDOW_SPAN: usize = 4;

/// Internal (elastic plus damping) forces (N) on the four nodes of one tetrahedron, for node
/// positions `x` (m) and velocities `v` (m/s). They sum to zero and have zero net torque.
#[inline(always)]
pub fn tet_forces<M: HyperelasticModel>(
    model: &M,
    damping: Option<&RayleighDamping>,
    rest: &TetRest,
    x: &[DVec3; 4],
    v: &[DVec3; 4],
) -> [DVec3; 4] {
    let f = rest.gradient(x);
    let mut stress = model.first_piola(&f);
    if let Some(damping) = damping {
        stress += damping.first_piola(&f, &rest.gradient(v));
    }
    stress_forces(rest, &stress)
}

/// The forces (N) a constant first Piola–Kirchhoff stress (Pa) puts on the four nodes of a
/// tetrahedron: `f_i = P b_i`, `f_0 = -(f_1 + f_2 + f_3)`.
#[inline(always)]
pub fn stress_forces(rest: &TetRest, stress: &DMat3) -> [DVec3; 4] {
    let forces = *stress * rest.control_normals();
    [
        -(forces.x_axis + forces.y_axis + forces.z_axis),
        forces.x_axis,
        forces.y_axis,
        forces.z_axis,
    ]
}

/// Rest data of [`LANES`] consecutive tetrahedra, one per lane.
#[derive(Debug, Clone, Copy)]
struct RestBlock {
    inverse_rest_edges: Mat3x4,
    /// The tetrahedra's [stiffness weights](FvmMesh::tet_weight) (m³).
    weight: f64x4,
}

/// The mesh as the finite-volume method sees it: tetrahedra, their rest data, and reusable storage
/// for summing the forces into nodal forces.
#[derive(Debug, Clone)]
pub struct FvmMesh {
    /// The tetrahedra, padded with copies of the last one to a multiple of [`LANES`].
    tets: Vec<[u32; 4]>,
    tet_count: usize,
    blocks: Vec<RestBlock>,
    /// Rest volume (m³) of each tetrahedron.
    volumes: Vec<f64>,
    node_count: usize,
    /// Per chunk of [`CHUNK_TETS`] tetrahedra: the first node it touches and its force window;
    /// empty for meshes of a single chunk.
    windows: Vec<(usize, Vec<DVec3>)>,
}

impl FvmMesh {
    /// Precomputes the rest data of every tetrahedron of `mesh`.
    pub fn new(mesh: &TetMesh) -> Self {
        let tet_count = mesh.tet_count();
        let rest = TetRest::of_mesh(mesh);
        let node_count = mesh.node_count();
        let padded = tet_count.div_ceil(LANES) * LANES;
        let mut tets = mesh.tets().to_vec();
        tets.resize(padded, tets[tet_count - 1]);
        let blocks = (0..padded / LANES)
            .map(|b| {
                let lane = |l: usize| rest[(LANES * b + l).min(tet_count - 1)];
                let lanes: [TetRest; LANES] = std::array::from_fn(lane);
                RestBlock {
                    inverse_rest_edges: Mat3x4::from_lanes(lanes.map(|r| r.inverse_rest_edges)),
                    weight: f64x4::new(lanes.map(|r| r.volume)),
                }
            })
            .collect();
        let windows = chunk_windows(&tets[..tet_count], node_count);
        Self {
            tets,
            tet_count,
            blocks,
            volumes: rest.iter().map(|r| r.volume).collect(),
            node_count,
            windows,
        }
    }

    /// Sets each tetrahedron's [stiffness weight](FvmMesh::tet_weight) to its rest volume times
    /// its factor in `factors` (one per tetrahedron): its Young's modulus over the modulus of the
    /// model the forces are computed with. Stress, energy and tangent of the tetrahedron scale
    /// alike.
    ///
    /// # Panics
    /// If `factors` does not have one entry per tetrahedron.
    pub(crate) fn scale_stiffness(&mut self, factors: &[f64]) {
        assert_eq!(factors.len(), self.tet_count, "one factor per tetrahedron");
        for (t, factor) in factors.iter().enumerate() {
            let block = &mut self.blocks[t / LANES];
            let mut weights = *block.weight.as_array();
            weights[t % LANES] = self.volumes[t] * factor;
            block.weight = f64x4::new(weights);
        }
    }

    /// The tetrahedra (node indices).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets[..self.tet_count]
    }

    /// Rest data of tetrahedron `tet`.
    ///
    /// # Panics
    /// If `tet` is not below the number of tetrahedra.
    pub fn tet_rest(&self, tet: usize) -> TetRest {
        assert!(tet < self.tet_count, "tetrahedron {tet} does not exist");
        TetRest {
            inverse_rest_edges: self.blocks[tet / LANES]
                .inverse_rest_edges
                .lane(tet % LANES),
            volume: self.volumes[tet],
        }
    }

    /// The stiffness weight (m³) of tetrahedron `tet`: the rest volume its stress acts over,
    /// times its stiffness factor `E_e/E` (1 unless the body's materials differ by
    /// [region](crate::body::DeformableBodyBuilder::region_material)). Its forces are
    /// `−w P ∇N_a` and its energy `w Ψ(F)`.
    ///
    /// # Panics
    /// If `tet` is not below the number of tetrahedra.
    pub fn tet_weight(&self, tet: usize) -> f64 {
        assert!(tet < self.tet_count, "tetrahedron {tet} does not exist");
        self.blocks[tet / LANES].weight.as_array()[tet % LANES]
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// The length `ℓ` (m) such that a pressure wave of speed `c` through the mesh at positions
    /// `x` has its highest angular frequency below about `2c/ℓ`: the smallest over the nodes of
    /// `ℓ_i = 2 sqrt(V_i / Σ_e V_e |∇N_i| Σ_j |∇N_j|)`, with `V_i` the node's rest control volume,
    /// the sums over the tetrahedra `e` at node `i` and the shape-function gradients taken in the
    /// deformed configuration (Gershgorin's bound on the lumped-mass wave operator, with the
    /// spatial stiffness of a compressed element). Unlike the smallest element altitude it counts
    /// how many elements share a node, and it shrinks as elements are crushed; zero if one is flat.
    ///
    ///
    /// With materials that differ by region, `V_e` in the row sums is the tetrahedron's
    /// [stiffness weight](FvmMesh::tet_weight), and the control volume a node's mass over the
    /// density of the wave speed.
    pub fn wave_length_scale(&self, x: &[DVec3]) -> f64 {
        self.mixed_wave_length_scale(x, None)
    }

    /// [`FvmMesh::wave_length_scale`] with each node's mass over the density `ρ` of the wave
    /// speed `c` in `mass_volumes` (m³) in place of its control volume `V_i` (`None` takes
    /// `V_i`): `2c/ℓ` then bounds the highest frequency of a mesh of materials that differ by
    /// region.
    ///
    /// # Panics
    /// If `mass_volumes` does not have one entry per node.
    pub(crate) fn mixed_wave_length_scale(&self, x: &[DVec3], mass_volumes: Option<&[f64]>) -> f64 {
        assert!(
            mass_volumes.is_none_or(|v| v.len() == self.node_count),
            "one mass volume per node"
        );
        let geometric = mass_volumes.is_none();
        let mut control_volume =
            mass_volumes.map_or_else(|| vec![0.0; self.node_count], <[_]>::to_vec);
        let mut row_sum = vec![0.0; self.node_count];
        for (t, tet) in self.tets().iter().enumerate() {
            let rest = self.tet_rest(t);
            let [x0, x1, x2, x3] = gather(tet, x);
            let edges = DMat3::from_cols(x1 - x0, x2 - x0, x3 - x0);
            if edges.determinant().abs() <= f64::EPSILON * rest.volume.abs() {
                return 0.0;
            }
            let g = edges.inverse().transpose();
            let gradients = [
                -(g.x_axis + g.y_axis + g.z_axis),
                g.x_axis,
                g.y_axis,
                g.z_axis,
            ];
            let total: f64 = gradients.iter().map(|g| g.length()).sum();
            let weight = self.tet_weight(t);
            for (corner, &n) in tet.iter().enumerate() {
                if geometric {
                    control_volume[n as usize] += 0.25 * rest.volume;
                }
                row_sum[n as usize] += weight * gradients[corner].length() * total;
            }
        }
        control_volume
            .iter()
            .zip(&row_sum)
            .filter(|(_, row)| **row > 0.0)
            .map(|(volume, row)| 2.0 * (volume / row).sqrt())
            .fold(f64::INFINITY, f64::min)
    }

    /// Writes into `out` the internal force (N) on every node, for positions `x` (m) and
    /// velocities `v` (m/s), one entry per node.
    ///
    /// # Panics
    /// If `x`, `v` or `out` does not have one entry per node.
    pub fn internal_forces<M: HyperelasticModel>(
        &mut self,
        model: &M,
        damping: Option<&RayleighDamping>,
        x: &[DVec3],
        v: &[DVec3],
        out: &mut [DVec3],
    ) {
        assert!(
            v.len() == self.node_count,
            "positions, velocities and forces need one entry per node"
        );
        let rate = damping.map_or(DampingRate::None, |damping| {
            DampingRate::Velocities(damping, v)
        });
        self.forces_with(ForceLaw { model, rate }, x, out);
    }

    /// Writes into `out` the internal force (N) on every node at positions `x` (m) in an
    /// implicit step: the elastic force and, with `damping`, the step's damping force (the
    /// gradient of [`RayleighDamping::step_potential`], its rate measured from each
    /// tetrahedron's Green strain), in one pass over the tetrahedra.
    ///
    /// # Panics
    /// If `x` or `out` does not have one entry per node, or `damping` one Green strain per
    /// tetrahedron.
    pub(crate) fn step_forces<M: HyperelasticModel>(
        &mut self,
        model: &M,
        damping: Option<StepDamping>,
        x: &[DVec3],
        out: &mut [DVec3],
    ) {
        let rate = damping.map_or(DampingRate::None, |step| {
            assert!(
                step.green.len() == self.tet_count,
                "one Green strain per tetrahedron"
            );
            DampingRate::Step(step)
        });
        self.forces_with(ForceLaw { model, rate }, x, out);
    }

    /// Writes into `out` the forces (N) of `law` at positions `x` (m), chunk by chunk (see the
    /// module's documentation).
    fn forces_with<M: HyperelasticModel>(
        &mut self,
        law: ForceLaw<'_, M>,
        x: &[DVec3],
        out: &mut [DVec3],
    ) {
        assert!(
            x.len() == self.node_count && out.len() == self.node_count,
            "positions, velocities and forces need one entry per node"
        );
        out.fill(DVec3::ZERO);
        if self.windows.is_empty() {
            let run = TetRun {
                tets: &self.tets,
                blocks: &self.blocks,
                valid: self.tet_count,
                first_tet: 0,
            };
            add_run_forces(law, run, x, out, 0);
            return;
        }
        let (tets, blocks, tet_count) = (&self.tets, &self.blocks, self.tet_count);
        let chunk_forces = |(c, (first, window)): (usize, &mut (usize, Vec<DVec3>))| {
            window.fill(DVec3::ZERO);
            let start = c * CHUNK_TETS;
            let end = (start + CHUNK_TETS).min(tets.len());
            let blocks = &blocks[start / LANES..end / LANES];
            let run = TetRun {
                tets: &tets[start..end],
                blocks,
                valid: tet_count - start,
                first_tet: start,
            };
            add_run_forces(law, run, x, window, *first);
        };
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            self.windows
                .par_iter_mut()
                .enumerate()
                .for_each(chunk_forces);
        }
        #[cfg(not(feature = "parallel"))]
        self.windows.iter_mut().enumerate().for_each(chunk_forces);
        for (first, window) in &self.windows {
            for (total, force) in out[*first..].iter_mut().zip(window) {
                *total += *force;
            }
        }
    }

    /// Total elastic energy `Σ w Ψ(F)` (J) at positions `x` (m), `w` the
    /// [stiffness weights](FvmMesh::tet_weight).
    /// Summed in the force loop's chunks of tetrahedra (on rayon's threads with the `parallel`
    /// feature), the chunks' sums in order: the same whatever the number of threads.
    pub fn elastic_energy<M: HyperelasticModel>(&self, model: &M, x: &[DVec3]) -> f64 {
        self.step_energy(model, None, x)
    }

    /// The elastic energy (J) at positions `x` (m) and, with `damping`, the step's dissipation
    /// potential ([`RayleighDamping::step_potential`]) weighted alike: `Σ w (Ψ(F) + D(F))`, each
    /// tetrahedron's `F` found once; summed as [`FvmMesh::elastic_energy`] is.
    ///
    /// # Panics
    /// If `damping` does not have one Green strain per tetrahedron.
    pub(crate) fn step_energy<M: HyperelasticModel>(
        &self,
        model: &M,
        damping: Option<StepDamping>,
        x: &[DVec3],
    ) -> f64 {
        if let Some(step) = damping {
            assert!(
                step.green.len() == self.tet_count,
                "one Green strain per tetrahedron"
            );
        }
        crate::parallel::sum_ranges(self.tet_count, CHUNK_TETS, |tets| {
            tets.map(|t| {
                let gradient = self.tet_rest(t).gradient(&gather(&self.tets[t], x));
                let mut density = model.energy_density(&gradient);
                if let Some(step) = damping {
                    density += step
                        .damping
                        .step_potential(&gradient, &step.green[t], step.h);
                }
                self.tet_weight(t) * density
            })
            .sum()
        })
    }
}

/// The constitutive side of the force loop: the elastic model and where the damping's rate
/// comes from.
struct ForceLaw<'a, M> {
    model: &'a M,
    rate: DampingRate<'a>,
}

/// Where the damping stress's strain rate comes from.
#[derive(Clone, Copy)]
enum DampingRate<'a> {
    /// No damping.
    None,
    /// The nodes' velocities (m/s): `Ġ = sym(Fᵀ Ḟ)`.
    Velocities(&'a RayleighDamping, &'a [DVec3]),
    /// An implicit step's: the Green strain's change over the step.
    Step(StepDamping<'a>),
}

impl<M> Clone for ForceLaw<'_, M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M> Copy for ForceLaw<'_, M> {}

/// A run of tetrahedra padded to whole blocks of [`LANES`], with their rest data; only the first
/// `valid` are real.
struct TetRun<'a> {
    tets: &'a [[u32; 4]],
    blocks: &'a [RestBlock],
    valid: usize,
    /// The mesh's index of the run's first tetrahedron.
    first_tet: usize,
}

/// Adds the forces (N) of `law` on `run`'s real tetrahedra at positions `x` (m) into `out`,
/// whose entry 0 is node `first`.
#[inline(always)]
fn add_run_forces<M: HyperelasticModel>(
    law: ForceLaw<'_, M>,
    run: TetRun<'_>,
    x: &[DVec3],
    out: &mut [DVec3],
    first: usize,
) {
    for (b, (block_tets, rest)) in run.tets.chunks_exact(LANES).zip(run.blocks).enumerate() {
        let forces = block_forces(law, rest, (block_tets, run.first_tet + b * LANES), x);
        let block_valid = run.valid.saturating_sub(b * LANES).min(LANES);
        for (tet, tet_forces) in block_tets.iter().zip(&forces).take(block_valid) {
            for (&n, f) in tet.iter().zip(tet_forces) {
                out[n as usize - first] += *f;
            }
        }
    }
}

/// [`tet_forces`] for the [`LANES`] tetrahedra `tets` of one block, the first of them the
/// mesh's tetrahedron `index`, with the damping's rate as `law` has it.
#[inline(always)]
fn block_forces<M: HyperelasticModel>(
    law: ForceLaw<'_, M>,
    rest: &RestBlock,
    (tets, index): (&[[u32; 4]], usize),
    x: &[DVec3],
) -> [[DVec3; 4]; LANES] {
    let f = lane_edges(tets, x) * rest.inverse_rest_edges;
    let extra = match law.rate {
        DampingRate::None => Mat3x4::splat(DMat3::ZERO),
        DampingRate::Velocities(damping, v) => {
            damping.second_piola_lanes(&f, &(lane_edges(tets, v) * rest.inverse_rest_edges))
        }
        DampingRate::Step(step) => {
            // Padding lanes past the last tetrahedron take a zero strain; their forces are
            // not added.
            let green = |l: usize| step.green.get(index + l).copied().unwrap_or(DMat3::ZERO);
            let green = Mat3x4::from_lanes(std::array::from_fn(green));
            step.damping.step_second_piola_lanes(&f, &green, step.h)
        }
    };
    let stress = law.model.first_piola_plus_lanes(&f, &extra);
    // Forces on nodes 1..3 are the columns of P b = -V P Dm⁻ᵀ (V the stiffness weight).
    let forces = stress * rest.inverse_rest_edges.transpose() * -rest.weight;
    let [f1, f2, f3] = forces.cols.map(Vec3x4::to_lanes);
    let f0 = (-(forces.cols[0] + forces.cols[1] + forces.cols[2])).to_lanes();
    std::array::from_fn(|l| [f0[l], f1[l], f2[l], f3[l]])
}

/// The edge matrices `[x1 - x0, x2 - x0, x3 - x0]` of the block's tetrahedra, one per lane.
#[inline(always)]
fn lane_edges(tets: &[[u32; 4]], values: &[DVec3]) -> Mat3x4 {
    let corner =
        |c: usize| Vec3x4::from_lanes(std::array::from_fn(|l| values[tets[l][c] as usize]));
    let origin = corner(0);
    Mat3x4::from_cols(corner(1) - origin, corner(2) - origin, corner(3) - origin)
}

/// The force windows of the chunks of `tets`: empty for a single chunk, or when the windows
/// would together span more than [`MAX_WINDOW_SPAN`] times the node count (a mesh numbered
/// without spatial order), in which case the mesh is summed serially.
fn chunk_windows(tets: &[[u32; 4]], node_count: usize) -> Vec<(usize, Vec<DVec3>)> {
    if tets.len() <= CHUNK_TETS {
        return Vec::new();
    }
    let spans: Vec<(usize, usize)> = tets
        .chunks(CHUNK_TETS)
        .map(|chunk| {
            let nodes = chunk.iter().flatten();
            let first = *nodes.clone().min().unwrap_or(&0) as usize;
            let last = *nodes.max().unwrap_or(&0) as usize;
            (first, last + 1 - first)
        })
        .collect();
    if spans.iter().map(|(_, len)| len).sum::<usize>() > MAX_WINDOW_SPAN * node_count {
        return Vec::new();
    }
    spans
        .into_iter()
        .map(|(first, len)| (first, vec![DVec3::ZERO; len]))
        .collect()
}

/// The four entries of `values` at the nodes of `tet`.
#[inline]
pub(crate) fn gather(tet: &[u32; 4], values: &[DVec3]) -> [DVec3; 4] {
    tet.map(|n| values[n as usize])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{LameParameters, StableNeoHookean, green_strain};

    /// The implicit step's forces and energy in one pass are the separate passes' (the elastic
    /// forces and energy, and per tetrahedron the scalar damping stress and dissipation
    /// potential) to round-off, 1e-12 of the largest: on 15 tetrahedra (the last block padded),
    /// deformed and measured from other Green strains tetrahedron by tetrahedron.
    #[test]
    fn a_steps_forces_and_energy_in_one_pass_are_the_separate_passes() {
        let mesh = crate::mesh::cuboid(DVec3::new(0.15, 0.05, 0.05), [3, 1, 1]).unwrap();
        let mut fvm = FvmMesh::new(&mesh);
        assert_eq!(fvm.tet_count % LANES, 3);
        let model = StableNeoHookean::new(LameParameters {
            lambda: 4e5,
            mu: 2e5,
        });
        let damping = RayleighDamping::new(300.0, 200.0).unwrap();
        let moved = |scale: f64| -> Vec<DVec3> {
            (mesh.positions().iter().enumerate())
                .map(|(n, p)| {
                    let k = n as f64;
                    *p + DVec3::new((0.7 * k).sin(), (1.3 * k).cos(), (0.4 * k).sin()) * scale
                })
                .collect()
        };
        let (x, earlier) = (moved(4e-3), moved(2e-3));
        let green: Vec<DMat3> = (0..fvm.tet_count)
            .map(|t| green_strain(&fvm.tet_rest(t).gradient(&gather(&fvm.tets[t], &earlier))))
            .collect();
        let h = 1e-3;
        let step = StepDamping {
            damping: &damping,
            green: &green,
            h,
        };
        let mut fused = vec![DVec3::ZERO; x.len()];
        fvm.step_forces(&model, Some(step), &x, &mut fused);
        let mut separate = vec![DVec3::ZERO; x.len()];
        let still = vec![DVec3::ZERO; x.len()];
        fvm.internal_forces(&model, None, &x, &still, &mut separate);
        let mut dissipation = 0.0;
        for (t, green) in green.iter().enumerate() {
            let rest = fvm.tet_rest(t);
            let f = rest.gradient(&gather(&fvm.tets[t], &x));
            let stress = damping.step_first_piola(&f, green, h);
            for (&n, force) in fvm.tets[t].iter().zip(stress_forces(&rest, &stress)) {
                separate[n as usize] += force;
            }
            dissipation += fvm.tet_weight(t) * damping.step_potential(&f, green, h);
        }
        let largest = separate.iter().map(|f| f.length()).fold(0.0, f64::max);
        assert!(largest > 0.0);
        for (a, b) in fused.iter().zip(&separate) {
            assert!(a.distance(*b) <= 1e-12 * largest, "{a} against {b}");
        }
        let energy = fvm.step_energy(&model, Some(step), &x);
        let expected = fvm.elastic_energy(&model, &x) + dissipation;
        assert!(
            (energy - expected).abs() <= 1e-12 * expected,
            "{energy} against {expected}"
        );
    }
}

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
use crate::damping::RayleighDamping;
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
            x.len() == self.node_count
                && v.len() == self.node_count
                && out.len() == self.node_count,
            "positions, velocities and forces need one entry per node"
        );
        out.fill(DVec3::ZERO);
        let law = ForceLaw { model, damping };
        if self.windows.is_empty() {
            let run = TetRun {
                tets: &self.tets,
                blocks: &self.blocks,
                valid: self.tet_count,
            };
            add_run_forces(law, run, [x, v], out, 0);
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
            };
            add_run_forces(law, run, [x, v], window, *first);
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
        crate::parallel::sum_ranges(self.tet_count, CHUNK_TETS, |tets| {
            tets.map(|t| {
                let gradient = self.tet_rest(t).gradient(&gather(&self.tets[t], x));
                self.tet_weight(t) * model.energy_density(&gradient)
            })
            .sum()
        })
    }
}

/// The constitutive side of the force loop: the elastic model and the optional damping.
struct ForceLaw<'a, M> {
    model: &'a M,
    damping: Option<&'a RayleighDamping>,
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
}

/// Adds the forces (N) of `run`'s real tetrahedra at positions `x` (m) and velocities `v` (m/s)
/// into `out`, whose entry 0 is node `first`.
#[inline(always)]
fn add_run_forces<M: HyperelasticModel>(
    law: ForceLaw<'_, M>,
    run: TetRun<'_>,
    [x, v]: [&[DVec3]; 2],
    out: &mut [DVec3],
    first: usize,
) {
    for (b, (block_tets, rest)) in run.tets.chunks_exact(LANES).zip(run.blocks).enumerate() {
        let forces = block_forces(law.model, law.damping, rest, block_tets, x, v);
        let block_valid = run.valid.saturating_sub(b * LANES).min(LANES);
        for (tet, tet_forces) in block_tets.iter().zip(&forces).take(block_valid) {
            for (&n, f) in tet.iter().zip(tet_forces) {
                out[n as usize - first] += *f;
            }
        }
    }
}

/// [`tet_forces`] for the [`LANES`] tetrahedra of one block.
#[inline(always)]
fn block_forces<M: HyperelasticModel>(
    model: &M,
    damping: Option<&RayleighDamping>,
    rest: &RestBlock,
    tets: &[[u32; 4]],
    x: &[DVec3],
    v: &[DVec3],
) -> [[DVec3; 4]; LANES] {
    let f = lane_edges(tets, x) * rest.inverse_rest_edges;
    let extra = match damping {
        Some(damping) => {
            damping.second_piola_lanes(&f, &(lane_edges(tets, v) * rest.inverse_rest_edges))
        }
        None => Mat3x4::splat(DMat3::ZERO),
    };
    let stress = model.first_piola_plus_lanes(&f, &extra);
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

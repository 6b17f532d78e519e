//! The force kernel: `f_i = P b_i` per tetrahedron (a pure function), and the loop that sums it
//! over a mesh into nodal forces without allocating.
//!
//! The loop runs serially or, with the `parallel` feature on large meshes and more than one rayon
//! thread, in two parallel passes (per-tetrahedron forces, then a per-node gather over a
//! precomputed incidence list). Both add a node's contributions in ascending tetrahedron order, so
//! the results are bit-identical whatever the thread count.

use super::TetRest;
use crate::damping::RayleighDamping;
use crate::material::HyperelasticModel;
use crate::mesh::TetMesh;
use rapier3d::glamx::DVec3;

/// Meshes with fewer tetrahedra than this are summed serially even with `parallel` on: below it,
/// thread hand-off costs more than it saves.
#[cfg(feature = "parallel")]
const PARALLEL_MIN_TETS: usize = 4096;

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
    let forces = stress * rest.control_normals();
    [
        -(forces.x_axis + forces.y_axis + forces.z_axis),
        forces.x_axis,
        forces.y_axis,
        forces.z_axis,
    ]
}

/// The mesh as the finite-volume method sees it: tetrahedra, their rest data, and reusable storage
/// for summing [`tet_forces`] into nodal forces.
#[derive(Debug, Clone)]
pub struct FvmMesh {
    tets: Vec<[u32; 4]>,
    rest: Vec<TetRest>,
    node_count: usize,
    wave_length_scale: f64,
    /// For node `n`, `incidence[offsets[n]..offsets[n + 1]]` lists `4 * tet + corner` of every
    /// tetrahedron corner at `n`, in ascending tetrahedron order.
    #[cfg(feature = "parallel")]
    offsets: Vec<usize>,
    #[cfg(feature = "parallel")]
    incidence: Vec<u32>,
    /// Per-tetrahedron forces of the parallel pass; empty when the mesh is summed serially.
    #[cfg(feature = "parallel")]
    per_tet: Vec<[DVec3; 4]>,
}

impl FvmMesh {
    /// Precomputes the rest data of every tetrahedron of `mesh`.
    pub fn new(mesh: &TetMesh) -> Self {
        let tets = mesh.tets().to_vec();
        let rest = TetRest::of_mesh(mesh);
        let node_count = mesh.node_count();
        let wave_length_scale = wave_length_scale(&tets, &rest, node_count);
        #[cfg(feature = "parallel")]
        {
            let (offsets, incidence) = node_incidence(&tets, node_count);
            let per_tet = if tets.len() >= PARALLEL_MIN_TETS {
                vec![[DVec3::ZERO; 4]; tets.len()]
            } else {
                Vec::new()
            };
            Self {
                tets,
                rest,
                node_count,
                wave_length_scale,
                offsets,
                incidence,
                per_tet,
            }
        }
        #[cfg(not(feature = "parallel"))]
        Self {
            tets,
            rest,
            node_count,
            wave_length_scale,
        }
    }

    /// The tetrahedra (node indices).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Rest data per tetrahedron, in the order of [`FvmMesh::tets`].
    pub fn rest(&self) -> &[TetRest] {
        &self.rest
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// The length `ℓ` (m) such that a wave of speed `c` through the mesh has its highest angular
    /// frequency below `2c/ℓ`: the smallest over the nodes of
    /// `ℓ_i = 2 sqrt(V_i / Σ_e V_e |∇N_i| Σ_j |∇N_j|)`, with `V_i` the node's control volume and
    /// the sums over the tetrahedra `e` at node `i` (Gershgorin's bound on the lumped-mass wave
    /// operator). Unlike the smallest element altitude it accounts for how many elements share a
    /// node, so it tracks the true limit on every kind of mesh.
    pub fn wave_length_scale(&self) -> f64 {
        self.wave_length_scale
    }

    /// Writes into `out` the internal force (N) on every node, for positions `x` (m) and
    /// velocities `v` (m/s), one entry per node.
    pub fn internal_forces<M: HyperelasticModel>(
        &mut self,
        model: &M,
        damping: Option<&RayleighDamping>,
        x: &[DVec3],
        v: &[DVec3],
        out: &mut [DVec3],
    ) {
        debug_assert!(x.len() == self.node_count && v.len() == self.node_count);
        debug_assert!(out.len() == self.node_count);
        #[cfg(feature = "parallel")]
        if !self.per_tet.is_empty() && rayon::current_num_threads() > 1 {
            self.internal_forces_parallel(model, damping, x, v, out);
            return;
        }
        out.fill(DVec3::ZERO);
        for (tet, rest) in self.tets.iter().zip(&self.rest) {
            let forces = tet_forces(model, damping, rest, &gather(tet, x), &gather(tet, v));
            for (corner, &n) in tet.iter().enumerate() {
                out[n as usize] += forces[corner];
            }
        }
    }

    #[cfg(feature = "parallel")]
    fn internal_forces_parallel<M: HyperelasticModel>(
        &mut self,
        model: &M,
        damping: Option<&RayleighDamping>,
        x: &[DVec3],
        v: &[DVec3],
        out: &mut [DVec3],
    ) {
        use rayon::prelude::*;
        let (tets, rest) = (&self.tets, &self.rest);
        self.per_tet
            .par_iter_mut()
            .zip(tets.par_iter().zip(rest.par_iter()))
            .for_each(|(forces, (tet, rest))| {
                *forces = tet_forces(model, damping, rest, &gather(tet, x), &gather(tet, v));
            });
        let (offsets, incidence, per_tet) = (&self.offsets, &self.incidence, &self.per_tet);
        out.par_iter_mut().enumerate().for_each(|(n, force)| {
            *force = incidence[offsets[n]..offsets[n + 1]]
                .iter()
                .fold(DVec3::ZERO, |sum, &e| {
                    sum + per_tet[e as usize / 4][e as usize % 4]
                });
        });
    }

    /// Total elastic energy `Σ V Ψ(F)` (J) at positions `x` (m).
    pub fn elastic_energy<M: HyperelasticModel>(&self, model: &M, x: &[DVec3]) -> f64 {
        self.tets
            .iter()
            .zip(&self.rest)
            .map(|(tet, rest)| rest.volume * model.energy_density(&rest.gradient(&gather(tet, x))))
            .sum()
    }
}

fn wave_length_scale(tets: &[[u32; 4]], rest: &[TetRest], node_count: usize) -> f64 {
    let mut control_volume = vec![0.0; node_count];
    let mut row_sum = vec![0.0; node_count];
    for (tet, rest) in tets.iter().zip(rest) {
        let g = rest.inverse_rest_edges.transpose();
        let gradients = [
            -(g.x_axis + g.y_axis + g.z_axis),
            g.x_axis,
            g.y_axis,
            g.z_axis,
        ];
        let total: f64 = gradients.iter().map(|g| g.length()).sum();
        for (corner, &n) in tet.iter().enumerate() {
            control_volume[n as usize] += 0.25 * rest.volume;
            row_sum[n as usize] += rest.volume * gradients[corner].length() * total;
        }
    }
    control_volume
        .iter()
        .zip(&row_sum)
        .filter(|(_, row)| **row > 0.0)
        .map(|(volume, row)| 2.0 * (volume / row).sqrt())
        .fold(f64::INFINITY, f64::min)
}

/// The four entries of `values` at the nodes of `tet`.
#[inline]
pub(crate) fn gather(tet: &[u32; 4], values: &[DVec3]) -> [DVec3; 4] {
    tet.map(|n| values[n as usize])
}

/// Node-to-corner incidence lists in CSR form, each in ascending tetrahedron order.
#[cfg(feature = "parallel")]
fn node_incidence(tets: &[[u32; 4]], node_count: usize) -> (Vec<usize>, Vec<u32>) {
    let mut offsets = vec![0usize; node_count + 1];
    for tet in tets {
        for &n in tet {
            offsets[n as usize + 1] += 1;
        }
    }
    for n in 0..node_count {
        offsets[n + 1] += offsets[n];
    }
    let mut fill = offsets.clone();
    let mut incidence = vec![0u32; 4 * tets.len()];
    for (t, tet) in tets.iter().enumerate() {
        for (corner, &n) in tet.iter().enumerate() {
            incidence[fill[n as usize]] = (4 * t + corner) as u32;
            fill[n as usize] += 1;
        }
    }
    (offsets, incidence)
}

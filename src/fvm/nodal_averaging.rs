//! Nodal averaging of the volumetric term (Bonet and Burton, "A simple average nodal pressure
//! tetrahedral element for incompressible and nearly incompressible dynamic explicit
//! applications", 1998), which frees linear tetrahedra from volumetric locking.
//!
//! A tetrahedron has a single volume strain, and for `ν → 0.5` the volumetric term `K/2 m²` of
//! its energy ([`VolumetricTerm`]) forces it to zero in every element: there are about as many
//! such constraints as degrees of freedom, and the mesh locks (a cantilever at `ν = 0.499` bends
//! a few percent of what it should). With nodal averaging the term is taken on each node's patch
//! of elements instead:
//!
//! `E = Σ_e V_e Ψ_rest(F_e) + Σ_a W_a K/2 θ_a²`, `θ_a = Σ_{e∋a} V_e m_e / Σ_{e∋a} V_e`,
//!
//! with `W_a` the node's control volume (a quarter of each incident element's rest volume). One
//! constraint per node instead of per element (about five times fewer) leaves the mesh free to
//! bend. It is an energy, so forces `-∂E/∂x` and the exact tangent follow: each element's stress
//! becomes `P(F) + K (θ̄_e - m_e) ∂m/∂F`, with `θ̄_e` the mean of `θ_a` over its four nodes, and the
//! tangent gains `Σ_a W_a K g_a g_aᵀ`, `g_a = ∂θ_a/∂x`, which couples the nodes of a patch.

use super::{FvmMesh, gather, stress_forces};
use crate::material::VolumetricTerm;
use rapier3d::glamx::{DMat3, DVec3};

/// How the volumetric (first Lamé parameter) part of the elastic energy is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum VolumetricTreatment {
    /// Per tetrahedron, as every other term: the plain linear tetrahedron. Accurate for
    /// compressible materials; locks as `ν → 0.5` (and is stiff in bending at any `ν`).
    #[default]
    PerElement,
    /// Averaged over each node's patch of tetrahedra (Bonet and Burton 1998): locking-free for
    /// nearly incompressible materials, at about twice the force cost and a wider tangent stencil.
    NodalAverage,
    /// Projected, per element, onto a few pressure functions (mean dilatation, see
    /// [`crate::element`]): the element's mean for quadratic tetrahedra, the linear functions
    /// for quadratic hexahedra (Q2/P1). Frees quadratic elements from locking at no extra
    /// stencil. Tetrahedra need at least two elements across a bent section: with one, the
    /// volume change that varies across it averages out and the section is far too soft (+55 %
    /// on the reference cantilever at 10 x 1 x 1 cells, +2.6 % to +1.5 % at 20 x 2 x 2, `ν` =
    /// 0.45 to 0.499); the hexahedra's linear pressure follows it with one (−0.05 % at 5 x 1 x 1
    /// cells, `ν` = 0.3; −0.28 % at `ν` = 0.499). Linear tetrahedra have a single point, so for
    /// them it is [`VolumetricTreatment::PerElement`].
    ElementAverage,
}

/// The node-to-element incidence and rest volumes nodal averaging needs, built once per body.
#[derive(Debug, Clone)]
pub(crate) struct NodalAveraging {
    /// Per node, the summed rest volume of its tetrahedra (m³).
    patch_volume: Vec<f64>,
    /// The tetrahedra of node `n` are `node_tets[tet_start[n]..tet_start[n + 1]]`.
    tet_start: Vec<usize>,
    node_tets: Vec<u32>,
    /// Storage reused by the force evaluation.
    scratch: VolumeMeasures,
}

/// The volume measures of one configuration.
#[derive(Debug, Clone, Default)]
pub(crate) struct VolumeMeasures {
    /// `m_e` per tetrahedron.
    pub(crate) element: Vec<f64>,
    /// `θ_a` per node.
    pub(crate) nodal: Vec<f64>,
}

impl VolumeMeasures {
    /// `θ̄_e - m_e` for tetrahedron `t` of `tets`: the element's share of the averaging.
    pub(crate) fn excess(&self, tet: &[u32], t: usize) -> f64 {
        0.25 * tet.iter().map(|&n| self.nodal[n as usize]).sum::<f64>() - self.element[t]
    }
}

impl NodalAveraging {
    /// The incidence of `fvm`'s mesh.
    pub(crate) fn new(fvm: &FvmMesh) -> Self {
        let n = fvm.node_count();
        let mut patch_volume = vec![0.0; n];
        let mut tet_start = vec![0usize; n + 1];
        for (t, tet) in fvm.tets().iter().enumerate() {
            for &node in tet {
                patch_volume[node as usize] += fvm.tet_rest(t).volume;
                tet_start[node as usize + 1] += 1;
            }
        }
        for i in 0..n {
            tet_start[i + 1] += tet_start[i];
        }
        let mut fill = tet_start.clone();
        let mut node_tets = vec![0u32; tet_start[n]];
        for (t, tet) in fvm.tets().iter().enumerate() {
            for &node in tet {
                node_tets[fill[node as usize]] = t as u32;
                fill[node as usize] += 1;
            }
        }
        Self {
            patch_volume,
            tet_start,
            node_tets,
            scratch: VolumeMeasures::default(),
        }
    }

    /// The tetrahedra around node `node`.
    fn tets_of(&self, node: usize) -> &[u32] {
        &self.node_tets[self.tet_start[node]..self.tet_start[node + 1]]
    }

    /// `m_e` and `θ_a` at positions `x` (m).
    pub(crate) fn measures<M: VolumetricTerm>(
        &self,
        model: &M,
        fvm: &FvmMesh,
        x: &[DVec3],
    ) -> VolumeMeasures {
        let mut measures = VolumeMeasures {
            element: Vec::new(),
            nodal: Vec::new(),
        };
        self.measure_into(model, fvm, x, &mut measures);
        measures
    }

    /// [`NodalAveraging::measures`] into `out`, reusing its storage.
    fn measure_into<M: VolumetricTerm>(
        &self,
        model: &M,
        fvm: &FvmMesh,
        x: &[DVec3],
        out: &mut VolumeMeasures,
    ) {
        out.nodal.clear();
        out.nodal.resize(fvm.node_count(), 0.0);
        out.element.clear();
        for (t, tet) in fvm.tets().iter().enumerate() {
            let rest = fvm.tet_rest(t);
            let m = model.volume_measure(&rest.gradient(&gather(tet, x)));
            for &n in tet {
                out.nodal[n as usize] += rest.volume * m;
            }
            out.element.push(m);
        }
        for (theta, volume) in out.nodal.iter_mut().zip(&self.patch_volume) {
            *theta /= volume;
        }
    }

    /// Adds to `out` the change of the internal forces (N per node) from per-element to nodally
    /// averaged volumetric term, at positions `x` (m). Allocates nothing after the first call.
    pub(crate) fn add_forces<M: VolumetricTerm>(
        &mut self,
        model: &M,
        fvm: &FvmMesh,
        x: &[DVec3],
        out: &mut [DVec3],
    ) {
        let mut measures = std::mem::take(&mut self.scratch);
        self.measure_into(model, fvm, x, &mut measures);
        let bulk = model.volumetric_modulus();
        for (t, tet) in fvm.tets().iter().enumerate() {
            let rest = fvm.tet_rest(t);
            let f = rest.gradient(&gather(tet, x));
            let stress = model.volume_measure_gradient(&f) * (bulk * measures.excess(tet, t));
            for (&n, force) in tet.iter().zip(stress_forces(&rest, &stress)) {
                out[n as usize] += force;
            }
        }
        self.scratch = measures;
    }

    /// The elastic energy `E` (J) with the averaged volumetric term, at positions `x` (m).
    pub(crate) fn elastic_energy<M: VolumetricTerm>(
        &self,
        model: &M,
        fvm: &FvmMesh,
        x: &[DVec3],
    ) -> f64 {
        let rest_energy: f64 = fvm
            .tets()
            .iter()
            .enumerate()
            .map(|(t, tet)| {
                let rest = fvm.tet_rest(t);
                rest.volume
                    * model.energy_density_without_volumetric(&rest.gradient(&gather(tet, x)))
            })
            .sum();
        let measures = self.measures(model, fvm, x);
        let volumetric: f64 = measures
            .nodal
            .iter()
            .zip(&self.patch_volume)
            .map(|(theta, v)| 0.25 * v * theta * theta)
            .sum();
        rest_energy + 0.5 * model.volumetric_modulus() * volumetric
    }

    /// The element part of the stress differential with averaging, `dP + K (θ̄ - m) d(∂m/∂F) - K
    /// (∂m/∂F : dF) ∂m/∂F`, for an element with deformation gradient `f` and `excess = θ̄ - m`.
    pub(crate) fn element_differential<M: VolumetricTerm>(
        model: &M,
        f: &DMat3,
        excess: f64,
        df: &DMat3,
    ) -> DMat3 {
        let bulk = model.volumetric_modulus();
        let gradient = model.volume_measure_gradient(f);
        model.first_piola_differential(f, df)
            + model.volume_measure_differential(f, df) * (bulk * excess)
            - gradient * (bulk * crate::material::double_dot(&gradient, df))
    }

    /// Calls `add(nodes, weight)` for every node `a`, with `nodes` the gradient `g_a = ∂θ_a/∂x`
    /// as (node, vector) pairs over the patch of `a` and `weight = W_a K` (Pa·m³): the tangent's
    /// coupling term is the sum of `weight g_a g_aᵀ`.
    pub(crate) fn for_each_coupling<M: VolumetricTerm>(
        &self,
        model: &M,
        fvm: &FvmMesh,
        x: &[DVec3],
        mut add: impl FnMut(&[(u32, DVec3)], f64),
    ) {
        let bulk = model.volumetric_modulus();
        // ∂m/∂F once per tetrahedron; each serves the four patches it belongs to.
        let measure_gradients: Vec<DMat3> = fvm
            .tets()
            .iter()
            .enumerate()
            .map(|(t, tet)| {
                model.volume_measure_gradient(&fvm.tet_rest(t).gradient(&gather(tet, x)))
            })
            .collect();
        let mut gradient: Vec<(u32, DVec3)> = Vec::new();
        for a in 0..fvm.node_count() {
            gradient.clear();
            for &t in self.tets_of(a) {
                let t = t as usize;
                let rest = fvm.tet_rest(t);
                let tet = &fvm.tets()[t];
                let dm = measure_gradients[t];
                let share = rest.volume / self.patch_volume[a];
                for (&n, g) in tet.iter().zip(rest.shape_gradients()) {
                    gradient.push((n, dm * g * share));
                }
            }
            gradient.sort_unstable_by_key(|(n, _)| *n);
            gradient.dedup_by(|later, earlier| {
                let same = later.0 == earlier.0;
                if same {
                    earlier.1 += later.1;
                }
                same
            });
            add(&gradient, 0.25 * self.patch_volume[a] * bulk);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::assembly::{assert_forces_and_tangent_match_energy, perturb_positions};
    use crate::prelude::*;

    /// A 2 x 2 x 2-cell cube with nodal averaging, its nodes moved by up to 15 % of a cell.
    fn perturbed_cube(model: MaterialModel, poisson_ratio: f64) -> DeformableBody {
        let material = Material::new(model, 1e6, poisson_ratio, 1000.0).unwrap();
        let mesh = mesh::cuboid(DVec3::splat(0.5), [2, 2, 2]).unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, material)
            .volumetric(VolumetricTreatment::NodalAverage)
            .build()
            .unwrap();
        perturb_positions(&mut body, 7, 0.075);
        body
    }

    fn forces(body: &mut DeformableBody) -> Vec<DVec3> {
        body.internal_forces().to_vec()
    }

    /// The forces are minus the gradient of the energy, and the assembled tangent is minus the
    /// gradient of the forces (see [`assert_forces_and_tangent_match_energy`]).
    #[test]
    fn forces_and_tangent_match_finite_differences_of_the_energy() {
        for model in [
            MaterialModel::Linear,
            MaterialModel::StVenantKirchhoff,
            MaterialModel::Corotated,
            MaterialModel::StableNeoHookean,
        ] {
            for nu in [0.3, 0.499, -0.6] {
                let mut body = perturbed_cube(model, nu);
                assert_forces_and_tangent_match_energy(&mut body, &format!("{model:?} ν = {nu}"));
            }
        }
    }

    /// Under a homogeneous deformation every node sees the elements' own volume measure, so
    /// averaging changes neither energy nor forces.
    #[test]
    fn homogeneous_deformation_is_unchanged() {
        let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1000.0).unwrap();
        let mesh = mesh::cuboid(DVec3::splat(0.5), [3, 3, 3]).unwrap();
        let stretch = DMat3::from_cols_array(&[1.1, 0.05, 0.0, 0.02, 0.95, 0.0, 0.0, 0.03, 1.02]);
        let mut bodies = [
            VolumetricTreatment::PerElement,
            VolumetricTreatment::NodalAverage,
        ]
        .map(|treatment| {
            let mut body = DeformableBodyBuilder::new(mesh.clone(), material)
                .volumetric(treatment)
                .build()
                .unwrap();
            for x in body.positions_mut() {
                *x = stretch * *x;
            }
            body
        });
        let energies = bodies.each_ref().map(|b| b.elastic_energy());
        assert!((energies[0] - energies[1]).abs() <= 1e-12 * energies[0]);
        let element = forces(&mut bodies[0]);
        let averaged = forces(&mut bodies[1]);
        let scale = element.iter().map(|f| f.length()).fold(0.0, f64::max);
        for (a, b) in element.iter().zip(&averaged) {
            assert!((*a - *b).length() <= 1e-12 * scale);
        }
    }
}

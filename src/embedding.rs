//! A fine tetrahedral mesh carried by a body's simulation nodes (an embedded mesh in a coarse
//! cage): resolution for contact and output is chosen apart from resolution for elasticity.
//!
//! Every vertex of the fine mesh lies, at rest, in one element of the simulation mesh, at
//! natural coordinates `ξ`; it then moves with that element, `x_v = Σ_a N_a(ξ) x_a` over the
//! element's nodes `a` (barycentric weights for a linear tetrahedron, the quadratic shape
//! functions for 10-node tetrahedra and 27-node hexahedra). Contacts with colliders act on the
//! fine surface's vertices: a vertex's velocity is `Σ_a w_a v_a`, its inverse effective mass
//! `Σ_a w_a² / m_a`, and an impulse `J` on it gives each node `w_a J`. The weights sum to one,
//! so the nodes receive exactly the impulse the collider gives up: momentum stays exchanged
//! exactly.

use crate::Error;
use crate::element::{Elements, QuadraticElements};
use crate::mesh::TetMesh;
use rapier3d::glamx::DVec3;

/// A fine mesh embedded in a body's simulation mesh (see the [module](self) documentation).
/// Made by [`SoftBodyBuilder::embedded`](crate::body::SoftBodyBuilder::embedded).
#[derive(Debug, Clone)]
pub struct Embedding {
    mesh: TetMesh,
    surface_triangles: Vec<[u32; 3]>,
    surface_vertices: Vec<u32>,
    /// Vertex `v`'s nodes and weights are `nodes[start[v]..start[v + 1]]`, likewise `weights`.
    start: Vec<usize>,
    nodes: Vec<u32>,
    weights: Vec<f64>,
}

/// How far outside the simulation mesh a fine vertex may lie, in units of the nearest
/// simulation tetrahedron's size (its barycentric coordinates may go this far below zero):
/// a curved fine surface over a faceted coarse one pokes slightly out.
const OUTSIDE_TOLERANCE: f64 = 0.5;

impl Embedding {
    /// Embeds `fine` (rest positions in the body's own frame, m) in the simulation mesh
    /// `simulation` (the body's linear tetrahedra, or the subdivision of its quadratic elements,
    /// `parents` giving each tetrahedron's element).
    pub(crate) fn new(
        fine: TetMesh,
        simulation: &TetMesh,
        elements: &Elements,
        parents: &[u32],
    ) -> Result<Self, Error> {
        let grid = TetGrid::new(simulation);
        let rest = simulation.positions();
        let quadratic = match elements {
            Elements::Quadratic { elements, .. } => Some(elements),
            Elements::Linear { .. } => None,
        };
        let mut start = vec![0];
        let (mut nodes, mut weights) = (Vec::new(), Vec::new());
        for (vertex, &p) in fine.positions().iter().enumerate() {
            let (tet, barycentric) = grid.locate(simulation, p);
            if barycentric.iter().copied().fold(f64::INFINITY, f64::min) < -OUTSIDE_TOLERANCE {
                return Err(Error::OutsideSimulationMesh {
                    vertex,
                    position: p.to_array(),
                });
            }
            let sub_tet = simulation.tets()[tet];
            match quadratic {
                None => {
                    nodes.extend(sub_tet);
                    weights.extend(barycentric);
                }
                Some(quadratic) => {
                    let element = parents[tet] as usize;
                    let (element_nodes, shape_values) =
                        quadratic_weights(quadratic, element, rest, &sub_tet, barycentric, p);
                    nodes.extend(element_nodes);
                    weights.extend(shape_values);
                }
            }
            start.push(nodes.len());
        }
        let surface_triangles = fine.surface_triangles();
        let mut surface_vertices: Vec<u32> = surface_triangles.iter().flatten().copied().collect();
        surface_vertices.sort_unstable();
        surface_vertices.dedup();
        Ok(Self {
            mesh: fine,
            surface_triangles,
            surface_vertices,
            start,
            nodes,
            weights,
        })
    }

    /// The fine mesh at rest, in the body's own frame (m).
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The fine mesh's boundary triangles, outward-oriented: the collision and render surface.
    pub fn surface_triangles(&self) -> &[[u32; 3]] {
        &self.surface_triangles
    }

    /// The vertices on the fine mesh's boundary, ascending: those contacts are detected for.
    pub fn surface_vertices(&self) -> &[u32] {
        &self.surface_vertices
    }

    /// The simulation nodes vertex `vertex` moves with, and their weights (summing to one).
    ///
    /// # Panics
    /// If the vertex does not exist.
    pub fn stencil(&self, vertex: u32) -> (&[u32], &[f64]) {
        let range = self.start[vertex as usize]..self.start[vertex as usize + 1];
        (&self.nodes[range.clone()], &self.weights[range])
    }

    /// The position (m) of vertex `vertex` for node positions `x` (m); with velocities, its
    /// velocity (m/s).
    ///
    /// # Panics
    /// If the vertex does not exist.
    pub fn interpolate(&self, vertex: u32, x: &[DVec3]) -> DVec3 {
        let (nodes, weights) = self.stencil(vertex);
        nodes
            .iter()
            .zip(weights)
            .map(|(&n, w)| x[n as usize] * *w)
            .sum()
    }

    /// The positions (m) of all fine vertices for node positions `x` (m).
    pub fn positions(&self, x: &[DVec3]) -> Vec<DVec3> {
        (0..self.mesh.node_count() as u32)
            .map(|v| self.interpolate(v, x))
            .collect()
    }
}

/// The nodes of quadratic element `element` and their shape functions at rest point `p` (m),
/// which lies in the element's subdivision tetrahedron `sub_tet` at barycentric coordinates
/// `barycentric`: the natural coordinates interpolated there, refined by Newton's method on
/// the (possibly curved) isoparametric map.
fn quadratic_weights<'a>(
    quadratic: &'a QuadraticElements,
    element: usize,
    rest: &[DVec3],
    sub_tet: &[u32; 4],
    barycentric: [f64; 4],
    p: DVec3,
) -> (&'a [u32], Vec<f64>) {
    let nodes = quadratic.element(element);
    let reference = quadratic.shape().reference_nodes();
    let guess: DVec3 = sub_tet
        .iter()
        .zip(barycentric)
        .map(|(n, l)| {
            let local = nodes.iter().position(|m| m == n).unwrap_or(0);
            reference[local] * l
        })
        .sum();
    let (xi, _) = quadratic.natural_coordinates(element, rest, p, guess);
    (nodes, quadratic.shape().shape_values(xi))
}

/// A uniform grid over a tetrahedral mesh's bounding box: per cell, the tetrahedra whose
/// bounding boxes overlap it.
struct TetGrid {
    origin: DVec3,
    cell: f64,
    counts: [usize; 3],
    tets: Vec<Vec<u32>>,
}

impl TetGrid {
    fn new(mesh: &TetMesh) -> Self {
        let p = mesh.positions();
        let (lo, hi) = p.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), x| (lo.min(*x), hi.max(*x)),
        );
        // About one tetrahedron per cell.
        let volume = (hi - lo)
            .max(DVec3::splat(f64::MIN_POSITIVE))
            .element_product();
        let cell = (volume / mesh.tet_count() as f64)
            .cbrt()
            .max(f64::MIN_POSITIVE);
        let extent = ((hi - lo) / cell).ceil().max(DVec3::ONE);
        let counts = [extent.x as usize, extent.y as usize, extent.z as usize];
        let mut grid = Self {
            origin: lo,
            cell,
            counts,
            tets: vec![Vec::new(); counts[0] * counts[1] * counts[2]],
        };
        for (t, tet) in mesh.tets().iter().enumerate() {
            let corners = tet.map(|n| p[n as usize]);
            let tet_lo = corners.iter().fold(corners[0], |a, b| a.min(*b));
            let tet_hi = corners.iter().fold(corners[0], |a, b| a.max(*b));
            let (c_lo, c_hi) = (grid.cell_of(tet_lo), grid.cell_of(tet_hi));
            for k in c_lo[2]..=c_hi[2] {
                for j in c_lo[1]..=c_hi[1] {
                    for i in c_lo[0]..=c_hi[0] {
                        let index = grid.index([i, j, k]);
                        grid.tets[index].push(t as u32);
                    }
                }
            }
        }
        grid
    }

    /// The cell containing `p`, clamped to the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let c = ((p - self.origin) / self.cell).floor();
        std::array::from_fn(|k| (c[k].max(0.0) as usize).min(self.counts[k] - 1))
    }

    fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        i + self.counts[0] * (j + self.counts[1] * k)
    }

    /// The tetrahedron containing `p` (m) and `p`'s barycentric coordinates in it, or, for a
    /// point outside the mesh, the nearby tetrahedron it is least outside of (the largest
    /// smallest coordinate).
    fn locate(&self, mesh: &TetMesh, p: DVec3) -> (usize, [f64; 4]) {
        let mut best = (0, [f64::NEG_INFINITY; 4]);
        let mut consider = |t: u32| {
            let l = barycentric(mesh, t as usize, p);
            let worst = l.iter().copied().fold(f64::INFINITY, f64::min);
            if worst > best.1.iter().copied().fold(f64::INFINITY, f64::min) {
                best = (t as usize, l);
            }
            worst >= 0.0
        };
        let home = self.cell_of(p);
        if self.tets[self.index(home)].iter().any(|&t| consider(t)) {
            return best;
        }
        // Outside every tetrahedron of its cell: search the surrounding block.
        for k in home[2].saturating_sub(1)..=(home[2] + 1).min(self.counts[2] - 1) {
            for j in home[1].saturating_sub(1)..=(home[1] + 1).min(self.counts[1] - 1) {
                for i in home[0].saturating_sub(1)..=(home[0] + 1).min(self.counts[0] - 1) {
                    for &t in &self.tets[self.index([i, j, k])] {
                        if consider(t) {
                            return best;
                        }
                    }
                }
            }
        }
        best
    }
}

/// The barycentric coordinates of `p` (m) in tetrahedron `tet` of `mesh`.
fn barycentric(mesh: &TetMesh, tet: usize, p: DVec3) -> [f64; 4] {
    let x = mesh.tets()[tet].map(|n| mesh.positions()[n as usize]);
    let edges = rapier3d::glamx::DMat3::from_cols(x[1] - x[0], x[2] - x[0], x[3] - x[0]);
    let l = edges.inverse() * (p - x[0]);
    [1.0 - l.x - l.y - l.z, l.x, l.y, l.z]
}

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
use crate::stencil::Stencil;
use rapier3d::glamx::DVec3;
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy};

/// A fine mesh embedded in a body's simulation mesh (see the [module](self) documentation).
/// Made by [`DeformableBodyBuilder::embedded`](crate::body::DeformableBodyBuilder::embedded).
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
        let tree = TetTree::new(simulation);
        let rest = simulation.positions();
        let quadratic = match elements {
            Elements::Quadratic { elements, .. } => Some(elements),
            Elements::Linear { .. } => None,
        };
        let mut start = vec![0];
        let (mut nodes, mut weights) = (Vec::new(), Vec::new());
        for (vertex, &p) in fine.positions().iter().enumerate() {
            let located = tree.locate(simulation, p).filter(|(_, l)| {
                l.iter().copied().fold(f64::INFINITY, f64::min) >= -OUTSIDE_TOLERANCE
            });
            let Some((tet, barycentric)) = located else {
                return Err(Error::OutsideSimulationMesh {
                    vertex,
                    position: p.to_array(),
                });
            };
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
        self.point_stencil(vertex).interpolate(x)
    }

    /// [`Embedding::stencil`] as a contact point's stencil.
    pub(crate) fn point_stencil(&self, vertex: u32) -> Stencil<'_> {
        let (nodes, weights) = self.stencil(vertex);
        Stencil { nodes, weights }
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
    let xi = quadratic.natural_coordinates(element, rest, p, guess);
    (nodes, quadratic.shape().shape_values(xi))
}

/// A parry bounding-volume hierarchy over a tetrahedral mesh's tetrahedra, each box padded by
/// [`OUTSIDE_TOLERANCE`] of the tetrahedron's longest extent so that points slightly outside
/// the mesh still find their nearest tetrahedra.
struct TetTree {
    bvh: Bvh,
}

impl TetTree {
    fn new(mesh: &TetMesh) -> Self {
        let p = mesh.positions();
        let leaves: Vec<Aabb> = mesh
            .tets()
            .iter()
            .map(|tet| {
                let corners = tet.map(|n| p[n as usize]);
                let lo = corners.iter().fold(corners[0], |a, b| a.min(*b));
                let hi = corners.iter().fold(corners[0], |a, b| a.max(*b));
                let padding = DVec3::splat(OUTSIDE_TOLERANCE * (hi - lo).max_element());
                Aabb::new((lo - padding).as_vec3(), (hi + padding).as_vec3())
            })
            .collect();
        Self {
            bvh: Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
        }
    }

    /// The tetrahedron containing `p` (m) and `p`'s barycentric coordinates in it, or, for a
    /// point outside the mesh, the nearby tetrahedron it is least outside of (the largest
    /// smallest coordinate); `None` when no tetrahedron is near.
    fn locate(&self, mesh: &TetMesh, p: DVec3) -> Option<(usize, [f64; 4])> {
        let query = Aabb::new(p.as_vec3(), p.as_vec3());
        let smallest = |l: &[f64; 4]| l.iter().copied().fold(f64::INFINITY, f64::min);
        let mut best: Option<(usize, [f64; 4])> = None;
        for leaf in self.bvh.intersect_aabb(&query) {
            let l = barycentric(mesh, leaf as usize, p);
            if best.is_none_or(|(_, b)| smallest(&l) > smallest(&b)) {
                best = Some((leaf as usize, l));
            }
            if smallest(&l) >= 0.0 {
                break;
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

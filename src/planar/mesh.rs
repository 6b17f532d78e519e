//! Triangle meshes in the plane: rest positions (m) and counterclockwise triangles, checked when
//! built as tetrahedral meshes are (see [`crate::mesh`]), and generators for the shapes a 2D
//! scene starts from.
//!
//! Contract: a mesh that passes [`TriangleMesh::new`] has every coordinate finite and within
//! ±[`MAX_COORDINATE`] m, every node in some triangle, and every triangle three distinct nodes
//! with a positive rest area `A > 1e-12 l²` (`l` its longest edge). Every defect is an [`Error`]
//! naming the first offending node or triangle.

use crate::Error;
use crate::limits::MAX_COORDINATE;
use rapier3d::glamx::DVec2;

/// Relative area below which a triangle counts as degenerate: `|A| <= 1e-12 l²`.
const DEGENERATE_RELATIVE_AREA: f64 = 1e-12;

/// How the cells of [`TriangleMesh::quadrilateral_with`] are cut into triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Diagonals {
    /// Along alternating diagonals, four triangles meeting at every other node ("union jack"):
    /// no preferred direction, and free of volumetric locking in plane strain.
    #[default]
    Alternating,
    /// All along the diagonal from the cell's first corner to its third: a preferred direction,
    /// and the pattern on which linear triangles lock as `ν → 0.5` in plane strain.
    Parallel,
}

/// A mesh of linear (3-node) triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    rest: Vec<DVec2>,
    triangles: Vec<[u32; 3]>,
}

/// The signed area (m²) of the triangle `a b c`: positive when counterclockwise.
pub(crate) fn signed_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    0.5 * (b - a).perp_dot(c - a)
}

impl TriangleMesh {
    /// A mesh of `rest` positions (m) and `triangles`, each three node indices counterclockwise.
    ///
    /// # Errors
    /// [`Error::EmptyTriangleMesh`], [`Error::NonFiniteCoordinate`],
    /// [`Error::CoordinateOutOfRange`], [`Error::TriangleNodeOutOfRange`],
    /// [`Error::TriangleRepeatedNode`], [`Error::DegenerateTriangle`],
    /// [`Error::InvertedTriangle`] or [`Error::UnreferencedNode`], naming the first offender.
    pub fn new(rest: Vec<DVec2>, triangles: Vec<[u32; 3]>) -> Result<Self, Error> {
        if rest.is_empty() || triangles.is_empty() {
            return Err(Error::EmptyTriangleMesh {
                nodes: rest.len(),
                triangles: triangles.len(),
            });
        }
        for (node, p) in rest.iter().enumerate() {
            let position = [p.x, p.y, 0.0];
            if !p.is_finite() {
                return Err(Error::NonFiniteCoordinate { node, position });
            }
            if p.abs().max_element() > MAX_COORDINATE {
                return Err(Error::CoordinateOutOfRange { node, position });
            }
        }
        let mut used = vec![false; rest.len()];
        for (triangle, nodes) in triangles.iter().enumerate() {
            check_triangle(triangle, *nodes, &rest)?;
            for &n in nodes {
                used[n as usize] = true;
            }
        }
        if let Some(node) = used.iter().position(|&u| !u) {
            return Err(Error::UnreferencedNode { node });
        }
        Ok(Self { rest, triangles })
    }

    /// The rest positions (m).
    pub fn rest_positions(&self) -> &[DVec2] {
        &self.rest
    }

    /// The triangles, node indices counterclockwise.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The rest positions (m) of triangle `t`'s corners.
    pub fn corners(&self, t: usize) -> [DVec2; 3] {
        self.triangles[t].map(|n| self.rest[n as usize])
    }

    /// The mesh's rest area (m²).
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                signed_area(a, b, c)
            })
            .sum()
    }

    /// The nodes within `tolerance` (m) of the line through `point` along `direction`, in
    /// increasing order: a clamped or loaded edge of a generated mesh.
    pub fn nodes_on_line(&self, point: DVec2, direction: DVec2, tolerance: f64) -> Vec<usize> {
        let normal = direction.perp().normalize();
        (self.rest.iter().enumerate())
            .filter(|(_, p)| (**p - point).dot(normal).abs() <= tolerance)
            .map(|(i, _)| i)
            .collect()
    }
}

impl TriangleMesh {
    /// The nodes of the mesh's 6-node triangles: the corners (same indices), then a node at the
    /// middle of each edge, shared by the triangles on it; each triangle's six nodes, corners
    /// then the mid-edge nodes of edges 01, 12, 20; and the boundary as segments (see
    /// [`TriangleMesh::boundary_edges`]), each edge cut at its mid-edge node. A body built
    /// with [`PlanarBodyBuilder::quadratic`](super::PlanarBodyBuilder::quadratic) has these
    /// nodes, in this order.
    pub fn quadratic_nodes(&self) -> (Vec<DVec2>, Vec<[u32; 6]>, Vec<[u32; 2]>) {
        let mut rest = self.rest.clone();
        let mut middle_of = std::collections::HashMap::new();
        let mut middle = |a: u32, b: u32, rest: &mut Vec<DVec2>| -> u32 {
            *middle_of.entry((a.min(b), a.max(b))).or_insert_with(|| {
                rest.push((rest[a as usize] + rest[b as usize]) / 2.0);
                (rest.len() - 1) as u32
            })
        };
        let elements = (self.triangles.iter())
            .map(|&[a, b, c]| {
                let (ab, bc, ca) = (
                    middle(a, b, &mut rest),
                    middle(b, c, &mut rest),
                    middle(c, a, &mut rest),
                );
                [a, b, c, ab, bc, ca]
            })
            .collect();
        let boundary = (self.boundary_edges().into_iter())
            .flat_map(|[a, b]| {
                let m = middle(a, b, &mut rest);
                [[a, m], [m, b]]
            })
            .collect();
        (rest, elements, boundary)
    }

    /// The boundary: the edges of one triangle only, each oriented as its triangle has it
    /// (counterclockwise), so that the mesh lies to its left and `(dy, −dx)` points out.
    pub fn boundary_edges(&self) -> Vec<[u32; 2]> {
        let mut count = std::collections::HashMap::new();
        for &[a, b, c] in &self.triangles {
            for (p, q) in [(a, b), (b, c), (c, a)] {
                *count.entry((p.min(q), p.max(q))).or_insert(0u32) += 1;
            }
        }
        (self.triangles.iter())
            .flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
            .filter(|[p, q]| count[&(*p.min(q), *p.max(q))] == 1)
            .collect()
    }
}

/// Checks triangle `triangle` with `nodes` against the `rest` positions.
fn check_triangle(triangle: usize, nodes: [u32; 3], rest: &[DVec2]) -> Result<(), Error> {
    for (k, &node) in nodes.iter().enumerate() {
        if node as usize >= rest.len() {
            return Err(Error::TriangleNodeOutOfRange {
                triangle,
                node,
                node_count: rest.len(),
            });
        }
        if nodes[..k].contains(&node) {
            return Err(Error::TriangleRepeatedNode { triangle, node });
        }
    }
    let [a, b, c] = nodes.map(|n| rest[n as usize]);
    let area = signed_area(a, b, c);
    let longest = (b - a).length().max((c - b).length()).max((a - c).length());
    if area.abs() <= DEGENERATE_RELATIVE_AREA * longest * longest || !area.is_normal() {
        return Err(Error::DegenerateTriangle { triangle, area });
    }
    if area < 0.0 {
        return Err(Error::InvertedTriangle { triangle, area });
    }
    Ok(())
}

/// The most triangles a generator makes (as [`TriangleMesh::polygon`]'s), so that a mistyped
/// cell count is refused rather than exhausting memory (about 1 kB per triangle once a body is
/// built).
const MAX_GENERATED_TRIANGLES: f64 = 1e7;

/// Checks that a generator making `triangles` triangles stays within
/// [`MAX_GENERATED_TRIANGLES`]; `parameter` and `value` name what sets it.
fn check_triangle_count(parameter: &'static str, value: f64, triangles: f64) -> Result<(), Error> {
    if triangles > MAX_GENERATED_TRIANGLES {
        return Err(Error::InvalidGeneratorParameter {
            parameter,
            value,
            reason: "would make more than ten million triangles",
        });
    }
    Ok(())
}

/// Checks that a generator's `cells` count is at least one.
fn check_cells(parameter: &'static str, cells: usize) -> Result<(), Error> {
    if cells == 0 || cells > 1 << 14 {
        return Err(Error::InvalidGeneratorParameter {
            parameter,
            value: cells as f64,
            reason: "must be between 1 and 16384",
        });
    }
    Ok(())
}

impl TriangleMesh {
    /// The quadrilateral with counterclockwise `corners` (m), mapped bilinearly onto a grid of
    /// `cells[0]` cells from the first corner to the second and `cells[1]` from the second to
    /// the third, each cut into two triangles along alternating diagonals (so that the mesh has
    /// no preferred direction; see [`Diagonals`]). Cook's membrane is
    /// `[(0,0), (48,44), (48,60), (0,44)]`.
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] for zero cells, more than 16 384 along a side or more
    /// than ten million triangles; the errors of [`TriangleMesh::new`] for corners that fold the
    /// quadrilateral.
    pub fn quadrilateral(corners: [DVec2; 4], cells: [usize; 2]) -> Result<Self, Error> {
        Self::quadrilateral_with(corners, cells, Diagonals::Alternating)
    }

    /// [`TriangleMesh::quadrilateral`] with the cells cut along `diagonals`.
    ///
    /// # Errors
    /// As [`TriangleMesh::quadrilateral`].
    pub fn quadrilateral_with(
        corners: [DVec2; 4],
        cells: [usize; 2],
        diagonals: Diagonals,
    ) -> Result<Self, Error> {
        check_cells("cells[0]", cells[0])?;
        check_cells("cells[1]", cells[1])?;
        let triangles = 2.0 * cells[0] as f64 * cells[1] as f64;
        check_triangle_count("cells[0] × cells[1]", triangles / 2.0, triangles)?;
        let [nx, ny] = cells;
        let [p0, p1, p2, p3] = corners;
        let mut rest = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            let v = j as f64 / ny as f64;
            for i in 0..=nx {
                let u = i as f64 / nx as f64;
                rest.push(p0.lerp(p1, u).lerp(p3.lerp(p2, u), v));
            }
        }
        let node = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut triangles = Vec::with_capacity(2 * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let [a, b, c, d] = [
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ];
                let rising = match diagonals {
                    Diagonals::Alternating => (i + j) % 2 == 0,
                    Diagonals::Parallel => true,
                };
                if rising {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        Self::new(rest, triangles)
    }

    /// The rectangle of `size` (m) with its lower left corner at the origin, `cells` along x and
    /// y (see [`TriangleMesh::quadrilateral`]).
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] for a non-positive or non-finite size, bad cells or
    /// more than ten million triangles.
    pub fn rectangle(size: DVec2, cells: [usize; 2]) -> Result<Self, Error> {
        for (parameter, value) in [("size.x", size.x), ("size.y", size.y)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidGeneratorParameter {
                    parameter,
                    value,
                    reason: "must be positive and finite",
                });
            }
        }
        let corners = [
            DVec2::ZERO,
            DVec2::new(size.x, 0.0),
            size,
            DVec2::new(0.0, size.y),
        ];
        Self::quadrilateral(corners, cells)
    }

    /// The disk of `radius` (m) centred at the origin, in `rings` rings of triangles around a
    /// centre node, ring `k` holding `6 k` nodes on its circle (nearly equilateral triangles).
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] for a non-positive radius, bad rings or more than
    /// ten million triangles.
    pub fn disk(radius: f64, rings: usize) -> Result<Self, Error> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::InvalidGeneratorParameter {
                parameter: "radius",
                value: radius,
                reason: "must be positive and finite",
            });
        }
        check_cells("rings", rings)?;
        check_triangle_count("rings", rings as f64, 6.0 * (rings as f64).powi(2))?;
        let mut rest = vec![DVec2::ZERO];
        for k in 1..=rings {
            let r = radius * k as f64 / rings as f64;
            for s in 0..6 * k {
                let angle = std::f64::consts::TAU * s as f64 / (6 * k) as f64;
                rest.push(DVec2::new(r * angle.cos(), r * angle.sin()));
            }
        }
        // First node of ring k: 1 + 3 k (k - 1).
        let first = |k: usize| if k == 0 { 0 } else { 1 + 3 * k * (k - 1) };
        let on_ring = |k: usize, s: usize| (first(k) + if k == 0 { 0 } else { s % (6 * k) }) as u32;
        let mut triangles = Vec::new();
        for k in 1..=rings {
            // Each of the six sectors: k outer edges, k - 1 inner edges.
            for sector in 0..6 {
                for s in 0..k {
                    let outer = sector * k + s;
                    let inner = sector * (k - 1) + s;
                    triangles.push([
                        on_ring(k - 1, inner),
                        on_ring(k, outer),
                        on_ring(k, outer + 1),
                    ]);
                    if s + 1 < k {
                        triangles.push([
                            on_ring(k - 1, inner),
                            on_ring(k, outer + 1),
                            on_ring(k - 1, inner + 1),
                        ]);
                    }
                }
            }
        }
        Self::new(rest, triangles)
    }
}

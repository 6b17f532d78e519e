//! Triangle meshes of a polygon outline: a constrained Delaunay triangulation of the outline,
//! refined (Ruppert's algorithm, by `spade`) until no triangle is larger than an equilateral
//! one of the edge length asked for and no angle is below 25° (where the outline's own angles
//! allow).
//!
//! Contract: the outline is checked first (at least three vertices, finite and within
//! ±[`MAX_COORDINATE`], no edge of zero length, no two edges crossing or touching but
//! neighbours at their shared vertex, none folding back onto its neighbour, a non-zero area,
//! either orientation; points collinear to round-off count as collinear): a bad one is an
//! [`Error::InvalidGeneratorParameter`] naming the first offending vertex or edge, and spade,
//! whose constraint insertion panics on crossing edges, never sees it.

use super::mesh::TriangleMesh;
use crate::Error;
use crate::limits::MAX_COORDINATE;
use rapier3d::glamx::DVec2;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

/// The smallest angle (degrees) the refinement keeps where the outline allows.
const ANGLE_LIMIT_DEGREES: f64 = 25.0;

/// An error naming `parameter` with `value` and `reason`.
fn invalid(parameter: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidGeneratorParameter {
        parameter,
        value,
        reason,
    }
}

/// Relative size below which a cross product counts as zero: three points within
/// `1e-12 |q − p| |r − p|` of a line are collinear (round-off of coordinates that are exactly
/// collinear, such as `0.3` between `0.5` and `0.0`, is far smaller than that).
const COLLINEAR: f64 = 1e-12;

/// `(q − p) × (r − p)`, zero when the three points are collinear to round-off.
fn side(p: DVec2, q: DVec2, r: DVec2) -> f64 {
    let cross = (q - p).perp_dot(r - p);
    if cross.abs() <= COLLINEAR * (q - p).length() * (r - p).length() {
        0.0
    } else {
        cross
    }
}

/// Whether the closed segments `a b` and `c d` share a point.
fn segments_meet(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (d1, d2, d3, d4) = (side(c, d, a), side(c, d, b), side(a, b, c), side(a, b, d));
    let within = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let crossing = (d1 > 0.0) != (d2 > 0.0) && (d3 > 0.0) != (d4 > 0.0);
    (crossing && d1 != 0.0 && d2 != 0.0 && d3 != 0.0 && d4 != 0.0)
        || (d1 == 0.0 && within(c, d, a))
        || (d2 == 0.0 && within(c, d, b))
        || (d3 == 0.0 && within(a, b, c))
        || (d4 == 0.0 && within(a, b, d))
}

/// Whether the outline turns back on itself at `b`, between `a` and `c`: the two edges lie
/// along one line, overlapping.
fn folds_back(a: DVec2, b: DVec2, c: DVec2) -> bool {
    side(b, a, c) == 0.0 && (a - b).dot(c - b) > 0.0
}

/// Checks the `outline` (see the module's contract).
fn check_outline(outline: &[DVec2]) -> Result<(), Error> {
    let n = outline.len();
    if n < 3 {
        return Err(invalid(
            "outline",
            n as f64,
            "a polygon needs at least three vertices",
        ));
    }
    for (i, p) in outline.iter().enumerate() {
        if !p.is_finite() || p.abs().max_element() > MAX_COORDINATE {
            return Err(invalid(
                "outline vertex",
                i as f64,
                "must be finite and within ±1e50 m",
            ));
        }
        if *p == outline[(i + 1) % n] {
            return Err(invalid(
                "outline edge",
                i as f64,
                "has zero length (a repeated vertex)",
            ));
        }
    }
    for i in 0..n {
        let (previous, next) = (outline[(i + n - 1) % n], outline[(i + 1) % n]);
        if folds_back(previous, outline[i], next) {
            return Err(invalid(
                "outline vertex",
                i as f64,
                "its two edges fold back onto each other",
            ));
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            let (a, b) = (outline[i], outline[(i + 1) % n]);
            let (c, d) = (outline[j], outline[(j + 1) % n]);
            if !neighbours && segments_meet(a, b, c, d) {
                return Err(invalid(
                    "outline edge",
                    j as f64,
                    "crosses or touches an earlier edge",
                ));
            }
        }
    }
    let area: f64 = (0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<f64>()
        / 2.0;
    if area == 0.0 {
        return Err(invalid("outline", area, "encloses no area"));
    }
    Ok(())
}

impl TriangleMesh {
    /// The polygon inside `outline` (m, vertices in order, either orientation, not repeated at
    /// the end), meshed with triangles no larger than an equilateral one of side `edge_length`
    /// (m) and angles of at least 25° where the outline's allow (see the module's
    /// documentation).
    ///
    /// # Errors
    /// [`Error::InvalidGeneratorParameter`] for a bad outline (naming the vertex or edge) or a
    /// non-positive edge length, or one that would need more than ten million triangles;
    /// [`Error::AllocationFailed`] should the triangulation be refused memory.
    ///
    /// # Example
    /// ```
    /// use rapier_fvm::glamx::DVec2;
    /// use rapier_fvm::planar::TriangleMesh;
    ///
    /// // An L-shaped bracket, 1 m by 1 m with 0.4 m arms, in triangles of about 5 cm.
    /// let outline = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.4), (0.4, 0.4), (0.4, 1.0), (0.0, 1.0)]
    ///     .map(|(x, y)| DVec2::new(x, y));
    /// let bracket = TriangleMesh::polygon(&outline, 0.05)?;
    /// assert!((bracket.area() - 0.64).abs() < 1e-12);
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn polygon(outline: &[DVec2], edge_length: f64) -> Result<Self, Error> {
        if !(edge_length.is_finite() && edge_length > 0.0) {
            return Err(invalid(
                "edge_length",
                edge_length,
                "must be positive and finite (m)",
            ));
        }
        check_outline(outline)?;
        let target_area = 3f64.sqrt() / 4.0 * edge_length * edge_length;
        let area: f64 = (0..outline.len())
            .map(|i| outline[i].perp_dot(outline[(i + 1) % outline.len()]))
            .sum::<f64>()
            .abs()
            / 2.0;
        let expected = area / target_area;
        if expected > 1e7 {
            return Err(invalid(
                "edge_length",
                edge_length,
                "would need more than ten million triangles",
            ));
        }
        let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
        let handles: Vec<FixedVertexHandle> = (outline.iter())
            .map(|p| cdt.insert(Point2::new(p.x, p.y)))
            .collect::<Result<_, _>>()
            .map_err(|_| invalid("outline", 0.0, "a vertex cannot be triangulated"))?;
        for i in 0..handles.len() {
            let (from, to) = (handles[i], handles[(i + 1) % handles.len()]);
            if cdt.try_add_constraint(from, to).is_empty() {
                return Err(invalid(
                    "outline edge",
                    i as f64,
                    "cannot be kept as an edge",
                ));
            }
        }
        let parameters = RefinementParameters::<f64>::new()
            .with_max_allowed_area(target_area)
            .with_angle_limit(AngleLimit::from_deg(ANGLE_LIMIT_DEGREES))
            .with_max_additional_vertices(10 * expected as usize + 10 * outline.len() + 100)
            .exclude_outer_faces(true);
        let refined = cdt.refine(parameters);
        let excluded: std::collections::HashSet<_> = refined.excluded_faces.into_iter().collect();
        let mut index = vec![u32::MAX; cdt.num_vertices()];
        let mut rest = Vec::new();
        let mut triangles = Vec::new();
        for face in cdt.inner_faces().filter(|f| !excluded.contains(&f.fix())) {
            let corners = face.vertices().map(|v| {
                let slot = &mut index[v.fix().index()];
                if *slot == u32::MAX {
                    *slot = rest.len() as u32;
                    rest.push(DVec2::new(v.position().x, v.position().y));
                }
                *slot
            });
            triangles.push(corners);
        }
        Self::new(rest, triangles)
    }
}

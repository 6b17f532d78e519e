//! A mesh read from a file is the file's: as many tetrahedra as it holds, the nodes they use and
//! the volume their corners enclose, `Σ |det(b - a, c - a, d - a)| / 6`, summed here from the
//! file's own numbers. For the cube's `TetGen` and Gmsh 2.2 ASCII files those numbers come from a
//! few lines of independent parsing (whitespace-separated tokens, nothing of the crate's
//! readers); for every mesh a reader returns, the fuzzed files' included, from the reader's raw
//! output before validation.
//!
//! Volumes agree when they differ by at most `32 ε Σ ℓ³` over the tetrahedra, `ℓ` the longest edge
//! of each and `ε` the machine epsilon: a 3x3 determinant of edges no longer than `ℓ` is a sum of
//! six products of three coordinates, each at most `ℓ³`, rounded about a dozen times, and the two
//! sums order their terms differently: 1.6e-13 m³ for the unit cube. A non-finite volume never
//! agrees.

use super::{asset, bytes};
use rapier_fvm::mesh::import::{self, RawMesh, SurfaceOptions};
use rapier_fvm::prelude::*;

/// Node positions and tetrahedra (indices into them), as a file writes them.
type Numbers = (Vec<DVec3>, Vec<[usize; 4]>);

/// The summed volume of `tets` (m³) and the round-off allowed in comparing it (see the module).
fn volume_and_tolerance(positions: &[DVec3], tets: &[[usize; 4]]) -> (f64, f64) {
    tets.iter().fold((0.0, 0.0), |(volume, tolerance), tet| {
        let [a, b, c, d] = tet.map(|n| positions[n]);
        let edges = DMat3::from_cols(b - a, c - a, d - a);
        let longest = [a, b, c, d]
            .iter()
            .flat_map(|p| [a, b, c, d].map(|q| p.distance(q)))
            .fold(0.0, f64::max);
        (
            volume + edges.determinant().abs() / 6.0,
            tolerance + 32.0 * f64::EPSILON * longest.powi(3),
        )
    })
}

/// Whether two volumes (m³) agree within `tolerance` (m³); never for a non-finite one.
fn volumes_agree(a: f64, b: f64, tolerance: f64) -> bool {
    a.is_finite() && b.is_finite() && (a - b).abs() <= tolerance
}

/// How many distinct nodes `tets` use.
fn used_nodes(tets: impl IntoIterator<Item = usize>) -> usize {
    let mut nodes: Vec<usize> = tets.into_iter().collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes.len()
}

/// Asserts that `mesh` is what `raw` holds: for linear tetrahedra their count, the nodes they use
/// and their volume; for quadratic ones (subdivided into eight each) the counts and a finite,
/// positive volume.
pub(super) fn assert_mesh_is_the_files(raw: &RawMesh, mesh: &TetMesh) {
    let corners = raw.tets.iter().flatten().map(|&n| n as usize);
    if !raw.mid_edge_nodes.is_empty() {
        let mids = raw.mid_edge_nodes.iter().flatten().map(|&n| n as usize);
        assert_eq!(mesh.tet_count(), 8 * raw.tets.len());
        assert_eq!(mesh.node_count(), used_nodes(corners.chain(mids)));
        assert!(
            mesh.volume().is_finite() && mesh.volume() > 0.0,
            "{}",
            mesh.volume()
        );
        return;
    }
    assert_eq!(mesh.tet_count(), raw.tets.len());
    assert_eq!(mesh.node_count(), used_nodes(corners));
    let tets: Vec<[usize; 4]> = raw.tets.iter().map(|t| t.map(|n| n as usize)).collect();
    let (volume, tolerance) = volume_and_tolerance(&raw.positions, &tets);
    assert!(
        volumes_agree(mesh.volume(), volume, tolerance),
        "mesh {} m³, file {volume} m³",
        mesh.volume()
    );
}

/// The lines of `text` without `#` comments, split into tokens, blank lines skipped.
fn token_lines(text: &str) -> impl Iterator<Item = Vec<&str>> {
    text.lines()
        .map(|line| {
            line.split('#')
                .next()
                .unwrap_or("")
                .split_whitespace()
                .collect::<Vec<_>>()
        })
        .filter(|tokens| !tokens.is_empty())
}

/// A `TetGen` `.node` and `.ele` pair: a header line then one line per node (`index x y z`) or
/// tetrahedron (`index a b c d`), indices counted from the first node's.
fn tetgen_numbers(node: &str, ele: &str) -> Numbers {
    let nodes: Vec<Vec<&str>> = token_lines(node).skip(1).collect();
    let first: usize = nodes[0][0].parse().unwrap();
    let positions = nodes
        .iter()
        .map(|t| DVec3::from_array([1, 2, 3].map(|i| t[i].parse().unwrap())))
        .collect();
    let tets = token_lines(ele)
        .skip(1)
        .map(|t| [1, 2, 3, 4].map(|i| t[i].parse::<usize>().unwrap() - first))
        .collect();
    (positions, tets)
}

/// A Gmsh 2.2 ASCII file: the `$Nodes` lines `id x y z` and the `$Elements` lines
/// `id type tag-count tags… nodes…` of type 4 (the four-node tetrahedron).
fn gmsh22_numbers(text: &str) -> Numbers {
    let section = |name: &str| -> Vec<Vec<&str>> {
        let start = text.find(&format!("${name}\n")).unwrap();
        let end = text.find(&format!("$End{name}\n")).unwrap();
        token_lines(&text[start..end]).skip(2).collect()
    };
    let nodes = section("Nodes");
    let index_of = |id: &str| nodes.iter().position(|t| t[0] == id).unwrap();
    let positions = nodes
        .iter()
        .map(|t| DVec3::from_array([1, 2, 3].map(|i| t[i].parse().unwrap())))
        .collect();
    let tets = section("Elements")
        .iter()
        .filter(|t| t[1] == "4")
        .map(|t| {
            let tags: usize = t[2].parse().unwrap();
            [0, 1, 2, 3].map(|i| index_of(t[3 + tags + i]))
        })
        .collect();
    (positions, tets)
}

#[test]
fn the_cube_files_hold_the_mesh_their_numbers_give() {
    let text = |name: &str| String::from_utf8(bytes(name)).unwrap();
    let cases = [
        (
            "cube.node",
            tetgen_numbers(&text("cube.node"), &text("cube.ele")),
        ),
        (
            "cube_v22_ascii.msh",
            gmsh22_numbers(&text("cube_v22_ascii.msh")),
        ),
    ];
    for (name, (positions, tets)) in cases {
        let mesh = import::load(asset(name), 1.0, &SurfaceOptions::default()).unwrap();
        let (volume, tolerance) = volume_and_tolerance(&positions, &tets);
        println!(
            "{name}: {} tetrahedra on {} nodes, {volume:.15} m³ from its numbers; loaded {} on {}, \
             {:.15} m³ (difference {:.1e} m³, tolerance {tolerance:.1e} m³)",
            tets.len(),
            positions.len(),
            mesh.tet_count(),
            mesh.node_count(),
            mesh.volume(),
            (mesh.volume() - volume).abs()
        );
        assert_eq!(mesh.tet_count(), tets.len(), "{name}");
        assert_eq!(
            mesh.node_count(),
            used_nodes(tets.iter().flatten().copied())
        );
        assert!(volumes_agree(mesh.volume(), volume, tolerance), "{name}");
        let raw = import::load_raw(asset(name), 1.0, &SurfaceOptions::default()).unwrap();
        assert_mesh_is_the_files(&raw, &mesh);
    }
    assert!(!volumes_agree(f64::NAN, 1.0, 1.0) && !volumes_agree(1.0, f64::INFINITY, 1.0));
}

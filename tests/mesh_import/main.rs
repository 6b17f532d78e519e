//! Mesh import: each format read from real files (written by gmsh and meshio, see
//! `tools/make_test_meshes.py`) against closed-form values, the formats against each other and
//! the files' own numbers, typed errors for malformed files, and fuzzing of every reader.

use rapier_fvm::mesh::import::{self, RawMesh, SurfaceOptions, gmsh, tetgen, vtk};
use rapier_fvm::prelude::*;
use rapier_fvm::{FileLocation, ImportErrorKind};
use std::path::PathBuf;

mod binary_vtu;
mod file_numbers;
mod filling;
mod fuzz;
mod hexahedra;
mod malformed;
mod regions;

fn asset(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("assets/meshes")
        .join(name)
}

fn bytes(name: &str) -> Vec<u8> {
    std::fs::read(asset(name)).unwrap()
}

/// The unit cube [0, 1]^3 of gmsh (341 nodes, 1140 tetrahedra), in every tetrahedral format.
const CUBE_FILES: [&str; 9] = [
    "cube_v22_ascii.msh",
    "cube_v22_binary.msh",
    "cube_v41_ascii.msh",
    "cube_v41_binary.msh",
    "cube.node",
    "cube.ele",
    "cube_ascii.vtu",
    "cube_binary.vtu",
    "cube_ascii.vtk",
];

/// The same cube in the layouts meshio (zlib `.vtu`) and the VTK 9 library write (see
/// `tools/make_test_meshes.py`): appended raw and base64, inline base64, ASCII, uncompressed and
/// zlib (one and many blocks), 32- and 64-bit headers, 32-bit indices; legacy `.vtk` with METADATA;
/// and gmsh's MSH 4.0 and MSH 2.2 with `$ParametricNodes`.
const CUBE_FROM_OTHER_WRITERS: [&str; 14] = [
    "cube_zlib.vtu",
    "cube_vtk_defaults.vtu",
    "cube_vtk_appended_raw_zlib.vtu",
    "cube_vtk_appended_base64.vtu",
    "cube_vtk_appended_raw.vtu",
    "cube_vtk_binary_zlib.vtu",
    "cube_vtk_binary_uint32.vtu",
    "cube_vtk_ascii.vtu",
    "cube_vtk_zlib_small_blocks.vtu",
    "cube_vtk_header_uint64.vtu",
    "cube_vtk9_legacy.vtk",
    "cube_vtk9_legacy_binary.vtk",
    "cube_v40_ascii.msh",
    "cube_v22_parametric.msh",
];

#[test]
fn the_cube_reads_the_same_from_every_format() {
    let mut all = CUBE_FILES.to_vec();
    all.push("cube_binary.vtk");
    all.extend(CUBE_FROM_OTHER_WRITERS);
    let reference = import::load(asset(all[0]), 1.0, &SurfaceOptions::default()).unwrap();
    for name in all {
        let mesh = import::load(asset(name), 1.0, &SurfaceOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(mesh.tet_count(), 1140, "{name}");
        assert_eq!(mesh.node_count(), 341, "{name}");
        // Side 1: volume 1 to rounding.
        assert!(
            (mesh.volume() - 1.0).abs() < 1e-12,
            "{name}: {}",
            mesh.volume()
        );
        let (lo, hi) = mesh
            .positions()
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        assert_eq!((lo, hi), (DVec3::ZERO, DVec3::ONE), "{name}");
        // Same node order in every file (meshio renumbered the used nodes in order).
        // (ASCII files round coordinates: gmsh to 16 digits, meshio's VTU to about 12.)
        let gap = mesh
            .positions()
            .iter()
            .zip(reference.positions())
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        assert!(gap < 1e-11, "{name}: {gap}");
        assert_eq!(mesh.tets(), reference.tets(), "{name}");
    }
}

#[test]
fn gmsh_geometry_points_and_boundary_elements_are_dropped() {
    let raw = gmsh::parse(&bytes("cube_v41_ascii.msh"), "cube.msh", 1.0).unwrap();
    // gmsh writes every node, the cube's corners and boundary triangles among them; all are
    // used by tetrahedra here, the triangles are skipped.
    assert_eq!(raw.tets.len(), 1140);
    assert_eq!(raw.positions.len(), 341);
    assert!(matches!(raw.tet_locations[0], FileLocation::Line(_)));
    let binary = gmsh::parse(&bytes("cube_v41_binary.msh"), "cube.msh", 1.0).unwrap();
    assert!(matches!(binary.tet_locations[0], FileLocation::Byte(_)));
}

#[test]
fn scale_converts_to_metres() {
    let mm = import::load(
        asset("cube_v22_ascii.msh"),
        0.001,
        &SurfaceOptions::default(),
    )
    .unwrap();
    assert!((mm.volume() - 1e-9).abs() < 1e-21);
    for scale in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = import::load(
            asset("cube_v22_ascii.msh"),
            scale,
            &SurfaceOptions::default(),
        );
        assert!(matches!(
            e,
            Err(Error::InvalidSetting {
                parameter: "scale",
                ..
            })
        ));
    }
}

#[test]
fn a_missing_file_is_an_io_error() {
    let e = import::load("no/such/mesh.msh", 1.0, &SurfaceOptions::default()).unwrap_err();
    assert!(
        matches!(&e, Error::Io { path, .. } if path == "no/such/mesh.msh"),
        "{e}"
    );
    let e = import::load("mesh.xyz", 1.0, &SurfaceOptions::default()).unwrap_err();
    assert!(matches!(
        e,
        Error::MeshImport {
            kind: ImportErrorKind::UnknownFormat,
            ..
        }
    ));
}

fn kind_and_location(result: Result<RawMesh, Error>) -> (ImportErrorKind, FileLocation, String) {
    match result {
        Err(Error::MeshImport {
            kind,
            location,
            message,
            ..
        }) => (kind, location, message),
        other => panic!("expected an import error, got {other:?}"),
    }
}

#[test]
fn tetgen_reads_one_based_indices_attributes_and_comments() {
    let node = b"# a tetrahedron\n4 3 1 1 # one attribute, markers\n\n1 0 0 0 7.5 1\n2 2 0 0 7.5 1\n3 0 2 0 7.5 0\n4 0 0 2 7.5 1\n";
    let ele = b"1 4 1\n1 1 3 2 4 5 # reversed: re-oriented on import\n";
    let mesh = tetgen::parse(node, "t.node", ele, "t.ele", 1.0)
        .unwrap()
        .into_mesh()
        .unwrap();
    assert!((mesh.volume() - 8.0 / 6.0).abs() < 1e-15);
    let bad = b"1 4 1\n1 1 3 2 5 5\n";
    let (kind, at, _) = kind_and_location(tetgen::parse(node, "t.node", bad, "t.ele", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::IndexOutOfRange, FileLocation::Line(2))
    );
    let quadratic = b"1 10 0\n";
    let (kind, _, _) = kind_and_location(tetgen::parse(node, "t.node", quadratic, "t.ele", 1.0));
    assert_eq!(kind, ImportErrorKind::UnsupportedElement);
}

#[test]
fn tetgen_files_must_hold_what_their_headers_announce() {
    // The gmsh cube through meshio's TetGen writer (1140 tetrahedra): a header announcing 1139
    // would drop the last one; announcing 1141, the file ends where it is expected.
    let node = bytes("cube.node");
    let ele = String::from_utf8(bytes("cube.ele")).unwrap();
    let lines = ele.lines().count();
    let count = |n: usize| ele.replacen("\n1140 4 0\n", &format!("\n{n} 4 0\n"), 1);
    let parse = |ele: &str| {
        kind_and_location(tetgen::parse(
            &node,
            "cube.node",
            ele.as_bytes(),
            "cube.ele",
            1.0,
        ))
    };
    assert_eq!(parse(&count(1139)).0, ImportErrorKind::BadCount);
    assert_eq!(parse(&count(1139)).1, FileLocation::Line(lines));
    assert_eq!(parse(&count(1141)).0, ImportErrorKind::Truncated);
    // Cut inside the last number (its line break gone), the last tetrahedron would read another
    // node; the same for the last point of the `.node` file.
    let cut = &ele[..ele.trim_end().len() - 1];
    assert_eq!(parse(cut).0, ImportErrorKind::Truncated);
    let node_text = String::from_utf8(node.clone()).unwrap();
    let cut = &node_text[..node_text.trim_end().len() - 1];
    let (kind, at, _) = kind_and_location(tetgen::parse(
        cut.as_bytes(),
        "cube.node",
        ele.as_bytes(),
        "cube.ele",
        1.0,
    ));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::Truncated,
            FileLocation::Line(node_text.lines().count())
        )
    );
}

#[test]
fn a_triangle_among_vtu_tetrahedra_is_skipped_but_a_wedge_is_an_error() {
    let mixed = vtk::parse_vtu(&bytes("cube_mixed.vtu"), "mixed.vtu", 1.0).unwrap();
    assert_eq!(mixed.tets.len(), 1140);
    let text = String::from_utf8(bytes("cube_ascii.vtk")).unwrap();
    // Make cell 0 a wedge (type 13).
    let at = text.find("CELL_TYPES 1140\n").unwrap() + "CELL_TYPES 1140\n".len();
    let wedge = format!("{}13{}", &text[..at], &text[at + 2..]);
    let parsed = vtk::parse_legacy(wedge.as_bytes(), "w.vtk", 1.0);
    let (kind, _, message) = kind_and_location(parsed);
    assert_eq!(kind, ImportErrorKind::UnsupportedElement);
    assert!(message.contains("cell 0 has type 13"), "{message}");
}

#[test]
fn an_obj_surface_split_into_groups_stays_closed() {
    // A unit right tetrahedron's four faces in two groups: the reader welds the vertices each
    // group repeats, giving 4 vertices and 4 faces enclosing 1/6 m³ (exact in binary).
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                g bottom\nf 1 3 2\nf 1 2 4\n\
                g top\nf 1 4 3\nf 2 3 4\n";
    let surface = rapier_fvm::mesh::import::surface::parse_obj(obj, "tet.obj", 1.0).unwrap();
    assert_eq!(surface.vertices.len(), 4);
    assert_eq!(surface.triangles.len(), 4);
    assert!((surface.enclosed_volume() - 1.0 / 6.0).abs() < 1e-15);
}

/// A Gmsh 2.2 file of second-order tetrahedra (type 11, Gmsh's node order, in millimetres, one
/// element written clockwise) loads as the quadratic mesh it was written from: same nodes, same
/// elements in VTK order, the clockwise one re-oriented; `load` gives its subdivision.
#[test]
fn gmsh_quadratic_tetrahedra_load_as_quadratic_meshes() {
    use rapier_fvm::mesh::QuadraticTetMesh;
    let linear = rapier_fvm::mesh::cuboid(DVec3::new(0.2, 0.1, 0.1), [2, 1, 1]).unwrap();
    let written = QuadraticTetMesh::from_linear(&linear).unwrap();
    let mut text = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    text += &format!("{}\n", written.node_count());
    for (n, p) in written.positions().iter().enumerate() {
        let mm = *p * 1000.0;
        text += &format!("{} {} {} {}\n", n + 1, mm.x, mm.y, mm.z);
    }
    text += &format!("$EndNodes\n$Elements\n{}\n", written.element_count());
    for (e, element) in written.elements().iter().enumerate() {
        // VTK order to Gmsh's: the last two mid-edge nodes swap.
        let mut gmsh = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8].map(|k| element[k] + 1);
        if e == 0 {
            // Clockwise: corners 2 and 3 swapped, with their edges.
            gmsh = [0, 1, 3, 2, 4, 9, 7, 6, 8, 5].map(|k| gmsh[k]);
        }
        let nodes: Vec<String> = gmsh.iter().map(u32::to_string).collect();
        text += &format!("{} 11 2 1 1 {}\n", e + 1, nodes.join(" "));
    }
    text += "$EndElements\n";
    let raw = gmsh::parse(text.as_bytes(), "quadratic.msh", 0.001).unwrap();
    assert_eq!(raw.mid_edge_nodes.len(), written.element_count());
    let read = raw.clone().into_quadratic_mesh().unwrap();
    assert_eq!(read.node_count(), written.node_count());
    // Nodes are renumbered in order of first use; the elements' node positions are the written
    // ones, element 0 included (re-oriented back).
    for (r, w) in read.elements().iter().zip(written.elements()) {
        for (a, b) in r.iter().zip(w) {
            let (pa, pb) = (
                read.positions()[*a as usize],
                written.positions()[*b as usize],
            );
            assert!(pa.distance(pb) < 1e-15, "{pa} vs {pb}");
        }
    }
    let subdivided = raw.into_mesh().unwrap();
    assert_eq!(subdivided.tet_count(), 8 * written.element_count());
    assert!((subdivided.volume() - 0.4 * 0.2 * 0.2).abs() < 1e-15);
}

#[test]
fn quadratic_tetrahedra_from_a_vtu_keep_their_mid_edge_nodes() {
    // meshio's tetra10 `.vtu` of gmsh's second-order cube: 1140 quadratic tetrahedra on 2091
    // nodes. Their corners are the linear cube's (to meshio's 12 ASCII digits, so 1e-11), and
    // each mid-edge node is the middle of its edge in VTK's order (the cube's faces are flat:
    // gmsh puts them there). The quadratic mesh encloses the unit volume to rounding.
    const EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)];
    let raw = vtk::parse_vtu(&bytes("cube_tet10_ascii.vtu"), "cube.vtu", 1.0).unwrap();
    let linear = vtk::parse_vtu(&bytes("cube_binary.vtu"), "cube.vtu", 1.0).unwrap();
    assert_eq!(
        (
            raw.tets.len(),
            raw.positions.len(),
            raw.mid_edge_nodes.len()
        ),
        (1140, 2091, 1140)
    );
    let p = |i: u32| raw.positions[i as usize];
    for ((tet, mid), reference) in raw.tets.iter().zip(&raw.mid_edge_nodes).zip(&linear.tets) {
        for (&corner, &same) in tet.iter().zip(reference) {
            assert!(p(corner).distance(linear.positions[same as usize]) < 1e-11);
        }
        for (&node, (a, b)) in mid.iter().zip(EDGES) {
            assert!(p(node).distance((p(tet[a]) + p(tet[b])) / 2.0) < 1e-11);
        }
    }
    // `check_raw` counts the mid-edge nodes as used and measures the curved volume.
    let report = import::check_raw(&raw);
    assert_eq!((report.unused_nodes, report.folded), (0, 0));
    assert!((report.volume - 1.0).abs() < 1e-12, "{}", report.volume);
    // Element 7's first mid-edge node pushed past the far corner of its edge: the elements
    // around that edge fold, and the first is reported by its number and its place in the file
    // (the line of the connectivity).
    let mut folded = raw.clone();
    let node = folded.mid_edge_nodes[7][0];
    let [a, b] = [0, 1].map(|k| folded.positions[folded.tets[7][k] as usize]);
    folded.positions[node as usize] = a + (b - a) * 1.6;
    assert!(import::check_raw(&folded).folded >= 1);
    let Err(Error::MeshImport {
        kind,
        location,
        message,
        ..
    }) = folded.into_quadratic_mesh()
    else {
        panic!("a folded element was accepted");
    };
    let element: usize = message
        .strip_prefix("element ")
        .and_then(|m| m.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{message}"));
    assert_eq!(kind, ImportErrorKind::InvalidMesh);
    assert!(message.contains("folds"), "{message}");
    assert!(raw.mid_edge_nodes[element].contains(&node), "{message}");
    assert_eq!(location, raw.tet_locations[element]);
    let mesh = raw.into_quadratic_mesh().unwrap();
    assert_eq!((mesh.element_count(), mesh.node_count()), (1140, 2091));
    assert!((mesh.subdivided().volume() - 1.0).abs() < 1e-12);
}

#[test]
fn vtu_compressed_other_than_by_zlib_is_refused_naming_the_compressor() {
    // meshio's LZMA and the VTK library's LZ4 files: typed errors at the points' data (the
    // first array read), naming the compressor.
    for (name, compressor) in [
        ("cube_lzma.vtu", "vtkLZMADataCompressor"),
        ("cube_vtk_lz4.vtu", "vtkLZ4DataCompressor"),
    ] {
        let (kind, at, message) = kind_and_location(vtk::parse_vtu(&bytes(name), name, 1.0));
        assert_eq!(kind, ImportErrorKind::UnknownVersion, "{name}");
        assert_ne!(at, FileLocation::Whole, "{name}");
        assert!(message.contains(compressor), "{name}: {message}");
    }
}

#[test]
fn msh_4_0_is_read_in_ascii_and_refused_in_binary_with_the_reason() {
    // gmsh writes MSH 4.0 in ASCII only; a binary 4.0 header is refused at its line, saying
    // which version to save instead.
    let text = String::from_utf8(bytes("cube_v40_ascii.msh")).unwrap();
    let binary = text.replacen("\n4 0 8\n", "\n4 1 8\n", 1);
    let (kind, at, message) =
        kind_and_location(gmsh::parse(binary.as_bytes(), "cube_v40.msh", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::UnknownVersion, FileLocation::Line(2))
    );
    assert!(message.contains("4.1"), "{message}");
    // A 4.0 file whose node section announces one node more than its blocks hold.
    let short = text.replacen("$Nodes\n27 341\n", "$Nodes\n27 342\n", 1);
    assert_ne!(short, text);
    let (kind, _, _) = kind_and_location(gmsh::parse(short.as_bytes(), "short.msh", 1.0));
    assert_eq!(kind, ImportErrorKind::BadCount);
}

#[test]
fn a_legacy_vtk_file_cut_inside_its_last_number_is_refused() {
    // meshio's ASCII cube ends with cell types `10`: cut to `1`, the last tetrahedron would be
    // a vertex (skipped) and the mesh one tetrahedron short.
    let text = String::from_utf8(bytes("cube_ascii.vtk")).unwrap();
    assert!(text.ends_with("\n10\n"));
    let cut = &text[..text.len() - 2];
    let (kind, at, _) = kind_and_location(vtk::parse_legacy(cut.as_bytes(), "cut.vtk", 1.0));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::Truncated,
            FileLocation::Line(text.lines().count())
        )
    );
}

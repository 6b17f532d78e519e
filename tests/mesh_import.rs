//! Mesh import: each format read from real files (written by gmsh and meshio, see
//! `tools/make_test_meshes.py`) against closed-form values, the formats against each other,
//! typed errors for malformed files, and fuzzing of every reader.

use proptest::prelude::*;
use rapier_fvm::mesh::import::{self, RawMesh, SurfaceOptions, gmsh, surface, tetgen, vtk};
use rapier_fvm::prelude::*;
use rapier_fvm::{FileLocation, ImportErrorKind};
use std::path::PathBuf;

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

#[test]
fn the_cube_reads_the_same_from_every_format() {
    let mut all = CUBE_FILES.to_vec();
    all.push("cube_binary.vtk");
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
fn malformed_gmsh_files_name_the_line_and_the_defect() {
    let text = String::from_utf8(bytes("cube_v22_ascii.msh")).unwrap();
    let parse = |s: &str| gmsh::parse(s.as_bytes(), "bad.msh", 1.0);
    // Unknown version on line 2.
    let (kind, at, _) = kind_and_location(parse(&text.replacen("2.2 0 8", "3.0 0 8", 1)));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::UnknownVersion, FileLocation::Line(2))
    );
    // Truncated in the middle of the nodes.
    let cut = &text[..text.find("\n100 ").unwrap()];
    let (kind, _, _) = kind_and_location(parse(cut));
    assert_eq!(kind, ImportErrorKind::Truncated);
    // A non-finite coordinate on node 1's line (line 6).
    let (kind, at, _) = kind_and_location(parse(&text.replacen("\n1 0 0 1\n", "\n1 0 nan 1\n", 1)));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::NonFinite, FileLocation::Line(6))
    );
    // A tetrahedron referring to a node that does not exist.
    let line = text
        .lines()
        .position(|l| l.split(' ').nth(1) == Some("4"))
        .unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let mut words: Vec<&str> = lines[line].split(' ').collect();
    let last = words.len() - 1;
    words[last] = "99999";
    lines[line] = words.join(" ");
    let (kind, at, _) = kind_and_location(parse(&lines.join("\n")));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::IndexOutOfRange,
            FileLocation::Line(line + 1)
        )
    );
    // A quadratic tetrahedron (element type 11, 10 nodes) first, then linear ones: the first
    // linear one is named.
    let mut quadratic = lines.clone();
    let fields: Vec<&str> = text.lines().nth(line).unwrap().split(' ').collect();
    quadratic[line] = format!(
        "{} 11 {}",
        fields[0],
        fields[2..]
            .iter()
            .chain(&["1", "2", "3", "4", "5", "6"])
            .copied()
            .collect::<Vec<_>>()
            .join(" ")
    );
    let (kind, at, message) = kind_and_location(parse(&quadratic.join("\n")));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::UnsupportedElement,
            FileLocation::Line(line + 2)
        )
    );
    assert!(message.contains("mixed"), "{message}");
    // A hexahedron among the tetrahedra.
    let mut hex = lines.clone();
    hex[line] = format!("{} 5 2 1 1 1 2 3 4 5 6 7 8", fields[0]);
    let (kind, _, message) = kind_and_location(parse(&hex.join("\n")));
    assert_eq!(kind, ImportErrorKind::UnsupportedElement);
    assert!(message.contains("type 5"), "{message}");
    // A bad element count.
    let count = text.lines().position(|l| l == "$Elements").unwrap() + 1;
    let mut counted = lines.clone();
    counted[count] = "5".into();
    let (kind, _, _) = kind_and_location(parse(&counted.join("\n")));
    assert_eq!(kind, ImportErrorKind::BadCount);
    // No tetrahedra at all.
    let only_nodes = &text[..text.find("$Elements").unwrap()];
    let (kind, at, _) = kind_and_location(parse(only_nodes));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::NoTetrahedra, FileLocation::Whole)
    );
}

#[test]
fn malformed_binary_gmsh_files_name_the_byte() {
    let data = bytes("cube_v41_binary.msh");
    let cut = &data[..data.len() / 2];
    let (kind, at, _) = kind_and_location(gmsh::parse(cut, "cut.msh", 1.0));
    assert_eq!(kind, ImportErrorKind::Truncated);
    assert!(matches!(at, FileLocation::Byte(_)), "{at:?}");
}

/// The kind, location and message of an import error from a surface reader.
fn surface_error(
    result: Result<surface::Surface, Error>,
) -> (ImportErrorKind, FileLocation, String) {
    kind_and_location(result.map(|_| unreachable_mesh()))
}

/// Never called: gives `surface_error`'s `Ok` arm a `RawMesh` type.
fn unreachable_mesh() -> RawMesh {
    panic!("expected an import error, the surface was read")
}

/// Prints an import error as the user sees it (collected in the closing note of the change).
fn shown(result: &Result<impl std::fmt::Debug, Error>) {
    if let Err(e) = result {
        println!("  {e}");
    }
}

#[test]
fn malformed_obj_files_name_the_line() {
    // A tetrahedron: four vertices, four outward faces; a group splits the faces.
    let tet = [
        "# a tetrahedron",     // 1
        "v 0 0 0",             // 2
        "v 1 0 0",             // 3
        "v 0 1 0",             // 4
        "",                    // 5
        "v 0 0 1",             // 6
        "o bottom",            // 7
        "f 1 3 2",             // 8
        "g sides",             // 9
        "f 1 2 4",             // 10
        "f 2/1 3/1 4/1",       // 11 (texture indices are ignored without `vt`)
        "f -4//1 -1//1 -2//1", // 12 (relative indices, empty texture slot)
    ]
    .join("\n");
    let good = surface::parse_obj(tet.as_bytes(), "tet.obj", 1.0).unwrap();
    assert_eq!(good.triangles.len(), 4);
    let parse = |text: &str| {
        let result = surface::parse_obj(text.as_bytes(), "bad.obj", 1.0);
        shown(&result);
        surface_error(result)
    };
    // A coordinate that is not a number on line 4.
    let (kind, at, message) = parse(&tet.replace("v 0 1 0", "v 0 one 0"));
    assert_eq!((kind, at), (ImportErrorKind::Syntax, FileLocation::Line(4)));
    assert!(message.contains("position parse error"), "{message}");
    // A face referring to vertex 9 of 4 on line 10: `tobj` checks indices when the object
    // ends, the line is still that of the face.
    let (kind, at, _) = parse(&tet.replace("f 1 2 4", "f 1 2 9"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::IndexOutOfRange, FileLocation::Line(10))
    );
    // A relative index before the first vertex (-5 of 4) on line 12.
    let (kind, at, _) = parse(&tet.replace("f -4//1", "f -5//1"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::IndexOutOfRange, FileLocation::Line(12))
    );
    // Index 0 (OBJ counts from 1) in the first object, on line 8.
    let (kind, at, _) = parse(&tet.replace("f 1 3 2", "f 0 3 2"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::IndexOutOfRange, FileLocation::Line(8))
    );
    // A face vertex that is not an index, and an empty face.
    let (kind, at, _) = parse(&tet.replace("f 2/1 3/1", "f 2/1 3/x"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Syntax, FileLocation::Line(11))
    );
    let (_, at, _) = parse(&tet.replace("f 1 2 4", "f"));
    assert_eq!(at, FileLocation::Line(10));
    // Text that is not UTF-8 on line 3.
    let mut bytes = tet.clone().into_bytes();
    let at = tet.find("v 1 0 0").unwrap() + 2;
    bytes[at] = 0xff;
    let (kind, at, _) = surface_error(surface::parse_obj(&bytes, "bad.obj", 1.0));
    assert_eq!((kind, at), (ImportErrorKind::Syntax, FileLocation::Line(3)));
    // A coordinate that overflows once scaled, on line 6.
    let huge = tet.replace("v 0 0 1", "v 0 0 1e300");
    let result = surface::parse_obj(huge.as_bytes(), "huge.obj", 1e10);
    shown(&result);
    let (kind, at, _) = surface_error(result);
    assert_eq!(
        (kind, at),
        (ImportErrorKind::NonFinite, FileLocation::Line(6))
    );
}

#[test]
fn malformed_stl_files_name_the_line_or_the_byte() {
    let text = String::from_utf8(bytes("sphere_ascii.stl")).unwrap();
    let parse = |data: &[u8]| {
        let result = surface::parse_stl(data, "bad.stl", 1.0);
        shown(&result);
        surface_error(result)
    };
    // The second facet's first vertex (line 10) loses a coordinate.
    let lines: Vec<&str> = text.lines().collect();
    let mut broken: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    broken[9] = "      vertex -0.809016994 0.5".into();
    let (kind, at, _) = parse(broken.join("\n").as_bytes());
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Syntax, FileLocation::Line(10))
    );
    // `endloop` misspelt on line 7.
    let mut broken: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    broken[6] = "    end loop".into();
    let (_, at, _) = parse(broken.join("\n").as_bytes());
    assert_eq!(at, FileLocation::Line(7));
    // Cut inside the third facet (after line 20): the file ends where a statement is missing.
    let (kind, at, _) = parse(lines[..20].join("\n").as_bytes());
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Truncated, FileLocation::Line(20))
    );

    // Binary: 80-byte header, triangle count, 50-byte records.
    let binary = bytes("cube.stl");
    assert_eq!(binary.len(), 84 + 12 * 50);
    // Cut 20 bytes into record 5 (of 12): the record starts at byte 334.
    let (kind, at, _) = parse(&binary[..84 + 5 * 50 + 20]);
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Truncated, FileLocation::Byte(334))
    );
    // Cut inside the header and inside the count.
    assert_eq!(parse(&binary[..50]).1, FileLocation::Byte(0));
    assert_eq!(parse(&binary[..82]).1, FileLocation::Byte(80));
    // A NaN coordinate in record 3's second vertex (bytes 84 + 150 + 24 onwards).
    let mut nan = binary.clone();
    let vertex = 84 + 3 * 50 + 24;
    nan[vertex + 4..vertex + 8].copy_from_slice(&f32::NAN.to_le_bytes());
    let (kind, at, _) = parse(&nan);
    assert_eq!(
        (kind, at),
        (ImportErrorKind::NonFinite, FileLocation::Byte(vertex))
    );
}

#[test]
fn malformed_vtu_files_name_the_line() {
    let text = String::from_utf8(bytes("cube_ascii.vtu")).unwrap();
    let line_of = |needle: &str| text.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let parse = |s: &str| {
        let result = vtk::parse_vtu(s.as_bytes(), "bad.vtu", 1.0);
        shown(&result);
        kind_and_location(result)
    };
    // A mismatched end tag: `</Points>` on line 1033 closes `<Pointz>`.
    let points_end = line_of("</Points>");
    assert_eq!(points_end, 1033);
    let (kind, at, _) = parse(&text.replacen("</Points>", "</Pointz>", 1));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Syntax, FileLocation::Line(points_end))
    );
    // An attribute without its closing quote on the offsets' line.
    let offsets = line_of("<DataArray type=\"Int64\" Name=\"offsets\"");
    let (kind, at, _) = parse(&text.replacen("Name=\"offsets\"", "Name=\"offsets", 1));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Syntax, FileLocation::Line(offsets))
    );
    // The file cut inside the cells: it ends inside open elements.
    let cut = text.lines().take(2000).collect::<Vec<_>>().join("\n");
    let (kind, at, _) = parse(&cut);
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Syntax, FileLocation::Line(2000))
    );
    // A connectivity entry past the 341 points: the connectivity's `<DataArray>` line.
    let connectivity = line_of("<DataArray type=\"Int64\" Name=\"connectivity\"");
    let mut lines: Vec<&str> = text.lines().collect();
    lines[connectivity + 3] = "99999";
    let (kind, at, message) = parse(&lines.join("\n"));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::IndexOutOfRange,
            FileLocation::Line(connectivity)
        )
    );
    assert!(message.contains("99999"), "{message}");
    // An unknown cell type (a hexahedron) and a non-finite coordinate: their arrays' lines.
    let types = line_of("<DataArray type=\"Int64\" Name=\"types\"");
    let mut lines: Vec<&str> = text.lines().collect();
    lines[types] = "12";
    let (kind, at, _) = parse(&lines.join("\n"));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::UnsupportedElement,
            FileLocation::Line(types)
        )
    );
    let mut lines: Vec<&str> = text.lines().collect();
    lines[7] = "nan";
    let (kind, at, _) = parse(&lines.join("\n"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::NonFinite, FileLocation::Line(7))
    );
    // One cell type too few: `vtkio` names the array, its line is given.
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(types);
    let (kind, at, _) = parse(&lines.join("\n"));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::BadCount, FileLocation::Line(types))
    );
    // Tetrahedra carry their connectivity's line.
    let raw = vtk::parse_vtu(text.as_bytes(), "cube.vtu", 1.0).unwrap();
    assert_eq!(raw.tet_locations[0], FileLocation::Line(connectivity));
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
fn a_triangle_among_vtu_tetrahedra_is_skipped_but_a_hexahedron_is_an_error() {
    let mixed = vtk::parse_vtu(&bytes("cube_mixed.vtu"), "mixed.vtu", 1.0).unwrap();
    assert_eq!(mixed.tets.len(), 1140);
    let text = String::from_utf8(bytes("cube_ascii.vtk")).unwrap();
    // Make cell 0 a hexahedron (type 12).
    let at = text.find("CELL_TYPES 1140\n").unwrap() + "CELL_TYPES 1140\n".len();
    let hex = format!("{}12{}", &text[..at], &text[at + 2..]);
    let (kind, _, message) = kind_and_location(vtk::parse_legacy(hex.as_bytes(), "h.vtk", 1.0));
    assert_eq!(kind, ImportErrorKind::UnsupportedElement);
    assert!(message.contains("cell 0 has type 12"), "{message}");
}

#[test]
fn the_sphere_obj_fills_with_good_tetrahedra_close_to_its_volume() {
    let sphere = surface::parse_obj(&bytes("sphere.obj"), "sphere.obj", 1.0).unwrap();
    assert_eq!(sphere.vertices.len(), 642);
    assert_eq!(sphere.triangles.len(), 1280);
    let enclosed = sphere.enclosed_volume();
    // The icosphere is inscribed in the unit sphere: its faceting removes 0.86 % of 4π/3.
    let exact = 4.0 / 3.0 * std::f64::consts::PI;
    assert!((enclosed / exact - 1.0 + 0.0086).abs() < 1e-4, "{enclosed}");
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0).unwrap();
    for cells_across in [8, 16, 32] {
        let raw = surface::fill(&sphere, &SurfaceOptions { cells_across }).unwrap();
        let report = import::check(&raw.positions, &raw.tets, &rubber);
        let mesh = raw.into_mesh().unwrap();
        let error = mesh.volume() / enclosed - 1.0;
        println!(
            "sphere.obj, {cells_across} cells across: {} tets, {} nodes, volume error {:+.2} % \
             of the enclosed volume, dihedral {:.1}..{:.1} deg, radius ratio >= {:.3}, \
             stable step {:.3e} s",
            report.tets,
            report.nodes,
            100.0 * error,
            report.min_dihedral_angle,
            report.max_dihedral_angle,
            report.min_radius_ratio,
            report.stable_time_step.unwrap(),
        );
        assert_eq!(report.inverted + report.degenerate + report.invalid, 0);
        assert!(error.abs() < 0.05, "{cells_across}: {error}");
        assert!(
            report.min_dihedral_angle > 5.0,
            "{}",
            report.min_dihedral_angle
        );
        // The boundary nodes are moved onto the surface, some only part of the way when the
        // full move would flatten an element: none lies further out than half a cell.
        let h = 2.0 / cells_across as f64;
        let radius = mesh
            .positions()
            .iter()
            .map(|p| p.length())
            .fold(0.0, f64::max);
        println!("  farthest node from the centre: {radius:.4} (cell size {h:.4})");
        assert!(radius < 1.0 + 0.5 * h && radius > 0.99, "{radius}");
    }
}

#[test]
fn the_stl_cube_fills_to_its_volume() {
    let cube = surface::parse_stl(&bytes("cube.stl"), "cube.stl", 1.0).unwrap();
    assert_eq!((cube.vertices.len(), cube.triangles.len()), (8, 12));
    assert!((cube.enclosed_volume() - 1.0).abs() < 1e-12);
    let mesh = surface::fill(&cube, &SurfaceOptions { cells_across: 8 })
        .unwrap()
        .into_mesh()
        .unwrap();
    // The lattice's boundary nodes snap onto the flat faces; the cube's edges are rounded off
    // by less than one cell.
    let error = mesh.volume() - 1.0;
    println!(
        "cube.stl, 8 cells across: {} tets, volume error {:+.3} %",
        mesh.tet_count(),
        100.0 * error
    );
    assert!(error.abs() < 0.02, "{error}");
    let ascii = import::load(asset("sphere_ascii.stl"), 2.0, &SurfaceOptions::default()).unwrap();
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
    assert!(
        (ascii.volume() / exact - 1.0).abs() < 0.12,
        "{}",
        ascii.volume()
    );
}

#[test]
fn an_open_surface_is_rejected() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
    let open = surface::parse_obj(obj, "open.obj", 1.0).unwrap();
    let e = surface::fill(&open, &SurfaceOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            Error::MeshImport {
                kind: ImportErrorKind::InvalidSurface,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn check_counts_inverted_and_degenerate_elements() {
    let p = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::splat(5.0),
    ];
    let tets = [[0, 1, 2, 3], [0, 2, 1, 3], [0, 1, 4, 2], [0, 1, 2, 9]];
    let steel = Material::new(MaterialModel::Corotated, 200e9, 0.3, 7850.0).unwrap();
    let report = import::check(&p, &tets, &steel);
    assert_eq!(
        (
            report.tets,
            report.nodes,
            report.unused_nodes,
            report.inverted,
            report.degenerate,
            report.invalid
        ),
        (4, 6, 1, 1, 1, 1)
    );
    assert_eq!(report.min_dihedral_angle, 0.0);
    assert_eq!(report.critical_time_step, None);
    let good = import::check(&p, &tets[..1], &steel);
    assert!(
        (good.min_dihedral_angle - 54.7356).abs() < 1e-3,
        "{}",
        good.min_dihedral_angle
    );
    assert!((good.max_dihedral_angle - 90.0).abs() < 1e-9);
    // Corner tetrahedron: 3 r_in / r_circ = 3 (3 - sqrt 3) / (3 + sqrt 3) / (sqrt 3 / 2) ... as
    // computed in closed form: r_in = 1 / (3 + sqrt 3), r_circ = sqrt 3 / 2.
    let expected = 3.0 / (3.0 + 3f64.sqrt()) / (3f64.sqrt() / 2.0);
    assert!((good.min_radius_ratio - expected).abs() < 1e-12);
    let dt = good.critical_time_step.unwrap();
    assert!(dt > 0.0 && dt < 1e-3, "{dt}");
}

// Fuzzing: arbitrary bytes and mutations of the valid files, for every reader. Each must
// return Ok or a typed error, never panic (a panic fails the test). The number of executions
// is `cases` of each property below; the total is printed by `fuzz_execution_count`.

/// Cases per fuzz property.
const CASES: u32 = 10_000;

fn run_reader(reader: usize, data: &[u8]) {
    let result = match reader {
        0 => gmsh::parse(data, "fuzz.msh", 1.0),
        1 => tetgen::parse(data, "fuzz.node", &bytes_cached_ele(), "cube.ele", 1.0),
        2 => tetgen::parse(&bytes_cached_node(), "cube.node", data, "fuzz.ele", 1.0),
        3 => vtk::parse_vtu(data, "fuzz.vtu", 1.0),
        4 => vtk::parse_legacy(data, "fuzz.vtk", 1.0),
        5 => located(surface::parse_obj(data, "fuzz.obj", 1.0))
            .and_then(|s| surface::fill(&s, &SurfaceOptions { cells_across: 4 })),
        _ => located(surface::parse_stl(data, "fuzz.stl", 1.0))
            .and_then(|s| surface::fill(&s, &SurfaceOptions { cells_across: 4 })),
    };
    match result.and_then(RawMesh::into_mesh) {
        Ok(mesh) => assert!(mesh.tet_count() > 0),
        Err(Error::MeshImport { .. } | Error::InvalidSetting { .. }) => {}
        Err(other) => panic!("untyped import error {other:?}"),
    }
}

/// `result`, after checking that an error of the OBJ or STL reader says where: their
/// locators must find every statement `tobj` or `stl_io` rejects.
fn located(result: Result<surface::Surface, Error>) -> Result<surface::Surface, Error> {
    if let Err(e @ Error::MeshImport { location, .. }) = &result {
        assert_ne!(*location, FileLocation::Whole, "unplaced error: {e}");
    }
    result
}

fn bytes_cached_node() -> Vec<u8> {
    static NODE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    NODE.get_or_init(|| bytes("cube.node")).clone()
}

fn bytes_cached_ele() -> Vec<u8> {
    static ELE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    ELE.get_or_init(|| bytes("cube.ele")).clone()
}

/// (reader, valid file) pairs mutated by the fuzz properties.
const SEEDS: [(usize, &str); 13] = [
    (0, "cube_v22_ascii.msh"),
    (0, "cube_v22_binary.msh"),
    (0, "cube_v41_ascii.msh"),
    (0, "cube_v41_binary.msh"),
    (1, "cube.node"),
    (2, "cube.ele"),
    (3, "cube_ascii.vtu"),
    (3, "cube_binary.vtu"),
    (4, "cube_ascii.vtk"),
    (4, "cube_binary.vtk"),
    (5, "sphere.obj"),
    (6, "cube.stl"),
    (6, "sphere_ascii.stl"),
];

fn seed(index: usize) -> (usize, Vec<u8>) {
    static FILES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    let files = FILES.get_or_init(|| SEEDS.iter().map(|(_, name)| bytes(name)).collect());
    (SEEDS[index].0, files[index].clone())
}

/// A mutation of a valid file: truncation, byte overwrites, or a number replaced by an extreme
/// one.
#[derive(Debug, Clone)]
enum Mutation {
    Truncate(prop::sample::Index),
    Bytes(Vec<(prop::sample::Index, u8)>),
    Number(prop::sample::Index, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<prop::sample::Index>().prop_map(Mutation::Truncate),
        prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4)
            .prop_map(Mutation::Bytes),
        (
            any::<prop::sample::Index>(),
            prop::sample::select(vec![
                "0",
                "-1",
                "1",
                "2",
                "4000000000",
                "18446744073709551615",
                "99999999999999999999",
                "nan",
                "inf",
                "-1e308",
                "1e308",
                "11",
                "5",
                "10",
                "24",
                "3",
            ])
        )
            .prop_map(|(i, n)| Mutation::Number(i, n)),
    ]
}

fn mutate(data: &[u8], mutation: &Mutation) -> Vec<u8> {
    match mutation {
        Mutation::Truncate(at) => data[..at.index(data.len() + 1)].to_vec(),
        Mutation::Bytes(changes) => {
            let mut data = data.to_vec();
            for (at, byte) in changes {
                let i = at.index(data.len());
                data[i] = *byte;
            }
            data
        }
        Mutation::Number(at, number) => {
            // Replace the run of digits at or after a position by `number`.
            let start = at.index(data.len());
            let Some(first) = data[start..].iter().position(u8::is_ascii_digit) else {
                return data.to_vec();
            };
            let first = start + first;
            let end = first
                + data[first..]
                    .iter()
                    .position(|b| !b.is_ascii_digit())
                    .unwrap_or(data.len() - first);
            [&data[..first], number.as_bytes(), &data[end..]].concat()
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn fuzz_arbitrary_bytes(reader in 0usize..7, data in prop::collection::vec(any::<u8>(), 0..512)) {
        run_reader(reader, &data);
    }

    #[test]
    fn fuzz_arbitrary_text(reader in 0usize..7, data in "[ -~\n]{0,300}") {
        run_reader(reader, data.as_bytes());
    }

    #[test]
    fn fuzz_mutated_files(file in 0usize..SEEDS.len(), mutation in mutation()) {
        let (reader, data) = seed(file);
        run_reader(reader, &mutate(&data, &mutation));
    }

    #[test]
    fn fuzz_mutated_headers(file in 0usize..SEEDS.len(), mutation in mutation()) {
        // The same mutations within the first 400 bytes, where the counts and versions are.
        let (reader, data) = seed(file);
        let head = data.len().min(400);
        let mut mutated = mutate(&data[..head], &mutation);
        mutated.extend_from_slice(&data[head..]);
        run_reader(reader, &mutated);
    }
}

/// Truncation at every length of the Gmsh and VTK cube files' first 4 kB and of the `TetGen`
/// files: every prefix must give a typed error (or, for a prefix that is a whole file, a mesh).
#[test]
fn fuzz_every_truncation_of_the_headers() {
    let mut executions = 0;
    for index in 0..SEEDS.len() {
        let (reader, data) = seed(index);
        for len in 0..data.len().min(4096) {
            run_reader(reader, &data[..len]);
            executions += 1;
        }
    }
    println!("truncations executed: {executions}");
}

#[test]
fn fuzz_execution_count() {
    // 4 properties of CASES cases each, plus the truncations (printed by their test).
    println!("proptest fuzz executions: {}", 4 * CASES);
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

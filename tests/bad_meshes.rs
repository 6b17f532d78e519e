//! Meshes `f64` cannot compute with are refused when they are built or read, naming
//! the node or the tetrahedron (and, from a file, the file, the line and the kind), and the
//! generators refuse cell counts their indices cannot address instead of overflowing.

use rapier_fvm::mesh::import::{RawMesh, gmsh, surface, tetgen, vtk};
use rapier_fvm::mesh::{MAX_COORDINATE, QuadraticHexMesh, QuadraticTetMesh};
use rapier_fvm::prelude::*;
use rapier_fvm::{FileLocation, ImportErrorKind};

fn unit_tet() -> Vec<DVec3> {
    vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
}

fn asset(name: &str) -> String {
    let path = format!("{}/assets/meshes/{name}", env!("CARGO_MANIFEST_DIR"));
    String::from_utf8(std::fs::read(path).unwrap()).unwrap()
}

/// The kind and place of a [`Error::MeshImport`], and its message.
fn import_error<T: std::fmt::Debug>(
    result: Result<T, Error>,
) -> (ImportErrorKind, FileLocation, String) {
    match result {
        Err(e @ Error::MeshImport { kind, location, .. }) => (kind, location, e.to_string()),
        other => panic!("expected an import error, got {other:?}"),
    }
}

#[test]
fn a_node_at_minus_9e307_is_refused_naming_it_where_its_volume_was_nan() {
    // (b - a).x overflows to infinity, times the zero y of (c - a): the volume was NaN, which no
    // comparison refused, and every frame of a body built on it failed.
    let positions = vec![
        DVec3::new(-9e307, 0.0, 0.0),
        DVec3::new(9e307, 0.0, 0.0),
        DVec3::Y,
        DVec3::Z,
    ];
    let error = TetMesh::new(positions, vec![[0, 1, 2, 3]]).unwrap_err();
    assert_eq!(
        error,
        Error::CoordinateOutOfRange {
            node: 0,
            position: [-9e307, 0.0, 0.0]
        }
    );
    assert!(error.to_string().starts_with("node 0 at"), "{error}");
}

#[test]
fn coordinates_up_to_the_bound_are_accepted_and_beyond_it_refused() {
    // A tetrahedron spanning the whole range: its volume (1e300 / 6 m³) is finite.
    let corner = |scale: f64| unit_tet().into_iter().map(|p| p * scale).collect();
    let mesh = TetMesh::new(corner(MAX_COORDINATE), vec![[0, 1, 2, 3]]).unwrap();
    let expected = MAX_COORDINATE.powi(3) / 6.0;
    assert!((mesh.volume() - expected).abs() <= 1e-12 * expected);
    let error = TetMesh::new(corner(1.5 * MAX_COORDINATE), vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(
        matches!(error, Error::CoordinateOutOfRange { node: 1, .. }),
        "{error}"
    );
}

#[test]
fn a_tetrahedron_too_small_for_f64_is_refused_naming_it() {
    // Two separate tetrahedra, the second of 1e-100 m: its volume would be a denormal number.
    let mut positions = unit_tet();
    positions.extend(
        unit_tet()
            .iter()
            .map(|p| *p * 1e-100 + DVec3::splat(2.0e-99)),
    );
    let tets = vec![[0, 1, 2, 3], [4, 5, 6, 7]];
    let error = TetMesh::new(positions.clone(), tets.clone()).unwrap_err();
    match error {
        Error::TetTooSmall { tet, longest_edge } => {
            assert_eq!(tet, 1);
            assert!((longest_edge - 2f64.sqrt() * 1e-100).abs() < 1e-110);
        }
        other => panic!("expected TetTooSmall, got {other:?}"),
    }
    assert!(
        error.to_string().starts_with("tetrahedron 1 is too small"),
        "{error}"
    );
    // 1e-90 m is small, but its volume is a normal number.
    let small: Vec<DVec3> = unit_tet().iter().map(|p| *p * 1e-90).collect();
    let mesh = TetMesh::new(small, vec![[0, 1, 2, 3]]).unwrap();
    assert!(mesh.volume().is_normal());
}

#[test]
fn quadratic_meshes_refuse_a_far_node_naming_it() {
    let linear = mesh::cuboid(DVec3::splat(0.5), [1, 1, 1]).unwrap();
    let quadratic = QuadraticTetMesh::from_linear(&linear).unwrap();
    let mut positions = quadratic.positions().to_vec();
    positions[12].y = -9e307;
    let error = QuadraticTetMesh::new(positions, quadratic.elements().to_vec()).unwrap_err();
    assert!(
        matches!(error, Error::CoordinateOutOfRange { node: 12, .. }),
        "{error}"
    );
}

#[test]
fn a_body_placed_beyond_the_bound_is_refused_naming_the_node() {
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let cube = mesh::cuboid(DVec3::splat(0.05), [1, 1, 1]).unwrap();
    let error = DeformableBodyBuilder::new(cube.clone(), material)
        .translation(DVec3::new(0.0, 2.0 * MAX_COORDINATE, 0.0))
        .build()
        .unwrap_err();
    assert!(
        matches!(error, Error::CoordinateOutOfRange { node: 0, .. }),
        "{error}"
    );
    let error = DeformableBodyBuilder::new(cube, material)
        .linvel(DVec3::new(1e9, 0.0, 0.0))
        .build()
        .unwrap_err();
    assert!(
        matches!(error, Error::InvalidSetting { parameter: "linvel", value, .. } if value == 1e9),
        "{error}"
    );
}

#[test]
fn generators_refuse_cell_counts_past_their_indices_without_overflowing() {
    let refused = |result: Result<TetMesh, Error>| {
        assert!(
            matches!(result, Err(Error::InvalidGeneratorParameter { .. })),
            "{result:?}"
        );
    };
    let half = DVec3::splat(0.5);
    // (2001)^3 = 8.0e9 nodes: more than u32 indices address.
    refused(mesh::cuboid(half, [2000, 2000, 2000]));
    refused(mesh::cuboid(half, [usize::MAX, usize::MAX, usize::MAX]));
    refused(mesh::cylinder(0.5, 0.5, usize::MAX, usize::MAX));
    refused(mesh::cylinder(0.5, 0.5, usize::MAX, 1));
    refused(mesh::sphere(0.5, usize::MAX));
    refused(QuadraticTetMesh::sphere(0.5, usize::MAX).map(|m| m.subdivided().clone()));
    // Twice the cells of a cage would overflow a usize.
    refused(
        QuadraticHexMesh::cuboid(half, [usize::MAX / 2 + 1, 1, 1]).map(|m| m.subdivided().clone()),
    );
}

#[test]
fn a_far_node_in_a_gmsh_file_is_refused_at_its_line() {
    let text = asset("cube_v22_ascii.msh");
    let far = text.replacen("\n1 0 0 1\n", "\n1 -9e307 0 1\n", 1);
    let (kind, at, message) = import_error(gmsh::parse(far.as_bytes(), "far.msh", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(6))
    );
    assert!(message.starts_with("far.msh: line 6: "), "{message}");
    // In range in the file, beyond it once scaled from kilometres... of 1e98 km.
    let scaled = text.replacen("\n1 0 0 1\n", "\n1 0 0 1e98\n", 1);
    let (kind, at, _) = import_error(gmsh::parse(scaled.as_bytes(), "far.msh", 1e3));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(6))
    );
}

#[test]
fn a_far_node_in_a_tetgen_file_is_refused_at_its_line() {
    let node = asset("cube.node");
    let ele = asset("cube.ele");
    let far = node.replacen("\n1 0.0000000000000000e+00", "\n1 -9e307", 1);
    let (kind, at, message) = import_error(tetgen::parse(
        far.as_bytes(),
        "cube.node",
        ele.as_bytes(),
        "cube.ele",
        1.0,
    ));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(4))
    );
    assert!(message.starts_with("cube.node: line 4: "), "{message}");
}

#[test]
fn a_far_point_in_a_vtk_file_is_refused_at_its_array() {
    let legacy = asset("cube_ascii.vtk");
    let far = legacy.replacen("\n0.0 0.0 1.0 ", "\n-9e307 0.0 1.0 ", 1);
    let (kind, at, _) = import_error(vtk::parse_legacy(far.as_bytes(), "far.vtk", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(6))
    );
    let xml = asset("cube_ascii.vtu");
    let points = xml
        .lines()
        .position(|l| l.contains("Name=\"Points\""))
        .unwrap();
    let mut lines: Vec<String> = xml.lines().map(str::to_owned).collect();
    lines[points + 1] = "-9e307".to_owned();
    let (kind, at, _) = import_error(vtk::parse_vtu(lines.join("\n").as_bytes(), "far.vtu", 1.0));
    assert_eq!(
        (kind, at),
        (
            ImportErrorKind::CoordinateOutOfRange,
            FileLocation::Line(points + 1)
        )
    );
}

#[test]
fn a_far_vertex_in_a_surface_file_is_refused_at_its_line() {
    let obj = asset("sphere.obj");
    let far = obj.replacen("\nv 0.52573111211913359 ", "\nv 9e307 ", 1);
    let (kind, at, _) = import_error(surface::parse_obj(far.as_bytes(), "far.obj", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(3))
    );
    let stl = "solid far\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e30 0 0\n\
               vertex 0 1 0\nendloop\nendfacet\nendsolid far\n";
    let (kind, at, _) = import_error(surface::parse_stl(stl.as_bytes(), "far.stl", 1e80));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(5))
    );
}

#[test]
fn a_raw_mesh_with_a_far_node_is_refused_at_the_first_tetrahedron_using_it() {
    let mut positions = unit_tet();
    positions.push(DVec3::new(0.0, 0.0, 1e200));
    let raw = RawMesh {
        path: "hand.node".into(),
        positions,
        tets: vec![[0, 1, 2, 3], [0, 1, 2, 4]],
        mid_edge_nodes: Vec::new(),
        tet_locations: vec![FileLocation::Line(7), FileLocation::Line(8)],
        regions: Vec::new(),
        hexahedra: Default::default(),
    };
    let (kind, at, message) = import_error(raw.into_mesh());
    assert_eq!(
        (kind, at),
        (ImportErrorKind::CoordinateOutOfRange, FileLocation::Line(8))
    );
    assert!(
        message.contains("tetrahedron 1 uses node 4 at"),
        "{message}"
    );
}

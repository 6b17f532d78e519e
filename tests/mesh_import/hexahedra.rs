//! Hexahedra from files: gmsh's transfinite box [0, 1] x [0, 0.5] x [0, 0.25] of 4 x 3 x 2
//! hexahedra (`tools/make_test_meshes.py hexahedra`), linear and 27-node, in MSH and through
//! meshio and the VTK library, against the box's closed-form numbers; the 27-node file as a
//! cage against the generator's cage of the same cells.

use super::*;
use rapier_fvm::mesh::import::{Hexahedra, MeshRegion, RegionId};
use rapier_fvm::statics::{self, StaticSettings};

const LINEAR_FILES: [&str; 3] = [
    "box_hex8_v41.msh",
    "box_hex8_v22_binary.msh",
    "box_hex8_meshio.vtu",
];
const TRIQUADRATIC_FILES: [&str; 3] = [
    "box_hex27_v41.msh",
    "box_hex27_meshio.vtu",
    "box_hex27_vtk9.vtk",
];
const HALF: DVec3 = DVec3::new(0.5, 0.25, 0.125);
const CELLS: [usize; 3] = [4, 3, 2];

fn load(name: &str) -> RawMesh {
    import::load_raw(asset(name), 1.0, &SurfaceOptions::default()).unwrap()
}

/// The boundary quadrilaterals of the box: two on each face per cell face.
fn boundary_quads() -> usize {
    let [x, y, z] = CELLS;
    2 * (x * y + y * z + x * z)
}

/// Conformity of the split: a face two hexahedra cut differently would leave its four
/// triangles on the boundary; exactly the box's own faces' triangles (of area 1.75 m², within
/// `tolerance`) remain.
fn assert_box_boundary(mesh: &TetMesh, triangles_per_quad: usize, name: &str, tolerance: f64) {
    let triangles = mesh.surface_triangles();
    assert_eq!(
        triangles.len(),
        triangles_per_quad * boundary_quads(),
        "{name}"
    );
    let p = mesh.positions();
    let area: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|n| p[n as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    assert!((area - 1.75).abs() < tolerance, "{name}: area {area}");
}

#[test]
fn linear_hexahedra_split_into_conforming_tetrahedra() {
    for name in LINEAR_FILES {
        let raw = load(name);
        let Hexahedra::Linear(corners) = &raw.hexahedra else {
            panic!("{name}: {:?}", raw.hexahedra);
        };
        assert_eq!(corners.len(), 24, "{name}");
        assert_eq!(raw.tets.len(), 6 * 24, "{name}");
        let report = import::check_raw(&raw);
        assert_eq!((report.hexahedra, report.inverted), (24, 0), "{name}");
        let mesh = raw.into_mesh().unwrap();
        assert_eq!(mesh.node_count(), 5 * 4 * 3, "{name}");
        assert!((mesh.volume() - 0.125).abs() < 1e-14, "{name}");
        assert_box_boundary(&mesh, 2, name, 1e-12);
    }
}

#[test]
fn linear_hexahedra_make_a_cage_with_nodes_at_their_middles() {
    // Each edge, face and cell of the 4 x 3 x 2 box gains its middle node: the 9 x 7 x 5
    // lattice; the clamp x = 0 (the corners' 4 x 3) widens to the face's 7 x 5 lattice nodes.
    for name in LINEAR_FILES {
        let raw = load(name);
        let clamp = raw
            .regions_in_mesh()
            .into_iter()
            .find(|r| r.tag == 2)
            .unwrap();
        assert_eq!(clamp.nodes.len(), 4 * 3, "{name}");
        let cage = raw.into_cage().unwrap();
        assert_eq!(
            (cage.element_count(), cage.node_count()),
            (24, 9 * 7 * 5),
            "{name}"
        );
        assert!((cage.subdivided().volume() - 0.125).abs() < 1e-14, "{name}");
        assert_box_boundary(cage.subdivided(), 8, name, 1e-12);
        let widened = clamp.with_cage_nodes(&cage);
        assert_eq!(widened.nodes.len(), 7 * 5, "{name}");
        let p = cage.positions();
        assert!(widened.nodes.iter().all(|&n| p[n as usize].x.abs() < 1e-15));
    }
    // A file of tetrahedra makes no cage.
    let error = load("cube_v41_ascii.msh").into_cage().unwrap_err();
    let shown = error.to_string();
    assert!(
        shown.contains("a cage needs a file of hexahedra"),
        "{shown}"
    );
}

#[test]
fn the_volume_region_holds_every_tetrahedron_of_its_hexahedra() {
    for name in ["box_hex8_v41.msh", "box_hex27_v41.msh"] {
        let raw = load(name);
        let block = MeshRegion::find(&raw.regions, &RegionId::Name("block".into()), name)
            .unwrap()
            .clone();
        assert_eq!(block.tets.len(), raw.tets.len(), "{name}");
        let clamp = MeshRegion::find(&raw.regions, &RegionId::Name("clamp".into()), name)
            .unwrap()
            .clone();
        let lattice = if name.contains("27") { 2 } else { 1 };
        let clamp_nodes = (lattice * 3 + 1) * (lattice * 2 + 1);
        assert_eq!(clamp.nodes.len(), clamp_nodes, "{name}");
        let kept = raw.keep_volume(&RegionId::Tag(1)).unwrap();
        assert_eq!(kept.tets.len(), 24 * if lattice == 2 { 48 } else { 6 });
    }
}

#[test]
fn triquadratic_hexahedra_read_in_every_format_sit_on_their_lattice() {
    for name in TRIQUADRATIC_FILES {
        let raw = load(name);
        let Hexahedra::Triquadratic(elements) = &raw.hexahedra else {
            panic!("{name}: {:?}", raw.hexahedra);
        };
        assert_eq!(elements.len(), 24, "{name}");
        // The VTK library writes ASCII coordinates to 11 significant digits.
        let tolerance = if name.ends_with(".vtk") { 1e-10 } else { 1e-12 };
        // A straight-sided box: node (i, j, k) of an element lies at the trilinear
        // interpolation of its corners, which checks each format's node order.
        for element in elements {
            let p = element.map(|n| raw.positions[n as usize]);
            let corner = |i: usize, j: usize, k: usize| p[i + 3 * j + 9 * k];
            for (a, position) in p.iter().enumerate() {
                let [s, t, u] = [a % 3, a / 3 % 3, a / 9].map(|c| c as f64 / 2.0);
                let mut expected = DVec3::ZERO;
                for (i, j, k) in (0..8).map(|c| (2 * (c & 1), (c & 2), (c >> 2) * 2)) {
                    let w = |x: f64, end: usize| if end == 0 { 1.0 - x } else { x };
                    expected += corner(i, j, k) * w(s, i) * w(t, j) * w(u, k);
                }
                assert!(position.distance(expected) < tolerance, "{name}: node {a}");
            }
        }
        let report = import::check_raw(&raw);
        assert_eq!(
            (report.hexahedra, report.folded, report.unused_nodes),
            (24, 0, 0),
            "{name}"
        );
        assert!((report.volume - 0.125).abs() < tolerance, "{name}");
        let cage = raw.into_cage().unwrap();
        assert_eq!(cage.element_count(), 24);
        assert_eq!(cage.node_count(), 9 * 7 * 5);
        assert!((cage.subdivided().volume() - 0.125).abs() < tolerance);
        assert_box_boundary(cage.subdivided(), 8, name, tolerance);
    }
}

/// The box clamped at x = 0 sagging under gravity (linear law, E = 1e6 Pa, ν = 0.3, density
/// 1000 kg/m³), as a cage read from the 27-node file and as the generator's cage of the same cells:
/// the same elements, so the same mean deflection of the end x = 1 up to the static solver's
/// tolerance (1e-6 relative); the subdivisions differ (file 48 tetrahedra per element, the
/// generator's 40).
#[test]
fn a_cage_read_from_a_file_bends_as_the_generated_one() {
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    let sag = |cage: mesh::QuadraticHexMesh| {
        let clamped = cage.nodes_where(|p| p.x < 1e-9);
        let end = cage.nodes_where(|p| p.x > 1.0 - 1e-9);
        let mut body = DeformableBodyBuilder::quadratic_hex(cage, material)
            .pinned_nodes(clamped)
            .build()
            .unwrap();
        let rest: f64 = end.iter().map(|&n| body.positions()[n as usize].z).sum();
        let gravity = DVec3::new(0.0, 0.0, -9.81);
        statics::solve_equilibrium(&mut body, gravity, &StaticSettings::default()).unwrap();
        let now: f64 = end.iter().map(|&n| body.positions()[n as usize].z).sum();
        (rest - now) / end.len() as f64
    };
    let read = sag(load("box_hex27_v41.msh").into_cage().unwrap());
    let generated = mesh::QuadraticHexMesh::cuboid(HALF, CELLS)
        .unwrap()
        .map_positions(|p| p + HALF)
        .unwrap();
    let generated = sag(generated);
    println!(
        "end sag: file {:.6} mm, generator {:.6} mm",
        read * 1e3,
        generated * 1e3
    );
    assert!(read > 0.0);
    assert!((read / generated - 1.0).abs() < 1e-6);
}

#[test]
fn other_volume_elements_are_refused_at_their_line() {
    let text = String::from_utf8(bytes("box_hex8_v41.msh")).unwrap();
    // The first hexahedron of the volume block turned into a prism (type 6, six nodes).
    let lines: Vec<&str> = text.lines().collect();
    // The block header `3 <entity> 5 <count>`: volume elements of type 5.
    let block = lines
        .iter()
        .position(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            f.len() == 4 && f[0] == "3" && f[2] == "5"
        })
        .unwrap();
    let first = lines[block + 1];
    let fields: Vec<&str> = first.split(' ').collect();
    let mut prism = lines.clone();
    let header = lines[block].replacen(" 5 ", " 6 ", 1);
    prism[block] = &header;
    let nodes = fields[..7].join(" ");
    prism[block + 1] = &nodes;
    let error = gmsh::parse(prism.join("\n").as_bytes(), "prism.msh", 1.0).unwrap_err();
    let Error::MeshImport {
        kind,
        location,
        message,
        ..
    } = error
    else {
        panic!("{error}");
    };
    assert_eq!(kind, ImportErrorKind::UnsupportedElement);
    assert_eq!(location, FileLocation::Line(block + 2));
    assert!(message.contains("type 6"), "{message}");
}

#[test]
fn a_folded_27_node_hexahedron_is_counted_and_refused_at_its_line() {
    // The centre node of the file's sixth hexahedron pushed past its face x = max: the element's
    // map folds (check counts it) and its subdivision inverts (the cage names its line).
    let mut raw = load("box_hex27_v41.msh");
    let Hexahedra::Triquadratic(elements) = &raw.hexahedra else {
        panic!("{:?}", raw.hexahedra);
    };
    let element = 5;
    let (centre, face) = (
        elements[element][13] as usize,
        elements[element][14] as usize,
    );
    raw.positions[centre].x = raw.positions[face].x + 0.2;
    let report = import::check_raw(&raw);
    assert_eq!(report.folded, 1);
    // The same element numbered left-handed (lattice i to 2 − i): still one folded.
    let mut mirrored = raw.clone();
    if let Hexahedra::Triquadratic(elements) = &mut mirrored.hexahedra {
        let e = elements[element];
        elements[element] = rapier_fvm::shape::hex27::mirrored(&e);
    }
    assert_eq!(import::check_raw(&mirrored).folded, 1);
    let line = raw.tet_locations[48 * element];
    assert!(matches!(line, FileLocation::Line(_)));
    match raw.into_cage().unwrap_err() {
        Error::MeshImport { kind, location, .. } => {
            assert_eq!((kind, location), (ImportErrorKind::InvalidMesh, line));
        }
        other => panic!("{other}"),
    }
}

//! Regions (Gmsh physical groups, VTU/VTK cell tags, `TetGen` region attributes and boundary
//! markers): read from the file, found by name or tag, numbered as the
//! validated mesh's nodes, one volume kept as a mesh of its own, and widened to a quadratic
//! body's mid-edge nodes.

use super::bytes;
use rapier_fvm::mesh::QuadraticTetMesh;
use rapier_fvm::mesh::import::{MeshRegion, RawMesh, RegionId, gmsh, tetgen, vtk};
use rapier_fvm::{Error, FileLocation};

#[test]
fn gmsh_physical_groups_are_kept_as_named_regions() {
    // gmsh's cube with its face x = 0 as surface group "clamp" (1) and its volume as "body"
    // (2), in MSH 2.2 ASCII (groups from element tags) and 4.1 binary (from `$Entities`): the
    // clamp's nodes are exactly the nodes at x = 0, the body's tetrahedra all 1140.
    for name in ["cube_regions_v22.msh", "cube_regions_v41_binary.msh"] {
        let raw = gmsh::parse(&bytes(name), name, 1.0).unwrap();
        assert_eq!(raw.tets.len(), 1140, "{name}");
        let names: Vec<(&str, u8, i64)> = raw
            .regions
            .iter()
            .map(|r| (r.name.as_str(), r.dimension, r.tag))
            .collect();
        assert_eq!(names, [("clamp", 2, 1), ("body", 3, 2)], "{name}");
        let on_face: Vec<u32> = (0..raw.positions.len() as u32)
            .filter(|&n| raw.positions[n as usize].x == 0.0)
            .collect();
        assert!(!on_face.is_empty());
        assert_eq!(raw.regions[0].nodes, on_face, "{name}");
        assert!(raw.regions[0].tets.is_empty());
        assert_eq!(
            raw.regions[1].tets,
            (0..1140).collect::<Vec<u32>>(),
            "{name}"
        );
    }
}

#[test]
fn a_region_selects_the_validated_mesh_s_nodes() {
    // The clamp's nodes mapped into the mesh `into_mesh` builds lie where the file puts them,
    // for the linear cube and for the quadratic one (tetra10 corners and mid-edge nodes).
    let raw = gmsh::parse(&bytes("cube_regions_v22.msh"), "cube.msh", 1.0).unwrap();
    let index = raw.mesh_node_indices();
    let mesh = raw.clone().into_mesh().unwrap();
    for &node in &raw.regions[0].nodes {
        let in_mesh = index[node as usize].unwrap();
        assert_eq!(
            mesh.positions()[in_mesh as usize],
            raw.positions[node as usize]
        );
    }
    let quadratic = vtk::parse_vtu(&bytes("cube_tet10_ascii.vtu"), "q.vtu", 1.0).unwrap();
    let index = quadratic.mesh_node_indices();
    let mesh = quadratic.clone().into_quadratic_mesh().unwrap();
    assert_eq!(index.iter().flatten().count(), mesh.node_count());
    for (node, in_mesh) in index.iter().enumerate() {
        let in_mesh = in_mesh.unwrap();
        assert_eq!(
            mesh.positions()[in_mesh as usize],
            quadratic.positions[node]
        );
    }
}

/// The file of two unit boxes side by side: volumes "left" (tag 1, x in [0, 1]) and "right"
/// (tag 2, x in [1, 2]), surfaces "clamp" (tag 3, x = 0) and "load" (tag 4, x = 2).
fn two_volumes() -> rapier_fvm::mesh::import::RawMesh {
    gmsh::parse(&bytes("two_volumes_v41.msh"), "two_volumes_v41.msh", 1.0).unwrap()
}

fn name(text: &str) -> RegionId {
    RegionId::Name(text.to_owned())
}

#[test]
fn each_volume_of_a_file_is_a_mesh_of_its_own() {
    // Each box alone: its volume 1 m^3 to rounding, its nodes on its side of x = 1, and the two
    // together all the file's tetrahedra.
    let raw = two_volumes();
    let total = raw.tets.len();
    let mut counted = 0;
    for (id, side) in [(name("left"), 0.0), (RegionId::Tag(2), 1.0)] {
        let part = raw.clone().keep_volume(&id).unwrap();
        counted += part.tets.len();
        assert_eq!(part.tet_locations.len(), part.tets.len());
        let mesh = part.into_mesh().unwrap();
        assert!(
            (mesh.volume() - 1.0).abs() < 1e-12,
            "{id}: {}",
            mesh.volume()
        );
        for p in mesh.positions() {
            assert!(
                p.x >= side - 1e-12 && p.x <= side + 1.0 + 1e-12,
                "{id}: {p}"
            );
        }
    }
    assert_eq!(counted, total);
}

#[test]
fn a_kept_volume_keeps_the_regions_that_touch_it() {
    // The left box keeps the clamp (its face x = 0, exactly its nodes there), loses the load
    // (on the right box), and its own tetrahedra are renumbered to all of the kept ones.
    let left = two_volumes().keep_volume(&name("left")).unwrap();
    let regions = left.regions_in_mesh();
    let clamp = MeshRegion::find(&regions, &name("clamp"), &left.path).unwrap();
    let load = MeshRegion::find(&regions, &RegionId::Tag(4), &left.path).unwrap();
    let own = MeshRegion::find(&regions, &name("left"), &left.path).unwrap();
    let other = MeshRegion::find(&regions, &name("right"), &left.path).unwrap();
    let tets = left.tets.len() as u32;
    let mesh = left.into_mesh().unwrap();
    let at_zero = mesh.nodes_where(|p| p.x == 0.0);
    assert!(!at_zero.is_empty());
    assert_eq!(clamp.nodes, at_zero);
    assert!(load.nodes.is_empty() && other.tets.is_empty());
    // The right box's nodes in the left one are those of the face they share.
    assert_eq!(other.nodes, mesh.nodes_where(|p| p.x == 1.0));
    assert_eq!(own.tets, (0..tets).collect::<Vec<u32>>());
    assert_eq!(own.nodes.len(), mesh.node_count());
}

#[test]
fn an_unknown_ambiguous_or_flat_region_is_refused_with_the_file_s_regions() {
    let raw = two_volumes();
    let message = |e: Error| {
        assert!(matches!(e, Error::MeshRegion { .. }), "{e:?}");
        e.to_string()
    };
    let unknown = message(MeshRegion::find(&raw.regions, &name("lid"), &raw.path).unwrap_err());
    assert_eq!(
        unknown,
        "two_volumes_v41.msh: region \"lid\": the file's regions are \"clamp\" (surface, tag \
         3), \"load\" (surface, tag 4), \"left\" (volume, tag 1), \"right\" (volume, tag 2)"
    );
    let flat = message(raw.clone().keep_volume(&RegionId::Tag(3)).unwrap_err());
    assert_eq!(
        flat,
        "two_volumes_v41.msh: region tag 3: \"clamp\" (surface, tag 3) is not a volume of \
         tetrahedra"
    );
    // cube_regions numbers its surface and its volume 1 and 2; a second group tagged 1 makes
    // the tag ambiguous.
    let mut cube = gmsh::parse(&bytes("cube_regions_v22.msh"), "cube.msh", 1.0).unwrap();
    cube.regions[1].tag = 1;
    let ambiguous =
        message(MeshRegion::find(&cube.regions, &RegionId::Tag(1), "cube.msh").unwrap_err());
    assert!(
        ambiguous.contains("more than one group answers to it"),
        "{ambiguous}"
    );
    let none = message(MeshRegion::find(&[], &name("clamp"), "cube.vtu").unwrap_err());
    assert!(
        none.ends_with("the file names no regions (Gmsh physical groups)"),
        "{none}"
    );
}

#[test]
fn a_first_order_face_widened_to_a_quadratic_body_is_its_whole_face() {
    // The clamp of the linear cube, on the quadratic mesh built from it: exactly the quadratic
    // mesh's nodes at x = 0 (corners and mid-edge nodes), no interior mid-edge node.
    let raw = gmsh::parse(&bytes("cube_regions_v22.msh"), "cube.msh", 1.0).unwrap();
    let clamp = raw.regions_in_mesh()[0].clone();
    let quadratic = QuadraticTetMesh::from_linear(&raw.into_mesh().unwrap()).unwrap();
    let widened = clamp.with_mid_edge_nodes(&quadratic);
    let at_zero: Vec<u32> = (0..quadratic.positions().len() as u32)
        .filter(|&n| quadratic.positions()[n as usize].x == 0.0)
        .collect();
    assert!(widened.nodes.len() > clamp.nodes.len());
    assert_eq!(widened.nodes, at_zero);
    // The body as a volume region takes every node.
    let body = gmsh::parse(&bytes("cube_regions_v22.msh"), "cube.msh", 1.0).unwrap();
    let whole = body.regions_in_mesh()[1].with_mid_edge_nodes(&quadratic);
    assert_eq!(whole.nodes.len(), quadratic.positions().len());
}

/// The positions of a region's nodes and of its tetrahedra's corners in `raw`, each sorted, so
/// that two files numbering the same mesh differently compare equal.
fn region_geometry(raw: &RawMesh, region: &MeshRegion) -> (Vec<[u64; 3]>, Vec<[[u64; 3]; 4]>) {
    let at = |n: u32| raw.positions[n as usize].to_array().map(f64::to_bits);
    let mut nodes: Vec<[u64; 3]> = region.nodes.iter().map(|&n| at(n)).collect();
    nodes.sort_unstable();
    let mut tets: Vec<[[u64; 3]; 4]> = (region.tets.iter())
        .map(|&t| {
            let mut corners = raw.tets[t as usize].map(at);
            corners.sort_unstable();
            corners
        })
        .collect();
    tets.sort_unstable();
    (nodes, tets)
}

#[test]
fn a_vtu_file_s_cell_tags_are_the_gmsh_file_s_regions() {
    // meshio's VTU of two_volumes_v41.msh keeps each cell's physical tag as "gmsh:physical":
    // the same four regions by dimension and tag, unnamed, with the same nodes and tetrahedra
    // (compared by position, to the bit), found by tag.
    let msh = two_volumes();
    let name = "two_volumes_meshio.vtu";
    let vtu = vtk::parse_vtu(&bytes(name), name, 1.0).unwrap();
    assert_eq!(vtu.regions.len(), msh.regions.len());
    for region in &msh.regions {
        let found = MeshRegion::find(&vtu.regions, &RegionId::Tag(region.tag), name).unwrap();
        assert_eq!(
            (found.dimension, found.name.as_str()),
            (region.dimension, "")
        );
        assert_eq!(
            region_geometry(&vtu, found),
            region_geometry(&msh, region),
            "{region}"
        );
    }
    let left = vtu.keep_volume(&RegionId::Tag(1)).unwrap();
    assert!((left.into_mesh().unwrap().volume() - 1.0).abs() < 1e-12);
}

#[test]
fn a_vtu_cell_tag_array_that_does_not_fit_its_cells_is_refused() {
    // The tag array cut to fewer values than the piece's cells, and a tag array of floats that
    // are not whole: errors at the array's line, never a region silently short.
    let text = std::fs::read_to_string(super::asset("cube_ascii.vtu")).unwrap();
    let cells: usize = text
        .split("NumberOfCells=\"")
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    let with_tags = |array: &str| {
        text.replacen(
            "</Cells>",
            &format!("</Cells>\n<CellData>\n{array}\n</CellData>"),
            1,
        )
    };
    let short = with_tags(&format!(
        "<DataArray type=\"Int32\" Name=\"gmsh:physical\" format=\"ascii\">{}</DataArray>",
        vec!["1"; cells - 1].join(" ")
    ));
    let error = vtk::parse_vtu(short.as_bytes(), "short.vtu", 1.0)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("gmsh:physical") && error.contains(&format!("for {cells} cells")),
        "{error}"
    );
    let floats = with_tags(&format!(
        "<DataArray type=\"Float64\" Name=\"CellEntityIds\" format=\"ascii\">{}</DataArray>",
        vec!["1.5"; cells].join(" ")
    ));
    let error = vtk::parse_vtu(floats.as_bytes(), "floats.vtu", 1.0)
        .unwrap_err()
        .to_string();
    assert!(error.contains("hold 1.5, not a tag"), "{error}");
    // Whole numbers stored as floats (as vmtk may write them) are tags.
    let whole_floats = with_tags(&format!(
        "<DataArray type=\"Float32\" Name=\"CellEntityIds\" format=\"ascii\">{}</DataArray>",
        vec!["2"; cells].join(" ")
    ));
    let raw = vtk::parse_vtu(whole_floats.as_bytes(), "whole_floats.vtu", 1.0).unwrap();
    assert_eq!((raw.regions.len(), raw.regions[0].tag), (1, 2));
    let whole = with_tags(&format!(
        "<DataArray type=\"Int32\" Name=\"gmsh:physical\" format=\"ascii\">{}</DataArray>",
        vec!["7"; cells].join(" ")
    ));
    let raw = vtk::parse_vtu(whole.as_bytes(), "whole.vtu", 1.0).unwrap();
    assert_eq!(raw.regions.len(), 1);
    assert_eq!(raw.regions[0].tets.len(), raw.tets.len());
}

#[test]
fn a_legacy_vtk_file_s_cell_tags_are_the_gmsh_file_s_regions() {
    // meshio's legacy VTK (5.1, binary) of two_volumes_v41.msh, whose tags are a FIELD array of
    // its CELL_DATA after a POINT_DATA field; and the VTK library's ASCII legacy file of the
    // 27-node box, with the same tags as its Gmsh file. Same regions, compared by position.
    for (msh, legacy) in [
        ("two_volumes_v41.msh", "two_volumes_meshio.vtk"),
        ("box_hex27_v41.msh", "box_hex27_vtk9.vtk"),
    ] {
        let msh = gmsh::parse(&bytes(msh), msh, 1.0).unwrap();
        let vtk = vtk::parse_legacy(&bytes(legacy), legacy, 1.0).unwrap();
        assert_eq!(vtk.regions.len(), msh.regions.len(), "{legacy}");
        for region in &msh.regions {
            let found = MeshRegion::find(&vtk.regions, &RegionId::Tag(region.tag), legacy)
                .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(found.dimension, region.dimension, "{legacy}: {region}");
            assert_eq!(found.nodes.len(), region.nodes.len(), "{legacy}: {region}");
            assert_eq!(found.tets.len(), region.tets.len(), "{legacy}: {region}");
            if legacy.starts_with("two") {
                // Written to the bit (binary doubles); the VTK library's ASCII rounds.
                assert_eq!(
                    region_geometry(&vtk, found),
                    region_geometry(&msh, region),
                    "{region}"
                );
            }
        }
    }
}

#[test]
fn legacy_cell_data_that_does_not_fit_its_grid_is_refused_at_its_line() {
    let text = std::fs::read_to_string(super::asset("box_hex27_vtk9.vtk")).unwrap();
    let line_of = |text: &str, start: &str| text.lines().position(|l| l.starts_with(start));
    let cell_data = line_of(&text, "CELL_DATA").unwrap();
    let parse = |text: &str| vtk::parse_legacy(text.as_bytes(), "box.vtk", 1.0);
    let error_at = |text: &str| match parse(text).unwrap_err() {
        Error::MeshImport {
            location, message, ..
        } => (location, message),
        other => panic!("{other}"),
    };
    // A section size other than the grid's cells.
    let wrong_size = text.replacen("CELL_DATA 30", "CELL_DATA 29", 1);
    let (at, message) = error_at(&wrong_size);
    assert_eq!(at, FileLocation::Line(cell_data + 1), "{message}");
    assert!(message.contains("30 cells"), "{message}");
    // A tag that is not a whole number (the array retyped as floats).
    let floats = text.replacen(
        "gmsh:physical 1 30 vtktypeint64\n2",
        "gmsh:physical 1 30 double\n2.5",
        1,
    );
    let (_, message) = error_at(&floats);
    assert!(message.contains("2.5 is not a whole number"), "{message}");
    // An attribute the format does not define.
    let unknown = text.replacen("FIELD FieldData 3", "COLOURS FieldData 3", 1);
    let (at, message) = error_at(&unknown);
    assert_eq!(at, FileLocation::Line(cell_data + 2), "{message}");
    assert!(message.contains("unknown attribute `COLOURS`"), "{message}");
    // A tag array of another size than the cells, or of two components: refused, never regions
    // read short.
    for shape in ["gmsh:physical 1 31", "gmsh:physical 2 15"] {
        let wrong = text.replacen("gmsh:physical 1 30", shape, 1);
        let (_, message) = error_at(&wrong);
        assert!(
            message.contains("the cell tag array `gmsh:physical`"),
            "{message}"
        );
    }
}

#[test]
fn legacy_cell_tags_as_scalars_are_the_same_regions_as_in_a_field() {
    // The VTK library's file with its tag array turned from a FIELD array into the cell data's
    // SCALARS (as a writer that marks the tags as the active scalars puts them).
    let text = std::fs::read_to_string(super::asset("box_hex27_vtk9.vtk")).unwrap();
    let scalars = text
        .replacen(
            "FIELD FieldData 3\ngmsh:physical 1 30 vtktypeint64\n",
            "SCALARS gmsh:physical vtktypeint64 1\nLOOKUP_TABLE default\n",
            1,
        )
        .replacen(
            "\ngmsh:geometrical 1 30",
            "\nFIELD FieldData 2\ngmsh:geometrical 1 30",
            1,
        );
    assert_ne!(scalars, text);
    let from_field = vtk::parse_legacy(text.as_bytes(), "field.vtk", 1.0).unwrap();
    let from_scalars = vtk::parse_legacy(scalars.as_bytes(), "scalars.vtk", 1.0).unwrap();
    assert_eq!(from_scalars.regions.len(), 2);
    assert_eq!(from_scalars.regions, from_field.regions);
}

#[test]
fn a_tetgen_file_s_attributes_and_markers_are_the_gmsh_file_s_regions() {
    // meshio's TetGen files of two_volumes_v41.msh: each tetrahedron's physical tag is its first
    // attribute (its geometrical tag the second), and the physical surfaces' points carry their
    // tags as boundary markers: the volumes "region 1" and "region 2" and the surfaces "marker 3"
    // and "marker 4", with the Gmsh groups' nodes and tetrahedra (compared by position, to the
    // bit: meshio writes 17 significant digits).
    let msh = two_volumes();
    let (node, ele) = ("two_volumes_meshio.node", "two_volumes_meshio.ele");
    let tetgen = tetgen::parse(&bytes(node), node, &bytes(ele), ele, 1.0).unwrap();
    assert_eq!(tetgen.regions.len(), msh.regions.len());
    for region in &msh.regions {
        let kind = if region.dimension == 3 {
            "region"
        } else {
            "marker"
        };
        let id = RegionId::Name(format!("{kind} {}", region.tag));
        let found = MeshRegion::find(&tetgen.regions, &id, ele).unwrap();
        assert_eq!((found.dimension, found.tag), (region.dimension, region.tag));
        assert_eq!(
            region_geometry(&tetgen, found),
            region_geometry(&msh, region),
            "{region}"
        );
    }
    let left = tetgen.keep_volume(&name("region 1")).unwrap();
    assert!((left.into_mesh().unwrap().volume() - 1.0).abs() < 1e-12);
}

#[test]
fn a_tetgen_region_attribute_that_is_not_a_whole_number_is_refused_at_its_line() {
    let node = b"4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    let ele = b"1 4 1\n0 0 1 2 3 1.5\n";
    let error = tetgen::parse(node, "tet.node", ele, "tet.ele", 1.0).unwrap_err();
    let message = error.to_string();
    assert!(
        message.starts_with("tet.ele: line 2: ") && message.contains("not a whole number"),
        "{message}"
    );
}

//! Malformed files: each reader names the defect's kind and its line (or byte offset in binary
//! data), and the OBJ, STL and VTU readers place the errors their crates report.

use super::{bytes, kind_and_location};
use rapier_fvm::mesh::import::{RawMesh, gmsh, surface, vtk};
use rapier_fvm::prelude::*;
use rapier_fvm::{FileLocation, ImportErrorKind};

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
    .join("\n")
        + "\n";
    let good = surface::parse_obj(tet.as_bytes(), "tet.obj", 1.0).unwrap();
    assert_eq!(good.triangles.len(), 4);
    let parse = |text: &str| {
        let result = surface::parse_obj(text.as_bytes(), "bad.obj", 1.0);
        shown(&result);
        surface_error(result)
    };
    // Cut inside its last number (`-2` read as `-`, or a vertex `1.5` as `1.`): without its
    // final line break the last statement may be cut short, refused at its line; a last comment
    // without one is harmless.
    let (kind, at, _) = parse(tet.trim_end());
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Truncated, FileLocation::Line(12))
    );
    assert!(surface::parse_obj(format!("{tet}# end").as_bytes(), "c.obj", 1.0).is_ok());
    // A coordinate that is not a number on line 4.
    let (kind, at, message) = parse(&tet.replace("v 0 1 0", "v 0 one 0"));
    assert_eq!((kind, at), (ImportErrorKind::Syntax, FileLocation::Line(4)));
    assert!(message.contains("position parse error"), "{message}");
    // Faces at fault, each named at its line (the statement replaced, its replacement, the
    // error's kind and line).
    for (face, bad, expected, line) in [
        // Vertex 9 of 4 on line 10: `tobj` checks indices when the object ends, the line is
        // still that of the face.
        ("f 1 2 4", "f 1 2 9", ImportErrorKind::IndexOutOfRange, 10),
        // A relative index before the first vertex (-5 of 4) on line 12.
        ("f -4//1", "f -5//1", ImportErrorKind::IndexOutOfRange, 12),
        // Index 0 (OBJ counts from 1) in the first object, on line 8.
        ("f 1 3 2", "f 0 3 2", ImportErrorKind::IndexOutOfRange, 8),
        // A face vertex that is not an index.
        ("f 2/1 3/1", "f 2/1 3/x", ImportErrorKind::Syntax, 11),
    ] {
        let (kind, at, _) = parse(&tet.replace(face, bad));
        assert_eq!((kind, at), (expected, FileLocation::Line(line)), "{bad}");
    }
    // An empty face.
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
        (ImportErrorKind::Truncated, FileLocation::Line(2000))
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
    // An unsupported cell type (a wedge) and a non-finite coordinate: their arrays' lines.
    let types = line_of("<DataArray type=\"Int64\" Name=\"types\"");
    let mut lines: Vec<&str> = text.lines().collect();
    lines[types] = "13";
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
    // One cell type too few: the types array's line.
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

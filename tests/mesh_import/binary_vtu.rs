//! Binary `.vtu` data that lies about its size: every count is checked before it is trusted, so
//! a file cut short, an offset past the data or a compressed block that inflates beyond what its
//! piece can hold gives a typed error at the array's place, with nothing allocated for the lie.

use super::{bytes, kind_and_location};
use rapier_fvm::mesh::import::vtk;
use rapier_fvm::{FileLocation, ImportErrorKind};
use std::io::Write;

/// A one-piece grid of four points and no cells whose points are the raw appended zlib `block`
/// of one compressed block declared `declared` bytes long (`UInt32` header).
fn zlib_points(block: &[u8], declared: u32) -> Vec<u8> {
    let mut header = Vec::new();
    for n in [1, declared, declared, block.len() as u32] {
        header.extend_from_slice(&n.to_le_bytes());
    }
    let mut file =
        b"<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" \
        header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n\
        <Piece NumberOfPoints=\"4\" NumberOfCells=\"0\">\n<Points>\n\
        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n\
        </Points>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_"
            .to_vec();
    file.extend_from_slice(&header);
    file.extend_from_slice(block);
    file.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    file
}

/// `n` zero bytes compressed by zlib.
fn zeros(n: usize) -> Vec<u8> {
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(&vec![0; n]).unwrap();
    encoder.finish().unwrap()
}

#[test]
fn a_decompression_bomb_is_refused_before_it_inflates() {
    // 256 MiB of zeros in about 250 kB. Declared as such, the block holds 32 Mi values where
    // the piece's 4 points take 12: refused from the header, at the data's byte offset.
    let bomb = zeros(256 << 20);
    let file = zlib_points(&bomb, 256 << 20);
    let (kind, at, message) = kind_and_location(vtk::parse_vtu(&file, "bomb.vtu", 1.0));
    assert_eq!(kind, ImportErrorKind::BadCount, "{message}");
    assert!(matches!(at, FileLocation::Byte(_)), "{at:?}");
    assert!(message.contains("more than the 12"), "{message}");
    // Declared as the 96 bytes the points take, the same block stops inflating one byte past
    // them.
    let file = zlib_points(&bomb, 96);
    let (kind, _, message) = kind_and_location(vtk::parse_vtu(&file, "bomb.vtu", 1.0));
    assert_eq!(kind, ImportErrorKind::BadCount, "{message}");
    assert!(message.contains("inflates to 97 bytes"), "{message}");
    // An honest block of the 96 bytes passes every check of the points: the file is refused
    // only for holding no tetrahedra (it declares no cells).
    let raw_points = zlib_points(&zeros(96), 96);
    let error = vtk::parse_vtu(&raw_points, "zeros.vtu", 1.0).unwrap_err();
    let (kind, _, _) = kind_and_location(Err(error));
    assert_eq!(kind, ImportErrorKind::NoTetrahedra);
}

#[test]
fn binary_data_cut_short_or_out_of_place_is_an_error_at_its_array() {
    // The VTK library's appended raw zlib cube: its points' offset moved past the appended data,
    // then the file cut inside that data.
    let text = bytes("cube_vtk_appended_raw_zlib.vtu");
    let head_end = text.windows(9).position(|w| w == b"</Points>").unwrap();
    let head = String::from_utf8_lossy(&text[..head_end]).into_owned();
    let points_line = 1 + head[..head.find("Name=\"Points\"").unwrap()]
        .matches('\n')
        .count();
    let moved = {
        let at = head.rfind("offset=\"0\"").unwrap();
        [&text[..at], b"offset=\"99999999\"", &text[at + 10..]].concat()
    };
    let (kind, at, _) = kind_and_location(vtk::parse_vtu(&moved, "moved.vtu", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Truncated, FileLocation::Line(points_line))
    );
    let appended = text
        .windows(14)
        .position(|w| w == b"<AppendedData ")
        .unwrap();
    for cut in [appended + 40, appended + 200, text.len() - 200] {
        let (kind, _, message) = kind_and_location(vtk::parse_vtu(&text[..cut], "cut.vtu", 1.0));
        assert!(
            matches!(kind, ImportErrorKind::Truncated | ImportErrorKind::Syntax),
            "{cut}: {kind:?} {message}"
        );
    }
    // meshio's inline base64 cube with its points' data line removed: no values where 1023 are
    // declared.
    let text = String::from_utf8(bytes("cube_binary.vtu")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let points = lines
        .iter()
        .position(|l| l.contains("Name=\"Points\""))
        .unwrap();
    lines.remove(points + 1);
    let (kind, at, _) =
        kind_and_location(vtk::parse_vtu(lines.join("\n").as_bytes(), "b.vtu", 1.0));
    assert_eq!(
        (kind, at),
        (ImportErrorKind::Truncated, FileLocation::Line(points + 1))
    );
}

/// A grid of `pieces`, each `(points, cells, [types, offsets, connectivity])` as ASCII text,
/// the points those of the unit right tetrahedron (shifted by 2 m in x per piece).
fn ascii_grid(pieces: &[(u64, u64, [&str; 3])]) -> String {
    let mut file = String::from(
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
         <UnstructuredGrid>\n",
    );
    for (number, (points, cells, [types, offsets, connectivity])) in pieces.iter().enumerate() {
        let x = 2.0 * number as f64;
        let corners: String = (0..*points)
            .map(|k| match k % 4 {
                0 => format!("{x} 0 0 "),
                1 => format!("{} 0 0 ", x + 1.0),
                2 => format!("{x} 1 0 "),
                _ => format!("{x} 0 1 "),
            })
            .collect();
        file += &format!(
            "<Piece NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\">\n<Points>\n\
             <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">{corners}</DataArray>\n\
             </Points>\n<Cells>\n\
             <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">{connectivity}</DataArray>\n\
             <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">{offsets}</DataArray>\n\
             <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">{types}</DataArray>\n\
             </Cells>\n</Piece>\n"
        );
    }
    file + "</UnstructuredGrid>\n</VTKFile>\n"
}

#[test]
fn pieces_join_and_every_count_holds_exactly_its_data() {
    // Two pieces of one tetrahedron each, the second's offsets with a leading zero: two
    // tetrahedra of 1/6 m³, the second's points after the first's.
    let good = ascii_grid(&[
        (4, 1, ["10", "4", "0 1 2 3"]),
        (4, 1, ["10", "0 4", "0 1 2 3"]),
    ]);
    let raw = vtk::parse_vtu(good.as_bytes(), "two.vtu", 1.0).unwrap();
    assert_eq!(raw.tets, vec![[0, 1, 2, 3], [4, 5, 6, 7]]);
    assert!((raw.into_mesh().unwrap().volume() - 2.0 / 6.0).abs() < 1e-15);
    // Counts that would overflow or hide data: a cell count of 2^64 - 1, an end past the
    // connectivity in a second piece, a piece declaring no cells (or points) while holding
    // some. Each a count error, none a panic or a dropped cell.
    let huge = u64::MAX;
    for (name, file) in [
        ("huge count", ascii_grid(&[(0, huge, ["10", "4", ""])])),
        (
            "end past the connectivity",
            ascii_grid(&[
                (4, 1, ["10", "4", "0 1 2 3"]),
                (4, 2, ["10 10", &format!("{huge} 4"), "0 1 2 3"]),
            ]),
        ),
        (
            "cells beyond a count of 0",
            ascii_grid(&[
                (4, 1, ["10", "4", "0 1 2 3"]),
                (4, 0, ["10", "4", "0 1 2 3"]),
            ]),
        ),
        (
            "points beyond a count of 0",
            ascii_grid(&[(0, 0, ["", "", ""])]).replacen(
                "format=\"ascii\"></DataArray>",
                "format=\"ascii\">0 0 0</DataArray>",
                1,
            ),
        ),
    ] {
        let (kind, at, message) = kind_and_location(vtk::parse_vtu(file.as_bytes(), name, 1.0));
        assert_eq!(kind, ImportErrorKind::BadCount, "{name}: {message}");
        assert!(matches!(at, FileLocation::Line(_)), "{name}: {at:?}");
    }
}

#[test]
fn a_big_endian_file_reads_as_its_little_endian_original() {
    // The VTK library's uncompressed appended raw cube with every header and value byte-swapped
    // and `byte_order="BigEndian"`: the same points (to the bit) and tetrahedra.
    let text = bytes("cube_vtk_appended_raw.vtu");
    let little = vtk::parse_vtu(&text, "little.vtu", 1.0).unwrap();
    let start = text
        .windows(14)
        .position(|w| w == b"<AppendedData ")
        .unwrap();
    let data = start + text[start..].iter().position(|&b| b == b'_').unwrap() + 1;
    let mut big = text.clone();
    // (offset, value size) of the points, connectivity, offsets and types, in file order.
    for (offset, size) in [(0, 8), (8188, 8), (44672, 8), (53796, 1)] {
        let at = data + offset;
        let count = u32::from_le_bytes(text[at..at + 4].try_into().unwrap()) as usize;
        big[at..at + 4].reverse();
        for value in big[at + 4..at + 4 + count].chunks_exact_mut(size) {
            value.reverse();
        }
    }
    let head = String::from_utf8_lossy(&big[..start]).replacen("LittleEndian", "BigEndian", 1);
    let big = [head.as_bytes(), &big[start..]].concat();
    let raw = vtk::parse_vtu(&big, "big.vtu", 1.0).unwrap();
    assert_eq!(raw.positions, little.positions);
    assert_eq!(raw.tets, little.tets);
}

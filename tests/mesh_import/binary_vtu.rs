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
    // An honest block of the 96 bytes reads: four points at the origin.
    let raw_points = zlib_points(&zeros(96), 96);
    let error = vtk::parse_vtu(&raw_points, "zeros.vtu", 1.0).unwrap_err();
    // (No cells: no tetrahedra, the points read.)
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

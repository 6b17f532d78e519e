//! Placing the errors of the crates that read OBJ and STL files, which say what is wrong
//! but not where: small scanners, run only once a reader has failed, that find the line (or the
//! byte offset, in binary STL) of the first statement the crate rejects. They follow the
//! crates' own rules (documented with each function) without building a mesh, allocate no more
//! than a small multiple of their input and accept any bytes.

use crate::error::FileLocation;

/// The lines of `data` as [`std::io::BufRead::lines`] splits them (at `\n`, a trailing `\r`
/// dropped), numbered from 1; `None` for a line that is not UTF-8.
fn lines(data: &[u8]) -> impl Iterator<Item = (usize, Option<&str>)> {
    let body = data.strip_suffix(b"\n").unwrap_or(data);
    let lines = (!data.is_empty()).then(|| body.split(|&b| b == b'\n'));
    lines.into_iter().flatten().enumerate().map(|(i, line)| {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        (i + 1, std::str::from_utf8(line).ok())
    })
}

/// Number of the last line of `data` (at least 1): where a file that ends too early stops.
fn last_line(data: &[u8]) -> usize {
    lines(data).last().map_or(1, |(number, _)| number)
}

// ---------------------------------------------------------------------------------------------
// Wavefront OBJ, as `tobj` 4.0 reads it.

/// `tobj`'s marker for an index a face vertex does not give.
const MISSING: usize = usize::MAX;

/// Statements read so far: the sizes face indices are checked against.
#[derive(Default)]
struct ObjCounts {
    positions: usize,
    /// Colour components (`v x y z r g b`), not triples: `tobj` keeps the valid ones of a line.
    colours: usize,
    texcoords: usize,
    normals: usize,
}

/// A face of the current object: its line and its largest indices as `tobj` resolves them
/// (0-based, [`MISSING`] when absent or unusable).
struct PendingFace {
    line: usize,
    vertex: usize,
    texcoord: Option<usize>,
    normal: Option<usize>,
}

impl PendingFace {
    /// Whether `tobj` rejects the face once its object ends with `counts` statements read.
    fn out_of_range(&self, counts: &ObjCounts) -> bool {
        self.vertex >= counts.positions
            || (counts.colours > 0
                && self.vertex.saturating_mul(3).saturating_add(2) >= counts.colours)
            || (counts.texcoords > 0 && self.texcoord.is_some_and(|t| t >= counts.texcoords))
            || (counts.normals > 0 && self.normal.is_some_and(|n| n >= counts.normals))
    }
}

/// The first of `faces` that `tobj` rejects when their object ends.
fn first_out_of_range(faces: &[PendingFace], counts: &ObjCounts) -> Option<usize> {
    faces
        .iter()
        .find(|face| face.out_of_range(counts))
        .map(|face| face.line)
}

/// Whether all of the first `n` of `words` parse as numbers, and there are `n`.
fn floats<'a>(words: &mut impl Iterator<Item = &'a str>, n: usize) -> bool {
    words.take(n).filter(|w| w.parse::<f64>().is_ok()).count() == n
}

/// A face vertex `v`, `v/t`, `v//n` or `v/t/n` as `tobj` resolves it against `counts`: 0-based
/// `[v, t, n]`, negative indices relative to the statements read so far; `None` if `tobj`
/// rejects it.
fn face_vertex(word: &str, counts: &ObjCounts) -> Option<[usize; 3]> {
    let mut indices = [MISSING; 3];
    let sizes = [counts.positions, counts.texcoords, counts.normals];
    for (slot, part) in word.split('/').enumerate() {
        if part.is_empty() {
            continue;
        }
        let x: isize = part.parse().ok()?;
        let size = *sizes.get(slot)?;
        indices[slot] = if x < 0 {
            size.wrapping_add_signed(x)
        } else {
            x.unsigned_abs().wrapping_sub(1)
        };
    }
    Some(indices)
}

/// The line of the first statement of the OBJ text `data` that `tobj` 4.0 rejects, or `None`.
///
/// `tobj` rejects a line that is not UTF-8; a `v` without three numbers, with a zero or invalid
/// fourth one (`w`), or with two or more than three extra values (colours); a `vt` without two
/// numbers, a `vn` without three; a `usemtl` without a name; an `f` or `l` vertex that is not
/// `v`, `v/t`, `v//n` or `v/t/n` integers. Face indices (1-based, negative ones relative to the
/// statements before) are checked when the object ends (at `o` or `g` after faces, or at the
/// end of the file), against everything read by then: the first face out of range is the
/// culprit, an empty face (`f` alone) included. Other statements are ignored.
pub(super) fn obj_error_line(data: &[u8]) -> Option<usize> {
    let mut counts = ObjCounts::default();
    let mut faces: Vec<PendingFace> = Vec::new();
    for (number, line) in lines(data) {
        let Some(line) = line else {
            // `tobj` reads lines as UTF-8 text.
            return Some(number);
        };
        let mut words = line.split_whitespace();
        let ok = match words.next() {
            None | Some("#") => true,
            Some("v") => {
                let ok = floats(&mut words, 3);
                counts.positions += usize::from(ok);
                ok && match (words.next(), words.next(), words.next(), words.next()) {
                    (None, ..) => true,
                    (Some(w), None, ..) => w.parse::<f64>().is_ok_and(|w| w != 0.0),
                    (Some(r), Some(g), Some(b), None) => {
                        counts.colours += [r, g, b]
                            .iter()
                            .take_while(|c| c.parse::<f64>().is_ok())
                            .count();
                        true
                    }
                    _ => false,
                }
            }
            Some("vt") => {
                let ok = floats(&mut words, 2);
                counts.texcoords += usize::from(ok);
                ok
            }
            Some("vn") => {
                let ok = floats(&mut words, 3);
                counts.normals += usize::from(ok);
                ok
            }
            Some("f" | "l") => {
                let mut face = PendingFace {
                    line: number,
                    vertex: 0,
                    texcoord: None,
                    normal: None,
                };
                let mut any = false;
                let mut ok = true;
                for word in words {
                    let Some([v, t, n]) = face_vertex(word, &counts) else {
                        ok = false;
                        break;
                    };
                    any = true;
                    face.vertex = face.vertex.max(v);
                    let given = |i: usize| (i != MISSING).then_some(i);
                    face.texcoord = face.texcoord.max(given(t));
                    face.normal = face.normal.max(given(n));
                }
                if !any {
                    // An empty polygon: rejected when the object ends.
                    face.vertex = MISSING;
                }
                faces.push(face);
                ok
            }
            Some("o" | "g") => {
                if let Some(culprit) = first_out_of_range(&faces, &counts) {
                    return Some(culprit);
                }
                faces.clear();
                true
            }
            Some("usemtl") => line
                .split_once(' ')
                .is_some_and(|(_, name)| !name.trim().is_empty()),
            Some(_) => true,
        };
        if !ok {
            return Some(number);
        }
    }
    first_out_of_range(&faces, &counts)
}

/// The line of the first `v` statement of the OBJ text `data` whose position (divided by its
/// `w`, times `scale`) is not finite or beyond ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE),
/// or `None`.
pub(super) fn obj_bad_vertex_line(data: &[u8], scale: f64) -> Option<usize> {
    lines(data).find_map(|(number, line)| {
        let mut words = line?.split_whitespace();
        if words.next() != Some("v") {
            return None;
        }
        let values: Vec<f64> = words.take(5).map_while(|w| w.parse().ok()).collect();
        let w = match values.len() {
            4 => values[3],
            _ => 1.0,
        };
        let bad = values.len() >= 3
            && values[..3]
                .iter()
                .any(|x| !super::coordinate_usable(x / w * scale));
        bad.then_some(number)
    })
}

// ---------------------------------------------------------------------------------------------
// STL, as `stl_io` 0.11 reads it.

/// Size of a binary STL header, then of the triangle count and of a triangle record.
const STL_HEADER: usize = 80;
const STL_COUNT: usize = 4;
const STL_RECORD: usize = 50;

/// Whether `stl_io` reads `data` as ASCII: its first line is UTF-8 starting with `solid `.
pub(super) fn stl_is_ascii(data: &[u8]) -> bool {
    let end = data
        .iter()
        .position(|&b| b == b'\n')
        .map_or(data.len(), |i| i + 1);
    std::str::from_utf8(&data[..end]).is_ok_and(|line| line.starts_with("solid "))
}

/// Whether `tokens` are `keyword` followed by `numbers` finite `f32` values.
fn stl_statement(tokens: &[&str], keywords: &[&str], numbers: usize) -> bool {
    tokens.len() == keywords.len() + numbers
        && tokens[..keywords.len()] == *keywords
        && tokens[keywords.len()..]
            .iter()
            .all(|t| t.parse::<f32>().is_ok_and(f32::is_finite))
}

/// Where `stl_io` 0.11 stops on the STL file `data`, or `None`.
///
/// ASCII (the first line starts with `solid `): the first non-blank line that is not UTF-8 or
/// not the statement expected next (`facet normal x y z` or `endsolid ...`, `outer loop`, three
/// `vertex x y z`, `endloop`, `endfacet`; numbers finite `f32`), or the last line when the file
/// ends inside a facet or before `endsolid`. Binary: byte 0 for a header shorter than 80 bytes,
/// 80 for a missing triangle count, else the offset of the first incomplete 50-byte record.
pub(super) fn stl_error_location(data: &[u8]) -> Option<FileLocation> {
    if !stl_is_ascii(data) {
        if data.len() < STL_HEADER {
            return Some(FileLocation::Byte(0));
        }
        let Some(count) = data.get(STL_HEADER..STL_HEADER + STL_COUNT) else {
            return Some(FileLocation::Byte(STL_HEADER));
        };
        let count = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as usize;
        let complete = (data.len() - STL_HEADER - STL_COUNT) / STL_RECORD;
        return (complete < count).then_some(FileLocation::Byte(
            STL_HEADER + STL_COUNT + complete * STL_RECORD,
        ));
    }
    let mut expected = 0;
    for (number, line) in lines(data).skip(1) {
        let Some(line) = line else {
            return Some(FileLocation::Line(number));
        };
        let tokens: Vec<&str> = line.split_whitespace().take(6).collect();
        if tokens.is_empty() {
            continue;
        }
        let ok = match expected {
            0 if tokens[0] == "endsolid" => return None,
            0 => stl_statement(&tokens, &["facet", "normal"], 3),
            1 => stl_statement(&tokens, &["outer", "loop"], 0),
            2..=4 => stl_statement(&tokens, &["vertex"], 3),
            5 => stl_statement(&tokens, &["endloop"], 0),
            _ => stl_statement(&tokens, &["endfacet"], 0),
        };
        if !ok {
            return Some(FileLocation::Line(number));
        }
        expected = (expected + 1) % 7;
    }
    Some(FileLocation::Line(last_line(data)))
}

/// Where the first vertex of the STL file `data` lies whose coordinates times `scale` are not
/// finite or beyond ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE): its `vertex` line (ASCII)
/// or its offset (binary); `None` if there is none.
pub(super) fn stl_bad_vertex_location(data: &[u8], scale: f64) -> Option<FileLocation> {
    let bad = |coordinates: &[f32]| {
        coordinates
            .iter()
            .any(|&x| !super::coordinate_usable(f64::from(x) * scale))
    };
    if stl_is_ascii(data) {
        return lines(data).find_map(|(number, line)| {
            let mut words = line?.split_whitespace();
            let vertex = words.next() == Some("vertex");
            let coordinates: Vec<f32> = words.take(3).filter_map(|w| w.parse().ok()).collect();
            (vertex && bad(&coordinates)).then_some(FileLocation::Line(number))
        });
    }
    let records = data.get(STL_HEADER + STL_COUNT..)?;
    records
        .chunks_exact(STL_RECORD)
        .enumerate()
        .flat_map(|(r, record)| (1..4).map(move |v| (r, v, &record[12 * v..12 * v + 12])))
        .find(|(_, _, vertex)| {
            let coordinate = |k: usize| {
                let b = &vertex[4 * k..4 * k + 4];
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            };
            bad(&[coordinate(0), coordinate(1), coordinate(2)])
        })
        .map(|(r, v, _)| FileLocation::Byte(STL_HEADER + STL_COUNT + r * STL_RECORD + 12 * v))
}

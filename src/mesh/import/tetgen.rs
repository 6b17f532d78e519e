//! `TetGen`'s `.node` and `.ele` files.
//!
//! `.node`: a header `<points> 3 <attributes> <boundary markers 0|1>`, then one line per point,
//! `<index> <x> <y> <z> [attributes] [marker]`. `.ele`: a header `<tetrahedra> <4|10>
//! <attributes>`, then `<index> <n1> <n2> <n3> <n4> [attributes]`. Points are numbered
//! consecutively from 0 or 1 (the first point says which), and the tetrahedra use the same
//! numbering. `#` starts a comment; blank lines are ignored. Ten-node (quadratic) tetrahedra
//! are an [`ImportErrorKind::UnsupportedElement`] error. A file must hold exactly the points or
//! tetrahedra its header announces, and its last one must end with a line break (a file cut
//! inside a number would read as another number).
//!
//! Regions ([`MeshRegion`]): the tetrahedra's first attribute is their region (`TetGen`'s `-A`
//! numbers regions 1, 2, …; meshio writes a Gmsh file's physical tag there), a whole number: the
//! tetrahedra of each value make the volume `"region N"` of tag `N`. The points' non-zero
//! boundary markers (`TetGen`'s facet markers) make the surfaces `"marker N"` of tag `N`, their
//! points. Point attributes and further tetrahedron attributes are read, checked finite, and
//! not kept.

use super::text::{Source, end_of_line, parse_finite, parse_point, parse_token, scaled};
use super::{MeshRegion, RawMesh, check_scale};
use crate::Error;
use crate::error::ImportErrorKind;
use rapier3d::glamx::DVec3;
use std::collections::BTreeMap;

/// The error of a point or tetrahedron line holding more than its numbers.
const TOO_MANY_NUMBERS: &str = "more numbers on the line than the header announces";

/// Reads a `TetGen` mesh from the contents of its `.node` and `.ele` files (named `node_path`
/// and `ele_path` in errors), coordinates times `scale` (m per file unit).
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad `scale`; [`Error::MeshImport`] for malformed files,
/// point indices out of range or not consecutive, or quadratic tetrahedra.
pub fn parse(
    node: &[u8],
    node_path: &str,
    ele: &[u8],
    ele_path: &str,
    scale: f64,
) -> Result<RawMesh, Error> {
    check_scale(scale)?;
    let (positions, base, markers) = parse_node(node, node_path, scale)?;
    let mut source = Source::new(ele_path, ele);
    let (count, attributes) = parse_ele_header(&mut source)?;
    let capacity = source.capacity(count, 10);
    let mut tets = Vec::with_capacity(capacity);
    let mut tet_locations = Vec::with_capacity(capacity);
    let mut volumes: BTreeMap<i64, Vec<u32>> = BTreeMap::new();
    let points = Numbering {
        base,
        count: positions.len() as u64,
    };
    for i in 0..count {
        let line = source.content_line(Some('#'), "a tetrahedron line")?;
        let (tet, region) = parse_tet_line(&source, line, base + i as u64, points, attributes)?;
        if let Some(region) = region {
            volumes.entry(region).or_default().push(i as u32);
        }
        tets.push(tet);
        tet_locations.push(source.location());
    }
    source.check_line_ended("the last tetrahedron")?;
    source.check_nothing_follows('#', "tetrahedra", count)?;
    Ok(RawMesh {
        path: ele_path.to_owned(),
        positions,
        regions: regions(&tets, volumes, &markers),
        tets,
        mid_edge_nodes: Vec::new(),
        hexahedra: super::Hexahedra::None,
        tet_locations,
    })
}

/// The regions of the module documentation: a volume per region attribute, its tetrahedra
/// (indices into `tets`) given, and a surface per non-zero boundary marker of `markers` (one per
/// point, or none).
fn regions(
    tets: &[[u32; 4]],
    volumes: BTreeMap<i64, Vec<u32>>,
    markers: &[i64],
) -> Vec<MeshRegion> {
    let mut regions = Vec::new();
    for (tag, members) in volumes {
        let mut nodes: Vec<u32> = (members.iter()).flat_map(|&t| tets[t as usize]).collect();
        nodes.sort_unstable();
        nodes.dedup();
        regions.push(MeshRegion {
            name: format!("region {tag}"),
            dimension: 3,
            tag,
            nodes,
            tets: members,
        });
    }
    let mut surfaces: BTreeMap<i64, Vec<u32>> = BTreeMap::new();
    for (point, &marker) in markers.iter().enumerate() {
        if marker != 0 {
            surfaces.entry(marker).or_default().push(point as u32);
        }
    }
    for (tag, nodes) in surfaces {
        regions.push(MeshRegion {
            name: format!("marker {tag}"),
            dimension: 2,
            tag,
            nodes,
            tets: Vec::new(),
        });
    }
    regions
}

/// The header of an `.ele` file: the tetrahedron count (not zero) and the number of attributes
/// each line ends with; quadratic (10-node) tetrahedra are refused.
fn parse_ele_header(source: &mut Source<'_>) -> Result<(usize, usize), Error> {
    let header = source.content_line(Some('#'), "the header `<tetrahedra> <4|10> <attributes>`")?;
    let mut tokens = header.split_ascii_whitespace();
    let count: usize = parse_token(source, tokens.next(), "tetrahedron count")?;
    let per_tet: usize = parse_token(source, tokens.next(), "nodes per tetrahedron")?;
    let attributes: usize = tokens
        .next()
        .map_or(Ok(0), |t| parse_token(source, Some(t), "attribute count"))?;
    match per_tet {
        4 => {}
        10 => {
            return Err(source.error(
                ImportErrorKind::UnsupportedElement,
                "quadratic (10-node) tetrahedra are not supported: run tetgen without -o2",
            ));
        }
        _ => {
            return Err(source.error(
                ImportErrorKind::Syntax,
                format!("{per_tet} nodes per tetrahedron: TetGen writes 4 or 10"),
            ));
        }
    }
    if count == 0 {
        return Err(source.error(
            ImportErrorKind::NoTetrahedra,
            "the file holds no tetrahedra",
        ));
    }
    Ok((count, attributes))
}

/// How the points are numbered: `count` of them from `base` (0 or 1).
#[derive(Clone, Copy)]
struct Numbering {
    base: u64,
    count: u64,
}

/// The corners (0-based) of the tetrahedron line `line` `<index> <n1> <n2> <n3> <n4>
/// [attributes]`, whose index must be `index`, and its region (its first attribute, a whole
/// number) if it has `attributes`; the nodes are numbered by `points`.
fn parse_tet_line(
    source: &Source<'_>,
    line: &str,
    expected: u64,
    points: Numbering,
    attributes: usize,
) -> Result<([u32; 4], Option<i64>), Error> {
    let Numbering { base, count } = points;
    let mut tokens = line.split_ascii_whitespace();
    let index: u64 = parse_token(source, tokens.next(), "tetrahedron index")?;
    if index != expected {
        return Err(source.error(
            ImportErrorKind::BadCount,
            format!(
                "tetrahedron index {index}, expected {expected}: tetrahedra are numbered \
                 consecutively like the points"
            ),
        ));
    }
    let mut tet = [0u32; 4];
    for corner in &mut tet {
        let node: u64 = parse_token(source, tokens.next(), "node index")?;
        let Some(local) = node.checked_sub(base).filter(|&n| n < count) else {
            return Err(source.error(
                ImportErrorKind::IndexOutOfRange,
                format!(
                    "node {node} does not exist: the points are numbered {base} to {}",
                    base + count - 1
                ),
            ));
        };
        *corner = local as u32;
    }
    let mut region = None;
    for k in 0..attributes {
        let value = parse_finite(source, tokens.next(), "tetrahedron attribute")?;
        if k == 0 {
            region = Some(whole_number(source, value, "region attribute")?);
        }
    }
    end_of_line(source, tokens, ImportErrorKind::BadCount, TOO_MANY_NUMBERS)?;
    Ok((tet, region))
}

/// `value` as a whole number, or an error naming it `what`.
fn whole_number(source: &Source<'_>, value: f64, what: &str) -> Result<i64, Error> {
    // Whole numbers up to 2^53 are exact in an f64.
    if value.fract() == 0.0 && value.abs() <= 9_007_199_254_740_992.0 {
        Ok(value as i64)
    } else {
        Err(source.error(
            ImportErrorKind::Syntax,
            format!("{what} {value} is not a whole number: regions are numbered 1, 2, …"),
        ))
    }
}

/// The points of a `.node` file, the index of the first (0 or 1), and the points' boundary
/// markers (none if the file has none).
fn parse_node(data: &[u8], path: &str, scale: f64) -> Result<(Vec<DVec3>, u64, Vec<i64>), Error> {
    let mut source = Source::new(path, data);
    let header = source.content_line(
        Some('#'),
        "the header `<points> 3 <attributes> <boundary markers>`",
    )?;
    let mut tokens = header.split_ascii_whitespace();
    let count: usize = parse_token(&source, tokens.next(), "point count")?;
    let dimension: u32 = parse_token(&source, tokens.next(), "dimension")?;
    let attributes: usize = tokens
        .next()
        .map_or(Ok(0), |t| parse_token(&source, Some(t), "attribute count"))?;
    let markers: u32 = tokens.next().map_or(Ok(0), |t| {
        parse_token(&source, Some(t), "boundary marker flag")
    })?;
    if dimension != 3 {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!("dimension {dimension}: only 3 is meaningful for tetrahedra"),
        ));
    }
    if markers > 1 {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!("boundary marker flag {markers} is neither 0 nor 1"),
        ));
    }
    if count == 0 {
        return Err(source.error(ImportErrorKind::BadCount, "the file declares no points"));
    }
    if count > u32::MAX as usize {
        return Err(source.error(ImportErrorKind::BadCount, "more than 2^32 - 1 points"));
    }
    let mut positions = Vec::with_capacity(source.capacity(count, 8));
    let mut point_markers = Vec::new();
    let mut base = 0;
    for i in 0..count {
        let line = source.content_line(Some('#'), "a point line")?;
        let mut tokens = line.split_ascii_whitespace();
        let index: u64 = parse_token(&source, tokens.next(), "point index")?;
        if i == 0 {
            if index > 1 {
                return Err(source.error(
                    ImportErrorKind::BadCount,
                    format!("the first point has index {index}: TetGen numbers from 0 or 1"),
                ));
            }
            base = index;
        } else if index != base + i as u64 {
            return Err(source.error(
                ImportErrorKind::BadCount,
                format!(
                    "point index {index}, expected {}: points are numbered consecutively",
                    base + i as u64
                ),
            ));
        }
        let p = parse_point(&source, &mut tokens)?;
        for _ in 0..attributes {
            parse_finite(&source, tokens.next(), "point attribute")?;
        }
        if markers == 1 {
            point_markers.push(parse_token(&source, tokens.next(), "boundary marker")?);
        }
        end_of_line(&source, tokens, ImportErrorKind::BadCount, TOO_MANY_NUMBERS)?;
        positions.push(scaled(&source, p, scale)?);
    }
    source.check_line_ended("the last point")?;
    source.check_nothing_follows('#', "points", count)?;
    Ok((positions, base, point_markers))
}

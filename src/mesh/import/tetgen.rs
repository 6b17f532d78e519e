//! `TetGen`'s `.node` and `.ele` files.
//!
//! `.node`: a header `<points> 3 <attributes> <boundary markers 0|1>`, then one line per point,
//! `<index> <x> <y> <z> [attributes] [marker]`. `.ele`: a header `<tetrahedra> <4|10> <region
//! attribute 0|1>`, then `<index> <n1> <n2> <n3> <n4> [region]`. Points are numbered
//! consecutively from 0 or 1 (the first point says which), and the tetrahedra use the same
//! numbering. `#` starts a comment; blank lines are ignored. Ten-node (quadratic) tetrahedra
//! are an [`ImportErrorKind::UnsupportedElement`] error.

use super::text::{Source, parse_finite, parse_token, scaled};
use super::{RawMesh, check_scale};
use crate::Error;
use crate::error::ImportErrorKind;
use rapier3d::glamx::DVec3;

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
    let (positions, base) = parse_node(node, node_path, scale)?;
    let mut source = Source::new(ele_path, ele);
    let header = source.content_line(Some('#'), "the header `<tetrahedra> <4|10> <0|1>`")?;
    let mut tokens = header.split_ascii_whitespace();
    let count: usize = parse_token(&source, tokens.next(), "tetrahedron count")?;
    let per_tet: usize = parse_token(&source, tokens.next(), "nodes per tetrahedron")?;
    let region: u32 = tokens
        .next()
        .map_or(Ok(0), |t| parse_token(&source, Some(t), "region flag"))?;
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
    if region > 1 {
        return Err(source.error(
            ImportErrorKind::Syntax,
            format!("region flag {region} is neither 0 nor 1"),
        ));
    }
    if count == 0 {
        return Err(source.error(
            ImportErrorKind::NoTetrahedra,
            "the file holds no tetrahedra",
        ));
    }
    let capacity = source.capacity(count, 10);
    let mut tets = Vec::with_capacity(capacity);
    let mut tet_locations = Vec::with_capacity(capacity);
    for i in 0..count {
        let line = source.content_line(Some('#'), "a tetrahedron line")?;
        let mut tokens = line.split_ascii_whitespace();
        let index: u64 = parse_token(&source, tokens.next(), "tetrahedron index")?;
        if index != base + i as u64 {
            return Err(source.error(
                ImportErrorKind::BadCount,
                format!(
                    "tetrahedron index {index}, expected {}: tetrahedra are numbered \
                     consecutively like the points",
                    base + i as u64
                ),
            ));
        }
        let mut tet = [0u32; 4];
        for corner in &mut tet {
            let node: u64 = parse_token(&source, tokens.next(), "node index")?;
            let local = node
                .checked_sub(base)
                .filter(|&n| n < positions.len() as u64);
            let Some(local) = local else {
                return Err(source.error(
                    ImportErrorKind::IndexOutOfRange,
                    format!(
                        "node {node} does not exist: the points are numbered {base} to {}",
                        base + positions.len() as u64 - 1
                    ),
                ));
            };
            *corner = local as u32;
        }
        if region == 1 {
            parse_finite(&source, tokens.next(), "region attribute")?;
        }
        if tokens.next().is_some() {
            return Err(source.error(
                ImportErrorKind::BadCount,
                "more numbers on the line than the header announces",
            ));
        }
        tets.push(tet);
        tet_locations.push(source.location());
    }
    Ok(RawMesh {
        path: ele_path.to_owned(),
        positions,
        tets,
        mid_edge_nodes: Vec::new(),
        tet_locations,
    })
}

/// The points of a `.node` file and the index of the first (0 or 1).
fn parse_node(data: &[u8], path: &str, scale: f64) -> Result<(Vec<DVec3>, u64), Error> {
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
        let x = parse_finite(&source, tokens.next(), "x coordinate")?;
        let y = parse_finite(&source, tokens.next(), "y coordinate")?;
        let z = parse_finite(&source, tokens.next(), "z coordinate")?;
        for _ in 0..attributes {
            parse_finite(&source, tokens.next(), "point attribute")?;
        }
        if markers == 1 {
            let _: i64 = parse_token(&source, tokens.next(), "boundary marker")?;
        }
        if tokens.next().is_some() {
            return Err(source.error(
                ImportErrorKind::BadCount,
                "more numbers on the line than the header announces",
            ));
        }
        positions.push(scaled(&source, DVec3::new(x, y, z), scale)?);
    }
    Ok((positions, base))
}

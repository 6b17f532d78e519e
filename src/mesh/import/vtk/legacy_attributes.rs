//! The attribute data after a legacy `.vtk` file's grid: `CELL_DATA` and `POINT_DATA`
//! sections of `SCALARS`, `FIELD` arrays and the other attributes of the format.
//!
//! A cell array named as a `.vtu` file's tags are (`gmsh:physical`, as meshio writes a Gmsh
//! file's physical groups, or `CellEntityIds`) gives the cells' region tags: one component of
//! whole numbers per cell, else an error. Every other attribute is read past, its values
//! counted (a section whose size disagrees with the grid's cells or points, a block with more
//! or fewer values than its header announces, and an unknown keyword are errors at their
//! line). `METADATA` blocks (the VTK 9 library's) are skipped as after the grid's arrays.

use super::legacy_data::{DataType, Legacy, data_type};
use super::xml_document::CELL_TAG_NAMES;
use crate::Error;
use crate::error::ImportErrorKind;
use crate::mesh::import::text::{parse_token, shorten};
use std::str::SplitAsciiWhitespace;

/// Which section the attributes being read belong to, and its size.
#[derive(Clone, Copy, PartialEq)]
enum Section {
    /// Before any `CELL_DATA` or `POINT_DATA`.
    None,
    /// `CELL_DATA`: one tuple per cell.
    Cells(usize),
    /// `POINT_DATA`: one tuple per point.
    Points(usize),
}

/// Reads the rest of the file after the grid of `cell_count` cells and `point_count` points:
/// the cells' region tags if a cell array holds them.
pub(super) fn read_cell_tags(
    file: &mut Legacy<'_>,
    cell_count: usize,
    point_count: usize,
) -> Result<Option<Vec<u64>>, Error> {
    let mut section = Section::None;
    let mut tags = None;
    while let Some(line) = file.keyword_line()? {
        let mut words = line.split_ascii_whitespace();
        let keyword = words.next().unwrap_or("").to_ascii_uppercase();
        let count = |file: &Legacy<'_>, words: &mut SplitAsciiWhitespace<'_>, what: &str| {
            parse_token::<usize>(&file.source, words.next(), what)
        };
        match keyword.as_str() {
            "CELL_DATA" | "POINT_DATA" => {
                let (size, expected, what) = if keyword == "CELL_DATA" {
                    (
                        count(file, &mut words, "cell data size")?,
                        cell_count,
                        "cells",
                    )
                } else {
                    (
                        count(file, &mut words, "point data size")?,
                        point_count,
                        "points",
                    )
                };
                if size != expected {
                    return Err(file.source.error(
                        ImportErrorKind::BadCount,
                        format!("{keyword} {size} for a grid of {expected} {what}"),
                    ));
                }
                section = if keyword == "CELL_DATA" {
                    Section::Cells(size)
                } else {
                    Section::Points(size)
                };
            }
            "METADATA" => while file.source.line()?.is_some_and(|l| !l.is_empty()) {},
            _ => {
                let tuples = match section {
                    Section::Cells(n) | Section::Points(n) => n,
                    Section::None => {
                        return Err(file.source.error(
                            ImportErrorKind::Syntax,
                            format!(
                                "expected CELL_DATA or POINT_DATA after the grid, found `{}`",
                                shorten(line)
                            ),
                        ));
                    }
                };
                let cells = matches!(section, Section::Cells(_));
                let read = read_attribute(file, &keyword, words, tuples, cells && tags.is_none())?;
                if read.is_some() {
                    tags = read;
                }
            }
        }
    }
    Ok(tags)
}

/// Reads the attribute `keyword` (its header's other `words`) of `tuples` tuples; returns
/// the region tags it holds when `want_tags` (a cell attribute, no tags read yet) and it is
/// the cells' tag array (one component, else an error).
fn read_attribute(
    file: &mut Legacy<'_>,
    keyword: &str,
    mut words: SplitAsciiWhitespace<'_>,
    tuples: usize,
    want_tags: bool,
) -> Result<Option<Vec<u64>>, Error> {
    let name = words.next().unwrap_or("");
    // Components per tuple, and the type of the values.
    let (components, ty) = match keyword {
        "SCALARS" => {
            let ty = data_type(&file.source, words.next())?;
            let components = match words.next() {
                Some(c) => parse_token(&file.source, Some(c), "scalar components")?,
                None => 1,
            };
            let table = file.keyword_line()?.unwrap_or("");
            if !table.to_ascii_uppercase().starts_with("LOOKUP_TABLE") {
                return Err(file.source.error(
                    ImportErrorKind::Syntax,
                    format!("expected `LOOKUP_TABLE <name>`, found `{}`", shorten(table)),
                ));
            }
            if want_tags && CELL_TAG_NAMES.contains(&name) {
                check_tag_shape(file, name, components, (tuples, tuples))?;
                return file.tags(tuples, ty, name).map(Some);
            }
            (components, ty)
        }
        "FIELD" => {
            let arrays = parse_token(&file.source, words.next(), "field array count")?;
            return read_field(file, arrays, tuples, want_tags);
        }
        "VECTORS" | "NORMALS" | "TANGENTS" | "HIGHERORDERDEGREES" => {
            (3, data_type(&file.source, words.next())?)
        }
        "TENSORS" => (9, data_type(&file.source, words.next())?),
        "TENSORS6" => (6, data_type(&file.source, words.next())?),
        "GLOBAL_IDS" | "PEDIGREE_IDS" | "EDGE_FLAGS" | "RATIONAL_WEIGHTS" => {
            (1, data_type(&file.source, words.next())?)
        }
        "TEXTURE_COORDINATES" => {
            let dimension = parse_token(&file.source, words.next(), "texture dimension")?;
            (dimension, data_type(&file.source, words.next())?)
        }
        "COLOR_SCALARS" => {
            let values = parse_token(&file.source, words.next(), "color components")?;
            // Unsigned bytes in binary files, floats in ASCII ones.
            (values, DataType::Unsigned(1))
        }
        "LOOKUP_TABLE" => {
            // A table's colours: `size` RGBA tuples, whatever the section's size.
            let size: usize = parse_token(&file.source, words.next(), "lookup table size")?;
            file.skip(size.saturating_mul(4), DataType::Unsigned(1), name)?;
            return Ok(None);
        }
        _ => {
            return Err(file.source.error(
                ImportErrorKind::Syntax,
                format!("unknown attribute `{}`", shorten(keyword)),
            ));
        }
    };
    file.skip(tuples.saturating_mul(components), ty, name)?;
    Ok(None)
}

/// Reads the `arrays` arrays of a field (`<name> <components> <tuples> <type>` each, or
/// `NULL_ARRAY`, a `METADATA` block after any); returns the region tags one holds when
/// `want_tags` and it is the cells' tag array (one component, `section_tuples` tuples, else an
/// error).
fn read_field(
    file: &mut Legacy<'_>,
    arrays: usize,
    section_tuples: usize,
    want_tags: bool,
) -> Result<Option<Vec<u64>>, Error> {
    let mut tags = None;
    let mut read = 0;
    while read < arrays {
        let Some(line) = file.keyword_line()? else {
            return Err(file.source.error(
                ImportErrorKind::Truncated,
                format!("the file ends after {read} of its field's {arrays} arrays"),
            ));
        };
        let mut words = line.split_ascii_whitespace();
        let name = words.next().unwrap_or("");
        match name {
            "METADATA" => {
                while file.source.line()?.is_some_and(|l| !l.is_empty()) {}
                continue;
            }
            "NULL_ARRAY" => {}
            _ => {
                let components: usize = parse_token(&file.source, words.next(), "components")?;
                let tuples: usize = parse_token(&file.source, words.next(), "tuples")?;
                let ty = data_type(&file.source, words.next())?;
                if want_tags && tags.is_none() && CELL_TAG_NAMES.contains(&name) {
                    check_tag_shape(file, name, components, (tuples, section_tuples))?;
                    tags = Some(file.tags(tuples, ty, name)?);
                } else {
                    file.skip(components.saturating_mul(tuples), ty, name)?;
                }
            }
        }
        read += 1;
    }
    Ok(tags)
}

/// [`ImportErrorKind::BadCount`] unless the cells' tag array `name` has one component and one
/// tuple per cell (`tuples` of the array, `cells` of the section): regions are never read
/// short.
fn check_tag_shape(
    file: &Legacy<'_>,
    name: &str,
    components: usize,
    (tuples, cells): (usize, usize),
) -> Result<(), Error> {
    if components == 1 && tuples == cells {
        return Ok(());
    }
    Err(file.source.error(
        ImportErrorKind::BadCount,
        format!(
            "the cell tag array `{}` has {components} components and {tuples} tuples, for \
             {cells} cells (one tag per cell)",
            shorten(name)
        ),
    ))
}

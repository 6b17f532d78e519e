//! Wavefront OBJ surfaces for Blender: one file per saved frame, one object (`o`) per body, the
//! soft bodies' boundary triangles at their world positions and the rigid bodies' meshes, in m,
//! faces wound counter-clockwise seen from outside.

use super::snapshot::Snapshot;
use super::{OutputError, file_stem};
use rapier_fvm::glamx::DVec3;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes the surfaces of every body of `snapshot` to the OBJ file `path`. Soft bodies keep only
/// the nodes on their surface.
///
/// # Errors
/// [`OutputError::Io`] if the file cannot be written.
pub fn write_obj(path: &Path, snapshot: &Snapshot) -> Result<(), OutputError> {
    let file = std::fs::File::create(path).map_err(OutputError::io(path))?;
    let mut out = BufWriter::new(file);
    let mut written = 0;
    let result = (|| -> std::io::Result<()> {
        writeln!(out, "# t = {} s", snapshot.time)?;
        for body in &snapshot.soft_bodies {
            // Surface nodes renumbered in order of first use.
            let mut index = vec![u32::MAX; body.positions.len()];
            let mut vertices = Vec::new();
            let triangles: Vec<[u32; 3]> = body
                .surface
                .iter()
                .map(|t| {
                    t.map(|n| {
                        let slot = &mut index[n as usize];
                        if *slot == u32::MAX {
                            *slot = vertices.len() as u32;
                            vertices.push(body.positions[n as usize]);
                        }
                        *slot
                    })
                })
                .collect();
            written = write_object(&mut out, &body.name, &vertices, &triangles, written)?;
        }
        for body in &snapshot.rigid_bodies {
            written = write_object(
                &mut out,
                &body.name,
                &body.vertices,
                &body.triangles,
                written,
            )?;
        }
        out.flush()
    })();
    result.map_err(OutputError::io(path))
}

/// Writes one object after `before` vertices; returns the vertex count after it.
fn write_object(
    out: &mut impl Write,
    name: &str,
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    before: usize,
) -> std::io::Result<usize> {
    writeln!(out, "o {}", file_stem(name))?;
    for v in vertices {
        writeln!(out, "v {} {} {}", v.x, v.y, v.z)?;
    }
    for t in triangles {
        let [a, b, c] = t.map(|i| before + i as usize + 1);
        writeln!(out, "f {a} {b} {c}")?;
    }
    Ok(before + vertices.len())
}

//! A soft body's region materials: the elements each of its `materials` entries selects (those
//! whose centroid lies in a box of rest coordinates, or a mesh file's volume group) with their
//! material, each refused at its key if it selects no element.

use crate::scene::soft_body::SoftBodySpec;
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::material::Material;
use rapier_fvm::mesh::import::MeshRegion;

/// Per element of a body, its nodes' mean rest position (m): its centroid, for the boxes.
pub(super) fn element_centroids<'a>(
    positions: &[DVec3],
    elements: impl Iterator<Item = &'a [u32]>,
) -> Vec<DVec3> {
    elements
        .map(|nodes| {
            nodes.iter().map(|&n| positions[n as usize]).sum::<DVec3>() / nodes.len() as f64
        })
        .collect()
}

/// The elements `spec`'s `materials` select, among elements of `centroids` (rest coordinates)
/// or in `regions` of the file `path` (their `tets` numbered as the body's elements), each with
/// its material; `key` in the scene of `source`.
///
/// # Errors
/// A [`SceneError`] at an entry that names no region of the file or a region of no volume, or
/// whose box holds no element's centroid.
pub(super) fn region_materials(
    spec: &SoftBodySpec,
    centroids: &[DVec3],
    (regions, path): (&[MeshRegion], &str),
    (key, source): (&str, &SceneSource),
) -> Result<Vec<(Vec<u32>, Material)>, SceneError> {
    let mut materials = Vec::with_capacity(spec.materials.len());
    for (i, entry) in spec.materials.iter().enumerate() {
        let at = format!("{key}.materials[{i}]");
        let elements = match (&entry.region, entry.min, entry.max) {
            (Some(name), _, _) => {
                let region = MeshRegion::find(regions, &name.id(), path)
                    .map_err(|e| source.error(&format!("{at}.region"), e.to_string()))?;
                region.tets.clone()
            }
            (None, Some(min), Some(max)) => {
                let (min, max) = (DVec3::from_array(min), DVec3::from_array(max));
                (0..centroids.len() as u32)
                    .filter(|&e| {
                        let c = centroids[e as usize];
                        c.cmpge(min).all() && c.cmple(max).all()
                    })
                    .collect()
            }
            _ => Vec::new(),
        };
        if elements.is_empty() {
            let what = if entry.region.is_some() {
                "the region holds no volume element"
            } else {
                "the box holds no element's centroid"
            };
            return Err(source.error(&at, what));
        }
        let material =
            (entry.material(&spec.material)).map_err(|e| source.error(&at, e.to_string()))?;
        materials.push((elements, material));
    }
    Ok(materials)
}

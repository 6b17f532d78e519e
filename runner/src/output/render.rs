//! Pictures of a [`Snapshot`] with no display or GPU: every surface triangle goes through the
//! [`Camera`] into a software z-buffer, lit by a light above and behind the camera (Lambert,
//! two-sided, so open patches and either winding show), coloured by material or by von Mises
//! stress, then labelled with plotters and encoded as PNG.

use super::raster::Raster;
use super::snapshot::Snapshot;
use super::{Camera, OutputError, font};
use plotters::backend::{BitMapBackend, DrawingBackend};
use plotters::prelude::*;
use rapier_fvm::glamx::DVec3;
use std::path::Path;

/// Background colour of the pictures.
const BACKGROUND: [u8; 3] = [250, 250, 250];
/// Colour of rigid bodies (0 to 1 per channel).
const RIGID: [f64; 3] = [0.62, 0.64, 0.68];
/// Colours of the soft bodies' materials, in order of first appearance.
const MATERIALS: [[f64; 3]; 6] = [
    [0.86, 0.37, 0.24],
    [0.22, 0.49, 0.80],
    [0.30, 0.69, 0.31],
    [0.85, 0.65, 0.13],
    [0.58, 0.40, 0.74],
    [0.10, 0.70, 0.72],
];
/// The viridis colour map, sampled at 0, 1/4, …, 1.
const VIRIDIS: [[f64; 3]; 5] = [
    [0.267, 0.005, 0.329],
    [0.230, 0.322, 0.546],
    [0.128, 0.567, 0.551],
    [0.369, 0.789, 0.383],
    [0.993, 0.906, 0.144],
];
/// Colour of the edges of 2D meshes (0 to 1 per channel).
const EDGES: [f64; 3] = [0.25, 0.25, 0.25];
/// Light factor on surfaces facing away from the light.
const AMBIENT: f64 = 0.35;

/// How soft bodies are coloured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coloring {
    /// One colour per material label, with a legend.
    Material,
    /// The nodal von Mises stress on the viridis map from 0 to `max` (Pa), with a colour bar;
    /// stresses above `max` get the top colour. Keep `max` fixed over a series so colours compare
    /// between frames.
    VonMises {
        /// The stress shown in the top colour (Pa), positive.
        max: f64,
    },
}

/// Draws `snapshot` through `camera`, coloured by `coloring`, with the simulated time in a
/// corner, into the PNG file `path`.
///
/// # Errors
/// [`OutputError::Picture`] if the picture cannot be drawn or written.
pub fn render_png(
    path: &Path,
    snapshot: &Snapshot,
    camera: &Camera,
    coloring: Coloring,
) -> Result<(), OutputError> {
    let (width, height) = camera.size();
    let mut raster = Raster::new(width, height, BACKGROUND);
    let light = (camera.toward_eye() + DVec3::new(-0.3, 1.0, 0.2)).normalize();
    let materials = material_labels(snapshot);
    for body in &snapshot.soft_bodies {
        let colors: Vec<[f64; 3]> = match coloring {
            Coloring::Material => {
                let index = materials.iter().position(|m| *m == body.material);
                vec![MATERIALS[index.unwrap_or(0) % MATERIALS.len()]; body.positions.len()]
            }
            Coloring::VonMises { max } => body
                .nodal_von_mises()
                .iter()
                .map(|s| viridis(s / max))
                .collect(),
        };
        for t in &body.surface {
            let corners = t.map(|n| body.positions[n as usize]);
            let shade = lambert(corners, light);
            let color = t.map(|n| colors[n as usize].map(|c| c * shade));
            raster.triangle(corners.map(|p| camera.project(p)), color);
        }
        if let super::Cells::Triangles(triangles) = &body.cells {
            draw_edges(&mut raster, camera, &body.positions, triangles);
        }
    }
    for body in &snapshot.rigid_bodies {
        for t in &body.triangles {
            let corners = t.map(|i| body.vertices[i as usize]);
            let shade = lambert(corners, light);
            raster.triangle(
                corners.map(|p| camera.project(p)),
                [RIGID.map(|c| c * shade); 3],
            );
        }
    }
    annotate(
        path,
        &raster,
        (width, height),
        snapshot.time,
        coloring,
        &materials,
    )
    .map_err(OutputError::picture(path))
}

/// Draws the edges of the 2D mesh `triangles` with nodes at `positions` (m) in a dark grey, so
/// that the mesh's deformation and turning show.
fn draw_edges(raster: &mut Raster, camera: &Camera, positions: &[DVec3], triangles: &[[u32; 3]]) {
    for t in triangles {
        for k in 0..3 {
            // An inner edge, shared by two triangles, is drawn twice, over itself.
            let [p, q] = [t[k], t[(k + 1) % 3]].map(|n| camera.project(positions[n as usize]));
            raster.segment(p, q, EDGES);
        }
    }
}

/// The material labels of the soft bodies, each once, in order of first appearance.
fn material_labels(snapshot: &Snapshot) -> Vec<String> {
    let mut labels: Vec<String> = Vec::new();
    for body in &snapshot.soft_bodies {
        if !labels.contains(&body.material) {
            labels.push(body.material.clone());
        }
    }
    labels
}

/// The light factor of a triangle: ambient plus Lambert on the side of the face that is lit.
fn lambert([a, b, c]: [DVec3; 3], light: DVec3) -> f64 {
    let normal = (b - a).cross(c - a).normalize_or_zero();
    AMBIENT + (1.0 - AMBIENT) * normal.dot(light).abs()
}

/// The viridis colour at `s` in `[0, 1]` (clamped).
fn viridis(s: f64) -> [f64; 3] {
    let x = s.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    [0, 1, 2].map(|k| VIRIDIS[i][k] * (1.0 - f) + VIRIDIS[i + 1][k] * f)
}

/// A stress (Pa) in the unit that keeps it readable, with that unit.
fn readable_stress(pa: f64) -> (f64, &'static str) {
    match pa.abs() {
        x if x >= 1e6 => (pa * 1e-6, "MPa"),
        x if x >= 1e3 => (pa * 1e-3, "kPa"),
        _ => (pa, "Pa"),
    }
}

/// Copies the raster into a plotters bitmap, draws the time and the legend or colour bar, and
/// writes the PNG.
fn annotate(
    path: &Path,
    raster: &Raster,
    (width, height): (u32, u32),
    time: f64,
    coloring: Coloring,
    materials: &[String],
) -> Result<(), Box<dyn std::error::Error>> {
    let mut backend = BitMapBackend::new(path, (width, height));
    backend.blit_bitmap((0, 0), (width, height), raster.rgb())?;
    let root = backend.into_drawing_area();
    if font::register() {
        let size = (height / 28).max(12);
        let text = TextStyle::from(("sans-serif", size).into_font()).color(&BLACK);
        root.draw_text(&format!("t = {time:.3} s"), &text, (12, 10))?;
        let x = width as i32 - 12 - 6 * size as i32;
        match coloring {
            Coloring::Material => {
                for (i, label) in materials.iter().enumerate() {
                    let y = 10 + (i as i32) * (size as i32 + 6);
                    let [r, g, b] = MATERIALS[i % MATERIALS.len()].map(|c| (c * 255.0) as u8);
                    let swatch = [(x, y), (x + size as i32, y + size as i32)];
                    root.draw(&Rectangle::new(swatch, RGBColor(r, g, b).filled()))?;
                    root.draw_text(label, &text, (x + size as i32 + 6, y))?;
                }
            }
            Coloring::VonMises { max } => {
                let (top, bottom) = (10 + 2 * size as i32, height as i32 * 2 / 3);
                for y in top..bottom {
                    let s = f64::from(bottom - y) / f64::from(bottom - top);
                    let [r, g, b] = viridis(s).map(|c| (c * 255.0) as u8);
                    let row = [(x, y), (x + size as i32, y + 1)];
                    root.draw(&Rectangle::new(row, RGBColor(r, g, b).filled()))?;
                }
                let (value, unit) = readable_stress(max);
                root.draw_text(
                    &format!("von Mises ({unit})"),
                    &text,
                    (x - size as i32 * 3, 10),
                )?;
                let label_x = x + size as i32 + 6;
                root.draw_text(&format!("≥ {value:.3}"), &text, (label_x, top))?;
                root.draw_text("0", &text, (label_x, bottom - size as i32))?;
            }
        }
    }
    root.present()?;
    Ok(())
}

//! A software z-buffer: triangles with per-vertex colours filled pixel by pixel, keeping the
//! nearest surface at each pixel; segments drawn over them (the edges of 2D meshes). Pixels are
//! sampled at their centres; a triangle covers the pixels whose centre lies inside it (either
//! winding).

use rapier_fvm::glamx::DVec3;

/// An RGB picture with a depth per pixel.
pub(crate) struct Raster {
    width: usize,
    height: usize,
    /// Row-major, top row first, 3 bytes per pixel.
    rgb: Vec<u8>,
    /// Depth (m) of the nearest surface drawn at each pixel.
    depth: Vec<f64>,
}

impl Raster {
    /// A `width` × `height` picture filled with `background`.
    pub(crate) fn new(width: u32, height: u32, background: [u8; 3]) -> Self {
        let (width, height) = (width as usize, height as usize);
        Self {
            width,
            height,
            rgb: background.repeat(width * height),
            depth: vec![f64::INFINITY; width * height],
        }
    }

    /// The pixels, row-major from the top left, 3 bytes (RGB) each.
    pub(crate) fn rgb(&self) -> &[u8] {
        &self.rgb
    }

    /// Fills the triangle with screen corners `p` (pixels, and depth in z) and corner colours
    /// `color` (0 to 1 per channel), interpolated linearly.
    pub(crate) fn triangle(&mut self, p: [DVec3; 3], color: [[f64; 3]; 3]) {
        let area = edge(p[0], p[1], p[2]);
        if area.is_nan() || area.abs() <= 1e-12 {
            return;
        }
        let lo = p[0].min(p[1]).min(p[2]);
        let hi = p[0].max(p[1]).max(p[2]);
        let x0 = lo.x.floor().max(0.0) as usize;
        let y0 = lo.y.floor().max(0.0) as usize;
        let x1 = (hi.x.ceil().max(0.0) as usize).min(self.width);
        let y1 = (hi.y.ceil().max(0.0) as usize).min(self.height);
        for y in y0..y1 {
            for x in x0..x1 {
                let c = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, 0.0);
                let w = [
                    edge(p[1], p[2], c),
                    edge(p[2], p[0], c),
                    edge(p[0], p[1], c),
                ]
                .map(|e| e / area);
                if w.iter().any(|&wi| wi < 0.0) {
                    continue;
                }
                let z = w[0] * p[0].z + w[1] * p[1].z + w[2] * p[2].z;
                let i = y * self.width + x;
                if z >= self.depth[i] {
                    continue;
                }
                self.depth[i] = z;
                for (k, byte) in self.rgb[3 * i..3 * i + 3].iter_mut().enumerate() {
                    let value = w[0] * color[0][k] + w[1] * color[1][k] + w[2] * color[2][k];
                    *byte = (value.clamp(0.0, 1.0) * 255.0).round() as u8;
                }
            }
        }
    }
}

impl Raster {
    /// Draws the segment between the screen points `a` and `b` (pixels) one pixel wide in
    /// `color` (0 to 1 per channel), over whatever is drawn (no depth test).
    pub(crate) fn segment(&mut self, a: DVec3, b: DVec3, color: [f64; 3]) {
        let steps = (b - a).truncate().abs().max_element().ceil();
        if !steps.is_finite() {
            return;
        }
        let rgb = color.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        for k in 0..=(steps as usize) {
            let p = a.lerp(b, k as f64 / steps.max(1.0));
            let (x, y) = (p.x.floor(), p.y.floor());
            if x < 0.0 || y < 0.0 || x >= self.width as f64 || y >= self.height as f64 {
                continue;
            }
            let i = y as usize * self.width + x as usize;
            self.rgb[3 * i..3 * i + 3].copy_from_slice(&rgb);
        }
    }
}

/// Twice the signed area of the screen triangle `a b c` (pixels²), from x and y only.
fn edge(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

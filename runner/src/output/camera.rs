//! Orthographic cameras: the fixed oblique one of 3D scenes looks down at the scene from the
//! front right, about 27° above the horizon (y is up); the front one of 2D scenes looks at the
//! plane z = 0. Each frames a given box with a margin in the left part of the picture, leaving a
//! column on the right for the legend or colour bar.

use rapier_fvm::glamx::DVec3;

/// Where the camera looks from, relative to the box centre (m, any length).
const VIEW_FROM: DVec3 = DVec3::new(0.9, 0.9, 1.6);
/// Fraction of the picture left free on each side of the framed box.
const MARGIN: f64 = 0.08;
/// Fraction of the picture's width kept free on the right for the legend.
const LEGEND_SHARE: f64 = 0.2;

/// Maps world points (m) to pixels of a `width` × `height` picture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Unit vector from the scene towards the camera.
    toward_eye: DVec3,
    /// Unit vectors of the picture's right and up directions in the world.
    right: DVec3,
    up: DVec3,
    /// The world point at the picture's centre (m).
    center: DVec3,
    /// Pixels per metre.
    scale: f64,
    /// The pixel the centre is drawn at.
    center_pixel: (f64, f64),
    /// Picture size (pixels).
    width: u32,
    height: u32,
}

impl Camera {
    /// The oblique camera that frames the box `min`..`max` (m) in a `width` × `height` picture
    /// (pixels). Use one box for a whole series, e.g. the union of [`Snapshot::bounds`] over its
    /// frames, so the view does not jump.
    ///
    /// [`Snapshot::bounds`]: super::Snapshot::bounds
    pub fn oblique(min: DVec3, max: DVec3, width: u32, height: u32) -> Self {
        let toward_eye = VIEW_FROM.normalize();
        let right = DVec3::Y.cross(toward_eye).normalize();
        Self::framing(toward_eye, right, (min, max), (width, height))
    }

    /// The camera looking at the plane z = 0 from the front (x to the right, y up) that frames
    /// the box `min`..`max` (m) in a `width` × `height` picture (pixels): the view of 2D scenes.
    pub fn front(min: DVec3, max: DVec3, width: u32, height: u32) -> Self {
        Self::framing(DVec3::Z, DVec3::X, (min, max), (width, height))
    }

    /// The camera looking along `-toward_eye` with `right` to the right that frames the box
    /// `min`..`max` (m) in a `width` × `height` picture.
    fn framing(
        toward_eye: DVec3,
        right: DVec3,
        (min, max): (DVec3, DVec3),
        (width, height): (u32, u32),
    ) -> Self {
        let up = toward_eye.cross(right);
        let corners = (0..8).map(|i| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        });
        let (lo, hi) = corners.fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), corner| {
                let p = DVec3::new(corner.dot(right), corner.dot(up), 0.0);
                (lo.min(p), hi.max(p))
            },
        );
        let extent = (hi - lo).max(DVec3::splat(1e-6));
        let usable = 1.0 - 2.0 * MARGIN;
        let scene_width = f64::from(width) * (1.0 - LEGEND_SHARE);
        let scale = (scene_width * usable / extent.x).min(f64::from(height) * usable / extent.y);
        let mid = (lo + hi) * 0.5;
        Self {
            toward_eye,
            right,
            up,
            center: right * mid.x + up * mid.y + toward_eye * (min + max).dot(toward_eye) * 0.5,
            scale,
            center_pixel: (0.5 * scene_width, 0.5 * f64::from(height)),
            width,
            height,
        }
    }

    /// Picture size (pixels).
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Unit vector from the scene towards the camera (for shading).
    pub fn toward_eye(&self) -> DVec3 {
        self.toward_eye
    }

    /// The pixel coordinates of world point `p` (m), x to the right and y down from the top left
    /// corner, and its depth (m, larger is farther from the camera).
    pub fn project(&self, p: DVec3) -> DVec3 {
        let d = p - self.center;
        DVec3::new(
            self.center_pixel.0 + d.dot(self.right) * self.scale,
            self.center_pixel.1 - d.dot(self.up) * self.scale,
            -d.dot(self.toward_eye),
        )
    }
}

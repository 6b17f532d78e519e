//! The output folder of a run: ParaView and OBJ frames as they are saved, then the pictures
//! and the probe plots.

use super::report::Files;
use crate::output::{
    Camera, Coloring, OutputError, ParaViewSeries, Snapshot, TimeSeries, file_stem, plot_series,
    render_png, write_obj,
};
use crate::scene::settings::OutputSpec;
use rapier_fvm::glamx::DVec3;
use std::path::{Path, PathBuf};

/// Size of the plots (pixels).
const PLOT_SIZE: (u32, u32) = (900, 500);

/// Where the pictures look from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum View {
    /// [`Camera::oblique`], for 3D scenes.
    Oblique,
    /// [`Camera::front`], for 2D scenes.
    Front,
}

/// Writes a run's output folder.
pub(crate) struct Writer {
    view: View,
    out: PathBuf,
    series: ParaViewSeries,
    files: Files,
    /// Frames between saved frames, the last frame, the frame step (s).
    save_every: usize,
    frames: usize,
    dt: f64,
    /// Half size of a half-space's drawn patch (m).
    patch: f64,
    /// The frames pictured, and their snapshots once taken.
    picture_frames: Vec<usize>,
    pictured: Vec<(usize, Snapshot)>,
    /// The box (m) around everything saved or pictured, for the camera.
    bounds: Option<(DVec3, DVec3)>,
    picture_size: [u32; 2],
}

impl Writer {
    /// A writer into `out` for `frames` frames of `dt` (s) of the scene `name` with output
    /// settings `output`, pictured from `view`; removes the files an earlier run left there.
    pub(crate) fn new(
        (name, output): (&str, &OutputSpec),
        out: &Path,
        (frames, dt): (usize, f64),
        view: View,
    ) -> Result<Self, OutputError> {
        for (dir, extension) in [
            ("paraview", "vtu"),
            ("paraview", "pvd"),
            ("obj", "obj"),
            ("pictures", "png"),
            ("plots", "png"),
        ] {
            clear(&out.join(dir), extension)?;
        }
        let series = ParaViewSeries::new(out.join("paraview"), name)?;
        let files = Files {
            pvd: relative(out, &series.pvd_path()),
            ..Files::default()
        };
        Ok(Self {
            view,
            out: out.to_path_buf(),
            series,
            files,
            save_every: output.save_every,
            frames,
            dt,
            patch: output.ground_patch,
            picture_frames: picture_frames(output, frames, dt),
            pictured: Vec::new(),
            bounds: None,
            picture_size: output.picture_size,
        })
    }

    /// Saves frame `frame` if it is a saved or pictured frame, as `capture(time (s), patch
    /// half size (m))` gives it (called only then).
    pub(crate) fn frame(
        &mut self,
        frame: usize,
        capture: impl FnOnce(f64, f64) -> Snapshot,
    ) -> Result<(), OutputError> {
        let saved = frame.is_multiple_of(self.save_every) || frame == self.frames;
        let pictured = self.picture_frames.contains(&frame);
        if !(saved || pictured) {
            return Ok(());
        }
        let snapshot = capture(frame as f64 * self.dt, self.patch);
        if let Some((lo, hi)) = snapshot.bounds() {
            self.bounds = Some(
                self.bounds
                    .map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))),
            );
        }
        if saved {
            self.files.vtu_count += self.series.write_frame(&snapshot)?.len();
            let obj = self.out.join("obj").join(format!("surface_{frame:05}.obj"));
            write_obj(&obj, &snapshot)?;
            self.files.obj.push(relative(&self.out, &obj));
        }
        if pictured {
            self.pictured.push((frame, snapshot));
        }
        Ok(())
    }

    /// Renders the pictures and plots `probes`; returns the files written.
    pub(crate) fn finish<'a>(
        mut self,
        probes: impl IntoIterator<Item = &'a TimeSeries>,
    ) -> Result<Files, OutputError> {
        let (lo, hi) = self.bounds.unwrap_or_default();
        self.files.pictures = render_pictures(
            &self.out,
            &self.pictured,
            (lo, hi),
            self.picture_size,
            self.dt,
            self.view,
        )?;
        for series in probes {
            let name = format!("{}.png", file_stem(&series.name));
            let path = self.out.join("plots").join(name);
            plot_series(&path, series, PLOT_SIZE)?;
            self.files.plots.push(relative(&self.out, &path));
        }
        Ok(self.files)
    }
}

/// The frames whose views are rendered: those nearest the scene's picture times, or the start,
/// a third, two thirds and the end.
fn picture_frames(output: &OutputSpec, frames: usize, dt: f64) -> Vec<usize> {
    let mut chosen: Vec<usize> = match &output.pictures {
        Some(times) => times
            .iter()
            .map(|t| ((t / dt).round().max(0.0) as usize).min(frames))
            .collect(),
        None => vec![0, frames / 3, 2 * frames / 3, frames],
    };
    chosen.sort_unstable();
    chosen.dedup();
    chosen
}

/// Renders each pictured frame by material and by stress from one camera framing the box
/// `lo`..`hi` (m); returns `(time (s), file)` of each picture.
fn render_pictures(
    out: &Path,
    pictured: &[(usize, Snapshot)],
    (lo, hi): (DVec3, DVec3),
    [width, height]: [u32; 2],
    dt: f64,
    view: View,
) -> Result<Vec<(f64, String)>, OutputError> {
    let camera = match view {
        View::Oblique => Camera::oblique(lo, hi, width, height),
        View::Front => Camera::front(lo, hi, width, height),
    };
    let max_stress = pictured
        .iter()
        .map(|(_, s)| stress_scale(s))
        .fold(1.0, f64::max);
    let mut written = Vec::new();
    for (frame, snapshot) in pictured {
        let time = *frame as f64 * dt;
        for (prefix, coloring) in [
            ("view", Coloring::Material),
            ("stress", Coloring::VonMises { max: max_stress }),
        ] {
            let path = out
                .join("pictures")
                .join(format!("{prefix}_{frame:05}.png"));
            render_png(&path, snapshot, &camera, coloring)?;
            written.push((time, relative(out, &path)));
        }
    }
    Ok(written)
}

/// The top of the stress colour scale (Pa) for a snapshot: each soft body's 95th percentile of
/// nodal von Mises stress (so that a few peak nodes at a contact corner do not leave the rest in
/// the bottom colour), and the median of these over the bodies (so that one body far more
/// stressed than the others, a taut rope, does not leave them all in the bottom colour: it shows
/// in the top colour instead).
fn stress_scale(snapshot: &Snapshot) -> f64 {
    let mut per_body: Vec<f64> = (snapshot.soft_bodies.iter())
        .map(|body| {
            let mut values: Vec<f64> = (body.nodal_von_mises().into_iter())
                .filter(|v| v.is_finite())
                .collect();
            values.sort_by(f64::total_cmp);
            values.get(values.len() * 95 / 100).copied().unwrap_or(0.0)
        })
        .collect();
    per_body.sort_by(f64::total_cmp);
    per_body.get(per_body.len() / 2).copied().unwrap_or(0.0)
}

/// Creates the folder `dir` if needed and removes the files with `extension` an earlier run
/// left in it, so that the folder holds only this run's output.
fn clear(dir: &Path, extension: &str) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(OutputError::io(dir))?;
    let entries = std::fs::read_dir(dir).map_err(OutputError::io(dir))?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_file() && path.extension().is_some_and(|e| e == extension) {
            std::fs::remove_file(&path).map_err(OutputError::io(&path))?;
        }
    }
    Ok(())
}

/// `path` relative to `out`, with `/` separators.
fn relative(out: &Path, path: &Path) -> String {
    path.strip_prefix(out)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

//! The writers of the runner's output folder, each reading only a [`Snapshot`] (or a
//! [`TimeSeries`] for plots): ParaView series, OBJ surfaces, rendered pictures and plots.

mod camera;
mod error;
mod font;
mod obj;
mod paraview;
mod plot;
mod raster;
mod render;
mod rigid_mesh;
mod snapshot;

pub use camera::Camera;
pub use error::OutputError;
pub use obj::write_obj;
pub use paraview::ParaViewSeries;
pub use plot::{TimeSeries, plot_series};
pub use render::{Coloring, render_png};
pub use snapshot::{Cells, RigidBodySnapshot, Snapshot, SoftBodySnapshot};

/// `name` made safe as a file name and an OBJ object name: ASCII letters, digits, `-` and `_`
/// kept, anything else replaced by `_`; `body` if nothing is left.
pub(crate) fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() {
        String::from("body")
    } else {
        stem
    }
}

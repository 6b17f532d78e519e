//! # `rapier_fvm_runner`
//!
//! The output side of the headless runner for [`rapier_fvm`] scenes, in its own crate so that
//! users of the library do not build the plotting and file-format dependencies.
//!
//! Each saved frame, the runner fills a [`output::Snapshot`] (plain data: positions, velocities,
//! tetrahedra, surfaces and stresses of the soft bodies, world-space triangle meshes of the rigid
//! bodies) and hands it to the writers:
//! - [`output::ParaViewSeries`]: a `.vtu` per soft body per frame and a `.pvd` index (ParaView);
//! - [`output::write_obj`]: the surfaces of every body as one OBJ file per frame (Blender);
//! - [`output::render_png`]: a shaded picture from a fixed oblique [`output::Camera`], with no
//!   display or GPU (a software z-buffer);
//! - [`output::plot_series`]: a probe's value against time as a PNG line plot.
//!
//! All lengths are in m, times in s, velocities in m/s and stresses in Pa.

pub mod output;

//! # `rapier_fvm_runner`
//!
//! The headless runner for [`rapier_fvm`] scenes, in its own crate so that users of the library
//! do not build the command line, the scene format and the plotting and file-format
//! dependencies. The binary `rapier-fvm` (`src/main.rs`) is a thin layer over these modules:
//! - [`scene`]: the TOML scene format, read and checked with errors that name the file, the
//!   line and the key;
//! - [`sim`]: a scene built into an [`rapier_fvm::world::FvmWorld`] and run frame by frame,
//!   with its probes sampled and its output written;
//! - [`output`]: the writers;
//! - [`planar`]: 2D scenes (`dimension = 2`), their runs and output through the same writers;
//! - [`advise`]: a cheaper scene within a target error of the scene as written.
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

pub mod advise;
pub mod calibrate;
pub mod output;
pub mod planar;
pub mod scene;
pub mod sim;

//! 2D scenes: soft bodies on triangles ([`rapier_fvm::planar`]) in plane stress or plane strain,
//! coupled with rapier2d's rigid bodies, read from a scene file whose `[world]` has
//! `dimension = 2` ([`scene`]), run frame by frame ([`run_planar`]) and written as 3D scenes
//! are: a ParaView series of triangles (at z = 0), OBJ surfaces, pictures from the front (by
//! material and by von Mises stress, `σ₃₃` included), a plot per probe ([`probe`]) and
//! `report.json` ([`PlanarReport`]).

mod build;
pub mod probe;
mod run;
pub mod scene;

pub use build::{PlanarRigidEntry, PlanarSimulation, PlanarSoftEntry};
pub use probe::{PlanarProbe, PlanarProbeSpec};
pub use run::{PlanarBodyReport, PlanarReport, run_planar};
pub use scene::PlanarScene;

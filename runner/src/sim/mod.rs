//! Running a scene: [`Simulation::build`] makes its world, [`run`] steps it frame by frame,
//! samples the probes after every frame, and writes the output folder:
//!
//! | file | what |
//! |---|---|
//! | `report.json` | the [`Report`]: settings used, sizes, timings, stability flags, probes |
//! | `paraview/<scene>.pvd`, `paraview/<body>_<n>.vtu` | ParaView series of the saved frames |
//! | `obj/surface_<n>.obj` | every body's surface per saved frame (Blender) |
//! | `pictures/view_<frame>.png`, `pictures/stress_<frame>.png` | rendered views by material and by von Mises stress |
//! | `plots/<probe>.png` | each probe against time |
//! | `plots/stepping_time_per_frame.png` | each frame's stepping wall time (ms) against time |

mod build;
mod cost;
mod frame_times;
mod loads;
mod materials;
mod meshes;
mod needs;
mod probe;
mod regions;
pub(crate) mod report;
mod run;
pub(crate) mod writer;

pub use build::{RigidEntry, Simulation, SoftEntry};
pub use loads::{DrivenLoad, LoadSchedule};
pub use needs::BodyNeeds;
pub use probe::Probe;
pub use report::{
    BodyFlags, Files, Flag, FrameTimes, ProbeReport, Report, RigidBodyReport, Settings,
    SoftBodyReport, Stability, StepParts,
};
pub use run::{RunError, RunOptions, run, run_within};

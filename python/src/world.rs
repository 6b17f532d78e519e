//! `World`: rapier's rigid bodies and the crate's soft bodies stepped together frame by frame
//! (the library's `FvmWorld`), built body by body or read from a scene file, saved and restored
//! bit for bit.
//!
//! A frame of a world read from a scene is the runner's frame: kinematic bodies and keyframed
//! loads driven to the frame's end time, one `FvmWorld::step`, the scene's probes sampled, so
//! a scene stepped from Python follows `rapier-fvm run`'s trajectory to the bit.

use crate::errors::{Error, argument};
use pyo3::prelude::*;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::world::FvmWorld;
use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::Simulation;

/// Rigid and soft bodies in one world: `World(dt=1/60, gravity=(0, -9.81, 0))`.
///
/// `dt` is the frame step (s), `gravity` the acceleration of gravity (m/s²) on every body.
/// `step()` advances one frame with the GIL released.
#[pyclass(module = "rapier_fvm")]
pub struct World {
    /// The world and, for a world read from a scene, its bodies' names and probes.
    pub sim: Simulation,
    /// The scene the world was read from, if any (its keyframes drive the world).
    pub scene: Option<Scene>,
    /// The frames stepped so far.
    pub frame: u64,
    /// The frame step (s).
    pub dt: f64,
}

impl World {
    /// A world of no body, stepping frames of `dt` (s) under `gravity` (m/s²).
    pub fn empty(dt: f64, gravity: DVec3) -> Self {
        let mut world = FvmWorld::default();
        world.physics.gravity = gravity.as_vec3();
        world.physics.integration_parameters.dt = dt as f32;
        let sim = Simulation {
            world,
            soft: Vec::new(),
            rigid: Vec::new(),
            probes: Vec::new(),
        };
        Self {
            sim,
            scene: None,
            frame: 0,
            dt,
        }
    }

    /// Advances one frame; the first body whose step failed (it kept its state) as an error.
    fn advance(&mut self) -> PyResult<()> {
        let t = (self.frame + 1) as f64 * self.dt;
        if let Some(scene) = &self.scene {
            self.sim.drive_kinematic(t);
            (self.sim.drive_loads(t, &scene.source)).map_err(crate::errors::scene)?;
        }
        let outcomes = self.sim.world.step();
        self.frame += 1;
        if self.scene.is_some() {
            self.sim.sample_probes(t);
        }
        for (handle, outcome) in outcomes {
            if let Err(error) = outcome {
                let name = match self.sim.soft.iter().find(|s| s.handle == handle) {
                    Some(entry) => format!("soft body {:?}", entry.name),
                    None => format!("{:?}", crate::handles::SoftBody::of(handle)),
                };
                return Err(Error::new_err(format!(
                    "frame {}: the step of {name} failed and it kept its state: {error}",
                    self.frame
                )));
            }
        }
        Ok(())
    }
}

#[pymethods]
impl World {
    #[new]
    #[pyo3(signature = (dt = 1.0 / 60.0, gravity = [0.0, -9.81, 0.0]))]
    fn new(dt: f64, gravity: [f64; 3]) -> PyResult<Self> {
        let single = crate::arrays::scalar_f32("dt", dt)?;
        if !(dt > 0.0 && single > 0.0) {
            return Err(argument(
                "dt",
                format!("must be positive (s), also in float32 as rapier holds it, got {dt}"),
            ));
        }
        let gravity = crate::arrays::vector3_f32("gravity", gravity)?;
        Ok(Self::empty(dt, gravity.as_dvec3()))
    }

    /// Advances the world by `frames` frames of `dt` (s each), with the GIL released.
    ///
    /// Raises `rapier_fvm.Error` after the first frame in which a soft body's step failed
    /// (that body kept its state; the others and the rigid bodies moved on). Signals (Ctrl-C)
    /// are handled between frames. While it steps, another thread's call on the same world
    /// raises `RuntimeError` (the world is borrowed); other worlds step in parallel.
    #[pyo3(signature = (frames = 1))]
    fn step(&mut self, py: Python<'_>, frames: u64) -> PyResult<()> {
        for _ in 0..frames {
            py.detach(|| self.advance())?;
            // Ctrl-C (or another signal's handler) stops a long run between frames.
            py.check_signals()?;
        }
        Ok(())
    }

    /// The simulated time (s): frames stepped times `dt`.
    #[getter]
    fn time(&self) -> f64 {
        self.frame as f64 * self.dt
    }

    /// The frames stepped so far.
    #[getter]
    fn frame(&self) -> u64 {
        self.frame
    }

    /// The frame step (s) as given; rapier holds it in float32 (1/60 s as 0.016666668 s), and
    /// that is the step the bodies take.
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The number of rapier steps (coupling substeps) per frame.
    #[getter]
    fn coupling_substeps(&self) -> u32 {
        self.sim.world.coupling.substeps
    }

    #[setter]
    fn set_coupling_substeps(&mut self, substeps: u32) -> PyResult<()> {
        if substeps == 0 {
            return Err(argument("coupling_substeps", "must be at least 1"));
        }
        self.sim.world.coupling.substeps = substeps;
        Ok(())
    }

    fn __repr__(&self) -> String {
        format!(
            "World({} soft bodies, {} rigid bodies, t = {} s)",
            self.sim.world.soft_bodies.len(),
            self.sim.world.physics.bodies.len(),
            self.time()
        )
    }
}

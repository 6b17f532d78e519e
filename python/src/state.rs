//! A world's state: saved as bytes and restored bit for bit (resets, rollouts), and pickled
//! (to hand a world to another process: a process pool's or a Ray worker's).
//!
//! The bytes are CBOR (the format the library's serialization is tested with; rapier's state
//! holds infinities, which JSON cannot carry) of the frame count and the whole `FvmWorld`:
//! rigid and soft bodies, contacts, attachments, sleep and solver caches. A pickle adds the frame
//! step, the scene the world was read from (its path and text: its keyframes drive the world,
//! and its mesh files are read again where the pickle is loaded) and the probes' samples.

use crate::errors::{Error, argument, scene as scene_error};
use crate::world::World;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::world::FvmWorld;
use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::Simulation;
use std::path::PathBuf;

/// The scene a pickled world was read from: its path and text.
type PickledScene = Option<(PathBuf, String)>;
/// Each probe's `(time (s), value)` samples, in scene order.
type ProbeSamples = Vec<Vec<(f64, f64)>>;

impl World {
    /// The world's state as CBOR bytes: the frame count and the whole `FvmWorld`.
    fn state_bytes(&self) -> PyResult<Vec<u8>> {
        let mut bytes = Vec::new();
        ciborium::into_writer(&(self.frame, &self.sim.world), &mut bytes)
            .map_err(|e| Error::new_err(format!("the world could not be saved: {e}")))?;
        Ok(bytes)
    }

    /// Puts back the state `bytes` of [`World::state_bytes`]; the probes keep their samples up
    /// to the restored frame.
    fn restore_bytes(&mut self, bytes: &[u8]) -> PyResult<()> {
        let (frame, world): (u64, FvmWorld) = ciborium::from_reader(bytes)
            .map_err(|e| argument("state", format!("not a saved world: {e}")))?;
        let names_kept = (self.sim.soft.iter()).all(|s| world.soft_bodies.contains(s.handle))
            && (self.sim.rigid.iter()).all(|r| world.physics.bodies.contains(r.handle));
        if !names_kept {
            return Err(argument(
                "state",
                "saved from another scene: its bodies are not this world's",
            ));
        }
        self.sim.world = world;
        self.frame = frame;
        for probe in &mut self.sim.probes {
            probe.series.samples.truncate(frame as usize + 1);
        }
        Ok(())
    }
}

#[pymethods]
impl World {
    /// The world's whole state (rigid and soft bodies, contacts, solver caches, frame count)
    /// as bytes; `restore` puts it back and the run then goes on bit for bit as it did.
    fn save<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        Ok(PyBytes::new(py, &self.state_bytes()?))
    }

    /// Puts back a state from `save` of this world (or of a world built the same way).
    fn restore(&mut self, state: &[u8]) -> PyResult<()> {
        self.restore_bytes(state)
    }

    /// Pickling: the world rebuilt by `_unpickle_world` from its frame step, scene, state and
    /// probes' samples.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let rebuild = py
            .import("rapier_fvm._native")?
            .getattr("_unpickle_world")?;
        let scene: PickledScene =
            (self.scene.as_ref()).map(|s| (s.source.path.clone(), s.source.text.clone()));
        let samples: ProbeSamples = (self.sim.probes.iter())
            .map(|p| p.series.samples.clone())
            .collect();
        let state = PyBytes::new(py, &self.state_bytes()?);
        let args = (self.dt, scene, state, samples).into_pyobject(py)?;
        Ok((rebuild, args))
    }
}

/// A pickled world rebuilt (see [`World::__reduce__`]).
#[pyfunction]
pub fn _unpickle_world(
    dt: f64,
    scene: PickledScene,
    state: &[u8],
    samples: ProbeSamples,
) -> PyResult<World> {
    let mut world = match scene {
        None => World::empty(dt, DVec3::ZERO),
        Some((path, text)) => {
            let scene = Scene::parse(&path, text).map_err(scene_error)?;
            let sim = Simulation::build(&scene).map_err(scene_error)?;
            World {
                sim,
                scene: Some(scene),
                frame: 0,
                dt,
            }
        }
    };
    world.restore_bytes(state)?;
    for (probe, samples) in world.sim.probes.iter_mut().zip(samples) {
        probe.series.samples = samples;
    }
    Ok(world)
}

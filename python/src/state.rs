//! A world's state: saved as bytes and restored bit for bit (resets, rollouts), and pickled
//! (to hand a world to another process: a process pool's or a Ray worker's).
//!
//! The bytes are CBOR (the format the library's serialization is tested with; rapier's state
//! holds infinities, which JSON cannot carry) of a [`Saved`]: the frame count and step, the
//! probes' samples and the whole `FvmWorld` (rigid and soft bodies, contacts, attachments,
//! sleep and solver caches). A state is put back only into a world of the same bodies (handles,
//! and each soft body's node count), so that every handle the caller holds names the same body
//! after it. A pickle adds the scene the world was read from (its path and text: its
//! keyframes drive the world, and its mesh files are read again where the pickle is loaded).

use crate::errors::{Error, argument, scene as scene_error};
use crate::world::World;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use rapier_fvm::glamx::DVec3;
use rapier_fvm::world::FvmWorld;
use rapier_fvm_runner::scene::Scene;
use rapier_fvm_runner::sim::Simulation;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The scene a pickled world was read from: its path and text.
type PickledScene = Option<(PathBuf, String)>;

/// A world's state as saved (`W` the world, borrowed to save and owned when read).
#[derive(Serialize, Deserialize)]
struct Saved<W> {
    /// Frames stepped.
    frame: u64,
    /// The frame step (s).
    dt: f64,
    /// Each probe's `(time (s), value)` samples, in scene order.
    probes: Vec<Vec<(f64, f64)>>,
    /// The world.
    world: W,
}

/// A world's bodies, to compare two worlds: each soft body's handle (raw parts) and node
/// count, each rigid body's handle.
#[derive(Serialize, Deserialize, PartialEq, Debug)]
struct Bodies {
    soft: Vec<((u32, u32), usize)>,
    rigid: Vec<(u32, u32)>,
}

impl Bodies {
    /// The bodies of `world`.
    fn of(world: &FvmWorld) -> Self {
        Self {
            soft: (world.soft_bodies.iter())
                .map(|(h, b)| (h.into_raw_parts(), b.node_count()))
                .collect(),
            rigid: (world.physics.bodies.iter())
                .map(|(h, _)| h.into_raw_parts())
                .collect(),
        }
    }
}

impl World {
    /// The world's state as CBOR bytes (a [`Saved`]).
    fn state_bytes(&self) -> PyResult<Vec<u8>> {
        let saved = Saved {
            frame: self.frame,
            dt: self.dt,
            probes: (self.sim.probes.iter())
                .map(|p| p.series.samples.clone())
                .collect(),
            world: &self.sim.world,
        };
        let mut bytes = Vec::new();
        ciborium::into_writer(&saved, &mut bytes)
            .map_err(|e| Error::new_err(format!("the world could not be saved: {e}")))?;
        Ok(bytes)
    }

    /// Puts back the state `bytes` of [`World::state_bytes`], if it is a state of a world of
    /// the same bodies and probes.
    fn restore_bytes(&mut self, bytes: &[u8]) -> PyResult<()> {
        let saved = read_saved(bytes)?;
        self.check_same_bodies(&saved)?;
        self.put_back(saved);
        Ok(())
    }

    /// Whether `saved` is a state of a world of this world's bodies and probes.
    fn check_same_bodies(&self, saved: &Saved<FvmWorld>) -> PyResult<()> {
        if Bodies::of(&saved.world) != Bodies::of(&self.sim.world) {
            return Err(argument(
                "state",
                "saved from a world of other bodies: this world's handles would name other \
                 bodies in it",
            ));
        }
        if saved.probes.len() != self.sim.probes.len() {
            return Err(argument(
                "state",
                format!(
                    "saved from a world of {} probes, this one has {}",
                    saved.probes.len(),
                    self.sim.probes.len()
                ),
            ));
        }
        Ok(())
    }

    /// Takes the world, frame, step and probes' samples of `saved`.
    fn put_back(&mut self, saved: Saved<FvmWorld>) {
        for (probe, samples) in self.sim.probes.iter_mut().zip(saved.probes) {
            probe.series.samples = samples;
        }
        self.sim.world = saved.world;
        self.frame = saved.frame;
        self.dt = saved.dt;
    }
}

/// The state in `bytes` (of [`World::state_bytes`]).
fn read_saved(bytes: &[u8]) -> PyResult<Saved<FvmWorld>> {
    ciborium::from_reader(bytes).map_err(|e| argument("state", format!("not a saved world: {e}")))
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

    /// Pickling: the world rebuilt by `_unpickle_world` from its scene and state.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let rebuild = py
            .import("rapier_fvm._native")?
            .getattr("_unpickle_world")?;
        let scene: PickledScene =
            (self.scene.as_ref()).map(|s| (s.source.path.clone(), s.source.text.clone()));
        let state = PyBytes::new(py, &self.state_bytes()?);
        let args = (scene, state).into_pyobject(py)?;
        Ok((rebuild, args))
    }
}

/// A pickled world rebuilt (see [`World::__reduce__`]): its scene's world given its state, or
/// a world made of the state alone.
#[pyfunction]
pub fn _unpickle_world(scene: PickledScene, state: &[u8]) -> PyResult<World> {
    let saved = read_saved(state)?;
    let mut world = match scene {
        None => World::empty(saved.dt, DVec3::ZERO),
        Some((path, text)) => {
            let scene = Scene::parse(&path, text).map_err(scene_error)?;
            let sim = Simulation::build(&scene).map_err(scene_error)?;
            let world = World {
                sim,
                scene: Some(scene),
                frame: 0,
                dt: saved.dt,
            };
            world.check_same_bodies(&saved)?;
            world
        }
    };
    world.put_back(saved);
    Ok(world)
}

//! A world's soft bodies from Python: added from a mesh and a material, glued to rigid bodies,
//! read as arrays (positions, velocities, surface, stresses, contact forces, energies) and
//! driven as a controller does (node positions and velocities, pins moved, loads set).

use crate::arrays::{rows_out, vector_out, vector3, vectors_in, vectors_out};
use crate::errors::{argument, library, unknown};
use crate::handles::{Collider, RigidBody, SoftBody};
use crate::model::{Material, Mesh};
use crate::world::World;
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rapier_fvm::body::{DeformableBody, DeformableBodyBuilder};
use rapier_fvm::damping::RayleighDamping;
use rapier_fvm::glamx::DVec3;

impl World {
    /// The soft body `body`, or a `KeyError`.
    pub fn soft(&self, body: SoftBody) -> PyResult<&DeformableBody> {
        (self.sim.world.soft_bodies.get(body.handle())).ok_or_else(|| unknown("soft body", body))
    }

    /// The soft body `body`, mutable, or a `KeyError`.
    pub fn soft_mut(&mut self, body: SoftBody) -> PyResult<&mut DeformableBody> {
        (self.sim.world.soft_bodies.get_mut(body.handle()))
            .ok_or_else(|| unknown("soft body", body))
    }
}

/// Node indices given from Python, each below `count` (argument `name`).
fn node_indices(name: &str, nodes: &[i64], count: usize) -> PyResult<Vec<u32>> {
    (nodes.iter())
        .map(|&n| match u32::try_from(n) {
            Ok(node) if (node as usize) < count => Ok(node),
            _ => Err(argument(name, format!("node {n} is not one of 0..{count}"))),
        })
        .collect()
}

#[pymethods]
impl World {
    /// Adds a soft body of `mesh` and `material`, placed by `translation` (m) and `rotation`
    /// (a scaled axis, rad), moving at `linvel` (m/s) and spinning at `angvel` (rad/s) about its
    /// centre of mass; `stiffness_time` is the stiffness-proportional Rayleigh damping's time
    /// constant β (s; the viscosities are β λ and β μ; a scene's `damping.stiffness_time`),
    /// `pinned` node indices held in place (move them with `set_positions`), `friction` its Coulomb
    /// coefficient (default the library's), `self_contact` whether it collides with itself,
    /// `rigid_stand_in` the strain tolerance below which it may step as a rapier rigid body
    /// (a scene's `rigid_stand_in`; default none).
    #[pyo3(signature = (mesh, material, *, translation = [0.0; 3], rotation = [0.0; 3],
        linvel = [0.0; 3], angvel = [0.0; 3], stiffness_time = None, pinned = Vec::new(),
        friction = None, self_contact = false, rigid_stand_in = None))]
    #[allow(clippy::too_many_arguments)]
    fn add_soft_body(
        &mut self,
        mesh: &Mesh,
        material: &Material,
        translation: [f64; 3],
        rotation: [f64; 3],
        linvel: [f64; 3],
        angvel: [f64; 3],
        stiffness_time: Option<f64>,
        pinned: Vec<i64>,
        friction: Option<f64>,
        self_contact: bool,
        rigid_stand_in: Option<f64>,
    ) -> PyResult<SoftBody> {
        let pinned = node_indices("pinned", &pinned, mesh.inner.node_count())?;
        let mut builder = DeformableBodyBuilder::new(mesh.inner.clone(), material.inner)
            .translation(vector3("translation", translation)?)
            .rotation(vector3("rotation", rotation)?)
            .linvel(vector3("linvel", linvel)?)
            .angvel(vector3("angvel", angvel)?)
            .pinned_nodes(pinned)
            .self_contact(self_contact);
        if let Some(beta) = stiffness_time {
            let lame = material.inner.lame();
            builder = builder
                .damping(RayleighDamping::stiffness_proportional(beta, lame).map_err(library)?);
        }
        if let Some(friction) = friction {
            builder = builder.friction(friction);
        }
        if let Some(tolerance) = rigid_stand_in {
            builder = builder.rigid_stand_in(tolerance);
        }
        let body = builder.build().map_err(library)?;
        Ok(SoftBody::of(self.sim.world.soft_bodies.insert(body)))
    }

    /// Whether `soft` stands in as a rapier rigid body now (see `add_soft_body`'s
    /// `rigid_stand_in`).
    fn stands_in(&self, soft: SoftBody) -> PyResult<bool> {
        self.soft(soft)?;
        Ok(self
            .sim
            .world
            .coupling
            .rigid_stand_in_of(soft.handle())
            .is_some())
    }

    /// Glues the nodes `nodes` of `soft` to the rigid body `rigid` where they are now.
    fn attach(&mut self, soft: SoftBody, nodes: Vec<i64>, rigid: RigidBody) -> PyResult<()> {
        let nodes = node_indices("nodes", &nodes, self.soft(soft)?.node_count())?;
        (self.sim.world.attach(soft.handle(), nodes, rigid.handle())).map_err(library)
    }

    /// The soft bodies, in the order of their handles.
    #[getter]
    fn soft_bodies(&self) -> Vec<SoftBody> {
        (self.sim.world.soft_bodies.iter())
            .map(|(handle, _)| SoftBody::of(handle))
            .collect()
    }

    /// The node positions of `body`, an `(n, 3)` array (m).
    fn positions<'py>(
        &self,
        py: Python<'py>,
        body: SoftBody,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(vectors_out(py, self.soft(body)?.positions()))
    }

    /// The node velocities of `body`, an `(n, 3)` array (m/s).
    fn velocities<'py>(
        &self,
        py: Python<'py>,
        body: SoftBody,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(vectors_out(py, self.soft(body)?.velocities()))
    }

    /// The lumped node masses of `body`, an `(n,)` array (kg).
    fn masses<'py>(&self, py: Python<'py>, body: SoftBody) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vector_out(py, self.soft(body)?.masses().to_vec()))
    }

    /// The boundary triangles of `body`, an `(k, 3)` uint32 array of node indices oriented out
    /// of the body.
    fn surface_triangles<'py>(
        &self,
        py: Python<'py>,
        body: SoftBody,
    ) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let triangles = self.soft(body)?.mesh().surface_triangles();
        Ok(rows_out(py, triangles.into_iter().flatten().collect(), 3))
    }

    /// The tetrahedra of `body`, an `(m, 4)` uint32 array of node indices.
    fn tets<'py>(&self, py: Python<'py>, body: SoftBody) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let tets = self.soft(body)?.mesh().tets();
        Ok(rows_out(py, tets.iter().flatten().copied().collect(), 4))
    }

    /// The Cauchy stress of each element of `body`, an `(m, 3, 3)` array (Pa), elastic part.
    fn stresses<'py>(
        &self,
        py: Python<'py>,
        body: SoftBody,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let stresses = self.soft(body)?.cauchy_stresses();
        let flat: Vec<f64> = (stresses.iter())
            .flat_map(|s| s.transpose().to_cols_array())
            .collect();
        let array = numpy::ndarray::Array3::from_shape_vec((stresses.len(), 3, 3), flat)
            .expect("nine values per element by construction");
        Ok(numpy::IntoPyArray::into_pyarray(array, py))
    }

    /// The force (N) and torque about the world origin (N m) the contacts of `soft` exerted on
    /// `collider` over its last step.
    fn contact_force(&self, soft: SoftBody, collider: Collider) -> PyResult<([f64; 3], [f64; 3])> {
        self.soft(soft)?;
        if !self.sim.world.physics.colliders.contains(collider.handle()) {
            return Err(unknown("collider", collider));
        }
        let (force, torque) = (self.sim.world)
            .contact_force_on(soft.handle(), collider.handle())
            .map_err(library)?;
        Ok((force.to_array(), torque.to_array()))
    }

    /// The force (N) and torque about the world origin (N m) `soft` exerted on the rigid body
    /// `rigid` over the last frame, through contacts and glue.
    fn load_on(&self, soft: SoftBody, rigid: RigidBody) -> PyResult<([f64; 3], [f64; 3])> {
        self.soft(soft)?;
        self.rigid(rigid)?;
        let (force, torque) = self.sim.world.load_on(soft.handle(), rigid.handle());
        Ok((force.to_array(), torque.to_array()))
    }

    /// Sets the positions (m) of `body`'s nodes `nodes` (all nodes if `None`) from the rows of
    /// `positions`; pinned nodes move where they are set and stay there.
    #[pyo3(signature = (body, positions, nodes = None))]
    fn set_positions(
        &mut self,
        body: SoftBody,
        positions: &Bound<'_, PyAny>,
        nodes: Option<Vec<i64>>,
    ) -> PyResult<()> {
        let values = vectors_in("positions", positions)?;
        self.set_node_vectors(
            body,
            values,
            nodes,
            (DeformableBody::positions, DeformableBody::set_positions),
        )
    }

    /// Sets the velocities (m/s) of `body`'s nodes `nodes` (all if `None`) from the rows of
    /// `velocities`; a pinned node's velocity is refused.
    #[pyo3(signature = (body, velocities, nodes = None))]
    fn set_velocities(
        &mut self,
        body: SoftBody,
        velocities: &Bound<'_, PyAny>,
        nodes: Option<Vec<i64>>,
    ) -> PyResult<()> {
        let values = vectors_in("velocities", velocities)?;
        self.set_node_vectors(
            body,
            values,
            nodes,
            (DeformableBody::velocities, DeformableBody::set_velocities),
        )
    }

    /// The kinetic energy (J), elastic energy (J), linear momentum (kg m/s), angular momentum
    /// about the world origin (kg m²/s) and centre of mass (m) of `body`, as a dict.
    fn measures<'py>(&self, py: Python<'py>, body: SoftBody) -> PyResult<Bound<'py, PyDict>> {
        let b = self.soft(body)?;
        let out = PyDict::new(py);
        out.set_item("kinetic_energy", b.kinetic_energy())?;
        out.set_item("elastic_energy", b.elastic_energy())?;
        for (name, v) in [
            ("linear_momentum", b.linear_momentum()),
            ("angular_momentum", b.angular_momentum()),
            ("center_of_mass", b.center_of_mass()),
        ] {
            out.set_item(name, vector_out(py, v.to_array().to_vec()))?;
        }
        Ok(out)
    }
}

impl World {
    /// Sets `values` on `body`'s nodes `nodes` (all if `None`): the body's `current` vectors
    /// with those rows replaced, handed whole to the checked setter `set`, so that a refused
    /// value leaves every node as it was.
    fn set_node_vectors(
        &mut self,
        body: SoftBody,
        values: Vec<DVec3>,
        nodes: Option<Vec<i64>>,
        (current, set): (NodeVectors, SetNodeVectors),
    ) -> PyResult<()> {
        let soft = self.soft_mut(body)?;
        let count = soft.node_count();
        let nodes = match nodes {
            Some(nodes) => node_indices("nodes", &nodes, count)?,
            None => (0..count as u32).collect(),
        };
        if nodes.len() != values.len() {
            return Err(argument(
                "nodes",
                format!("{} nodes for {} rows", nodes.len(), values.len()),
            ));
        }
        let mut all = current(soft).to_vec();
        for (node, value) in nodes.into_iter().zip(values) {
            all[node as usize] = value;
        }
        set(soft, &all).map_err(library)
    }
}

/// A body's node vectors (positions or velocities).
type NodeVectors = fn(&DeformableBody) -> &[DVec3];
/// A body's checked setter of its node vectors.
type SetNodeVectors = fn(&mut DeformableBody, &[DVec3]) -> Result<(), rapier_fvm::Error>;

//! A world's rigid bodies and colliders from Python: the ground and rigid bodies of any
//! `Shape` (fixed, dynamic or kinematic), their poses and velocities read, kinematic bodies
//! driven.
//!
//! rapier stores poses and velocities in `f32`; they are handed over as float64 arrays of
//! those values.

use crate::arrays::{rows_out, scalar_f32, vector3, vector3_f32};
use crate::errors::{argument, unknown};
use crate::handles::{Collider, RigidBody};
use crate::model::Shape;
use crate::world::World;
use numpy::PyArray2;
use pyo3::prelude::*;
use rapier_fvm::glamx::DQuat;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};

impl World {
    /// The rigid body `body` of rapier's set, or a `KeyError`.
    pub fn rigid(&self, body: RigidBody) -> PyResult<&rapier3d::dynamics::RigidBody> {
        (self.sim.world.physics.bodies.get(body.handle()))
            .ok_or_else(|| unknown("rigid body", body))
    }
}

/// A rigid body of kind `kind`, placed by `translation` (m) and `rotation` (scaled axis, rad),
/// moving at `linvel` (m/s) and `angvel` (rad/s).
fn body_builder(
    kind: &str,
    [translation, rotation, linvel, angvel]: [[f64; 3]; 4],
) -> PyResult<RigidBodyBuilder> {
    let builder = match kind {
        "dynamic" => RigidBodyBuilder::dynamic(),
        "fixed" => RigidBodyBuilder::fixed(),
        "kinematic" => RigidBodyBuilder::kinematic_position_based(),
        other => {
            return Err(argument(
                "kind",
                format!("{other:?} is not \"dynamic\", \"fixed\" or \"kinematic\""),
            ));
        }
    };
    Ok(builder
        .translation(vector3_f32("translation", translation)?)
        .rotation(vector3_f32("rotation", rotation)?)
        .linvel(vector3_f32("linvel", linvel)?)
        .angvel(vector3_f32("angvel", angvel)?))
}

/// A collider of `shape` and `density` (kg/m³), of positive mass in `f32`, with `friction`
/// and `restitution`.
fn collider_builder(
    shape: SharedShape,
    [density, friction, restitution]: [f64; 3],
) -> PyResult<ColliderBuilder> {
    let not_negative = |name: &str, value: f64| {
        let single = scalar_f32(name, value)?;
        if single >= 0.0 {
            Ok(single)
        } else {
            Err(argument(name, format!("must not be negative, got {value}")))
        }
    };
    let density_f32 = scalar_f32("density", density)?;
    let mass = shape.mass_properties(density_f32).mass();
    if !(density_f32 > 0.0 && mass.is_finite() && mass > 0.0) {
        return Err(argument(
            "density",
            format!(
                "{density} kg/m³ gives this shape a mass of {mass} kg in float32, not positive"
            ),
        ));
    }
    Ok(ColliderBuilder::new(shape)
        .density(density_f32)
        .friction(not_negative("friction", friction)?)
        .restitution(not_negative("restitution", restitution)?))
}

#[pymethods]
impl World {
    /// Adds the ground: a fixed half-space whose surface passes through `normal * height` (m),
    /// solid below it, with Coulomb friction `friction`.
    #[pyo3(signature = (*, height = 0.0, normal = [0.0, 1.0, 0.0], friction = 0.5))]
    fn add_ground(&mut self, height: f64, normal: [f64; 3], friction: f64) -> PyResult<Collider> {
        let normal = vector3("normal", normal)?;
        let largest = normal.abs().max_element();
        let normal = (normal / largest)
            .try_normalize()
            .ok_or_else(|| argument("normal", "must be a non-zero direction"))?;
        let height = scalar_f32("height", height)?;
        let friction = scalar_f32("friction", friction)?;
        if friction < 0.0 {
            return Err(argument(
                "friction",
                format!("must not be negative, got {friction}"),
            ));
        }
        let normal = normal.as_vec3();
        let collider = ColliderBuilder::new(SharedShape::halfspace(normal))
            .translation(normal * height)
            .friction(friction);
        Ok(Collider::of(
            self.sim.world.physics.insert_collider(collider, None),
        ))
    }

    /// Adds a rigid body of shape `shape` (a `Shape`): `kind` is `"dynamic"`, `"fixed"` or
    /// `"kinematic"`; placed by `translation` (m) and `rotation` (scaled axis, rad), moving at
    /// `linvel` (m/s) and `angvel` (rad/s), of density `density` (kg/m³), with Coulomb friction
    /// `friction` and restitution `restitution`.
    #[pyo3(signature = (shape, *, kind = "dynamic".to_owned(), translation = [0.0; 3],
        rotation = [0.0; 3], linvel = [0.0; 3], angvel = [0.0; 3], density = 1000.0,
        friction = 0.5, restitution = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn add_rigid_body(
        &mut self,
        shape: &Shape,
        kind: String,
        translation: [f64; 3],
        rotation: [f64; 3],
        linvel: [f64; 3],
        angvel: [f64; 3],
        density: f64,
        friction: f64,
        restitution: f64,
    ) -> PyResult<RigidBody> {
        let body = body_builder(&kind, [translation, rotation, linvel, angvel])?;
        let collider = collider_builder(shape.inner.clone(), [density, friction, restitution])?;
        Ok(RigidBody::of(
            self.sim.world.physics.insert(body, collider).0,
        ))
    }

    /// The rigid bodies, in the order of their handles (a soft body standing in as a rigid
    /// body is not one of them).
    #[getter]
    fn rigid_bodies(&self) -> Vec<RigidBody> {
        (self.sim.world.physics.bodies.iter())
            .filter(|(handle, _)| self.sim.world.coupling.stand_in_for(*handle).is_none())
            .map(|(handle, _)| RigidBody::of(handle))
            .collect()
    }

    /// The colliders of `body` (a rigid body's shapes, as `contact_force` takes them).
    fn colliders_of(&self, body: RigidBody) -> PyResult<Vec<Collider>> {
        Ok(self
            .rigid(body)?
            .colliders()
            .iter()
            .map(|c| Collider::of(*c))
            .collect())
    }

    /// The pose of `body`: its translation (m) and its rotation as a unit quaternion
    /// `(x, y, z, w)`.
    fn rigid_pose(&self, body: RigidBody) -> PyResult<([f64; 3], [f64; 4])> {
        let b = self.rigid(body)?;
        let q = b.rotation().as_dquat();
        Ok((b.translation().as_dvec3().to_array(), q.to_array()))
    }

    /// The linear (m/s) and angular (rad/s) velocity of `body`.
    fn rigid_velocity(&self, body: RigidBody) -> PyResult<([f64; 3], [f64; 3])> {
        let b = self.rigid(body)?;
        Ok((
            b.linvel().as_dvec3().to_array(),
            b.angvel().as_dvec3().to_array(),
        ))
    }

    /// Every rigid body's pose in the order of `rigid_bodies`: an `(n, 7)` array of the
    /// translation (m) then the rotation quaternion `(x, y, z, w)`.
    fn rigid_poses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let flat: Vec<f64> = (self.sim.world.physics.bodies.iter())
            .filter(|(handle, _)| self.sim.world.coupling.stand_in_for(*handle).is_none())
            .flat_map(|(_, b)| {
                let [x, y, z] = b.translation().as_dvec3().to_array();
                let [qx, qy, qz, qw] = b.rotation().as_dquat().to_array();
                [x, y, z, qx, qy, qz, qw]
            })
            .collect();
        rows_out(py, flat, 7)
    }

    /// Tells the kinematic body `body` where to be at the end of the next frame: `translation`
    /// (m) and, if given, `rotation` as a unit quaternion `(x, y, z, w)`; rapier moves it there
    /// over the frame and the soft bodies it touches feel it.
    #[pyo3(signature = (body, translation, rotation = None))]
    fn set_kinematic_target(
        &mut self,
        body: RigidBody,
        translation: [f64; 3],
        rotation: Option<[f64; 4]>,
    ) -> PyResult<()> {
        let translation = vector3_f32("translation", translation)?;
        let rotation = match rotation {
            None => None,
            Some(q) => {
                let q = DQuat::from_array(q);
                if !(q.is_finite() && (q.length() - 1.0).abs() < 1e-6) {
                    return Err(argument("rotation", format!("not a unit quaternion: {q}")));
                }
                Some(q)
            }
        };
        self.rigid(body)?;
        let b = &mut self.sim.world.physics.bodies[body.handle()];
        if !b.is_kinematic() {
            return Err(argument("body", format!("{body:?} is not kinematic")));
        }
        b.set_next_kinematic_translation(translation);
        if let Some(q) = rotation {
            b.set_next_kinematic_rotation(q.as_quat());
        }
        Ok(())
    }
}

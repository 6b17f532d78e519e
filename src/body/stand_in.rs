//! When a deformable body may stand in as a rapier rigid body ([`RigidStandIn`]): the contract
//! between a body and the coupling that switches it (`coupling::stand_in`).
//!
//! A stiff body whose strain stays below a tolerance `ε_tol` moves, to within that strain, as a
//! rigid body: the coupling then hands it to rapier as one (its nodes' mass, centre of mass and
//! inertia tensor, its convex hull as collider) and carries its nodes by the rigid pose, at a
//! rapier body's cost; it turns elastic again when the loads on it predict a strain above
//! `ε_tol`. Linear and angular momentum are kept across both switches.

use crate::Error;

/// A deformable body's permission to stand in as a rigid body while its strain (dimensionless)
/// stays below [`RigidStandIn::strain_tolerance`] (see [`crate::coupling::SoftCoupling`]'s
/// stand-ins).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct RigidStandIn {
    /// The largest strain (dimensionless, the Green strain's norm plus the vibration's
    /// `|v_def| / c`) the body may have when it turns rigid is half of this; it turns elastic
    /// again when its contacts' forces `F` (N) predict `F / (E V^(2/3))` above it.
    pub strain_tolerance: f64,
}

impl RigidStandIn {
    /// A stand-in below the strain `strain_tolerance`.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] unless `0 < strain_tolerance < 1`.
    pub fn new(strain_tolerance: f64) -> Result<Self, Error> {
        if !(strain_tolerance > 0.0 && strain_tolerance < 1.0) {
            return Err(Error::InvalidSetting {
                parameter: "rigid_stand_in",
                value: strain_tolerance,
                reason: "the strain tolerance must lie in (0, 1)",
            });
        }
        Ok(Self { strain_tolerance })
    }
}

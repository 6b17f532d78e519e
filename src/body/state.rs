//! Setting a body's nodal state from outside the integrators, checked, and the check every step
//! makes first.
//!
//! Contract: a body's state is steppable when every node position (m) is finite and within
//! ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE), and every velocity (m/s) finite and slower
//! than [`SPEED_OF_LIGHT`]. The setters refuse anything else, and a non-zero velocity on a pinned
//! node (the integrators hold pinned nodes at rest), with an [`Error`] naming the first offending
//! node, and change nothing then. A state made unsteppable through the raw slices
//! ([`DeformableBody::positions_mut`], [`DeformableBody::velocities_mut`]) is refused by
//! [`DeformableBody::check_state`], which the coupling runs before every substep: the body is not
//! stepped, every time, and nothing of it moves.

use super::DeformableBody;
use crate::Error;
pub use crate::limits::SPEED_OF_LIGHT;
use crate::mesh::check_position;
use rapier3d::glamx::DVec3;

impl DeformableBody {
    /// Sets every node's world position (m), one per node; pinned nodes are held where they are
    /// put. Restarts two-step integrators, as [`DeformableBody::positions_mut`] does.
    ///
    /// # Errors
    /// [`Error::WrongNodeCount`] unless there is one position per node;
    /// [`Error::NonFiniteCoordinate`] or [`Error::CoordinateOutOfRange`] naming the first node
    /// whose position is NaN, infinite or beyond ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE).
    /// Nothing is changed then.
    pub fn set_positions(&mut self, positions: &[DVec3]) -> Result<(), Error> {
        self.check_count(positions.len())?;
        for (node, &position) in positions.iter().enumerate() {
            check_position(node, position)?;
        }
        self.positions.copy_from_slice(positions);
        self.count_state_edit();
        Ok(())
    }

    /// Sets every node's velocity (m/s), one per node, zero on pinned nodes. Restarts two-step
    /// integrators, as [`DeformableBody::velocities_mut`] does.
    ///
    /// # Errors
    /// [`Error::WrongNodeCount`] unless there is one velocity per node;
    /// [`Error::NonFiniteVelocity`], [`Error::SpeedOutOfRange`] or [`Error::PinnedNodeVelocity`]
    /// naming the first node whose velocity is NaN, infinite, faster than [`SPEED_OF_LIGHT`] or
    /// non-zero on a pinned node. Nothing is changed then.
    pub fn set_velocities(&mut self, velocities: &[DVec3]) -> Result<(), Error> {
        self.check_count(velocities.len())?;
        for (node, &velocity) in velocities.iter().enumerate() {
            self.check_settable_velocity(node, velocity)?;
        }
        self.velocities.copy_from_slice(velocities);
        self.count_state_edit();
        Ok(())
    }

    /// Sets the world position (m) of node `node`. Restarts two-step integrators.
    ///
    /// # Errors
    /// [`Error::NodeOutOfRange`] for a node that does not exist; [`Error::NonFiniteCoordinate`]
    /// or [`Error::CoordinateOutOfRange`] for a position NaN, infinite or beyond
    /// ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE). Nothing is changed then.
    pub fn set_node_position(&mut self, node: usize, position: DVec3) -> Result<(), Error> {
        self.check_node(node)?;
        check_position(node, position)?;
        self.positions[node] = position;
        self.count_state_edit();
        Ok(())
    }

    /// Sets the velocity (m/s) of node `node`. Restarts two-step integrators.
    ///
    /// # Errors
    /// [`Error::NodeOutOfRange`] for a node that does not exist; [`Error::NonFiniteVelocity`],
    /// [`Error::SpeedOutOfRange`] or [`Error::PinnedNodeVelocity`] for a velocity NaN, infinite,
    /// faster than [`SPEED_OF_LIGHT`] or non-zero on a pinned node. Nothing is changed then.
    pub fn set_node_velocity(&mut self, node: usize, velocity: DVec3) -> Result<(), Error> {
        self.check_node(node)?;
        self.check_settable_velocity(node, velocity)?;
        self.velocities[node] = velocity;
        self.count_state_edit();
        Ok(())
    }

    /// `Ok` if the body's state can be stepped: every node position finite and within
    /// ±[`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE) m, every velocity finite and no faster
    /// than [`SPEED_OF_LIGHT`]. The coupling checks it before every substep and leaves a body
    /// that fails it as it is, with this error as its result.
    ///
    /// # Errors
    /// [`Error::NonFiniteCoordinate`], [`Error::CoordinateOutOfRange`],
    /// [`Error::NonFiniteVelocity`] or [`Error::SpeedOutOfRange`] naming the first node (by
    /// index) whose position or velocity breaks it.
    pub fn check_state(&self) -> Result<(), Error> {
        for (node, (&position, &velocity)) in
            self.positions.iter().zip(&self.velocities).enumerate()
        {
            check_position(node, position)?;
            check_velocity(node, velocity)?;
        }
        Ok(())
    }

    /// [`Error::WrongNodeCount`] unless `given` is the node count.
    fn check_count(&self, given: usize) -> Result<(), Error> {
        if given == self.node_count() {
            Ok(())
        } else {
            Err(Error::WrongNodeCount {
                given,
                node_count: self.node_count(),
            })
        }
    }

    /// [`Error::NodeOutOfRange`] unless node `node` exists.
    fn check_node(&self, node: usize) -> Result<(), Error> {
        if node < self.node_count() {
            Ok(())
        } else {
            Err(Error::NodeOutOfRange {
                node,
                node_count: self.node_count(),
            })
        }
    }

    /// [`check_velocity`], and zero on a pinned node.
    fn check_settable_velocity(&self, node: usize, velocity: DVec3) -> Result<(), Error> {
        check_velocity(node, velocity)?;
        if self.pinned[node] && velocity != DVec3::ZERO {
            return Err(Error::PinnedNodeVelocity {
                node,
                velocity: velocity.to_array(),
            });
        }
        Ok(())
    }
}

/// `Ok` if `velocity` (m/s) of node `node` is finite and slower than [`SPEED_OF_LIGHT`].
///
/// # Errors
/// [`Error::NonFiniteVelocity`] or [`Error::SpeedOutOfRange`] naming `node`.
pub(crate) fn check_velocity(node: usize, velocity: DVec3) -> Result<(), Error> {
    if !velocity.is_finite() {
        return Err(Error::NonFiniteVelocity {
            node,
            velocity: velocity.to_array(),
        });
    }
    // Scaled by the largest component, so that a speed whose square overflows is measured too.
    let largest = velocity.abs().max_element();
    let speed = if largest > 0.0 {
        largest * (velocity / largest).length()
    } else {
        0.0
    };
    if speed > SPEED_OF_LIGHT {
        return Err(Error::SpeedOutOfRange { node, speed });
    }
    Ok(())
}

//! What a [`Load`]'s value is, and its validation: every refusal an [`Error::InvalidLoad`] that
//! names the load and what is wrong, the load left as it was.

use super::{Load, LoadValue, follower};
use crate::Error;

/// What [`Load::set`] says of a value of the other kind.
const VALUE_KINDS: &str = "a vector is the value of a traction or body force, a number that of \
                           a pressure, cable or chamber";

impl Load {
    /// The load's name, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Traction { .. } => "traction",
            Self::Pressure { .. } => "pressure",
            Self::BodyForce { .. } => "body force",
            Self::Cable { .. } => "cable",
            Self::Chamber { .. } => "chamber",
        }
    }

    /// The load's current magnitude.
    pub fn value(&self) -> LoadValue {
        match self {
            Self::Traction { traction, .. } => LoadValue::Vector(*traction),
            Self::BodyForce { density } => LoadValue::Vector(*density),
            Self::Pressure { pressure, .. } => LoadValue::Scalar(*pressure),
            Self::Cable { tension, .. } => LoadValue::Scalar(*tension),
            Self::Chamber { volume, .. } => LoadValue::Scalar(*volume),
        }
    }

    /// Sets the load's magnitude, checked as [`Load::check`] does.
    ///
    /// # Errors
    /// [`Error::InvalidLoad`] for a value of the other kind (a vector for a pressure), a
    /// non-finite value, a negative tension or a chamber's volume not positive; the load is then
    /// unchanged.
    pub fn set(&mut self, value: LoadValue) -> Result<(), Error> {
        let mut changed = self.clone();
        match (&mut changed, value) {
            (Self::Traction { traction: v, .. }, LoadValue::Vector(new))
            | (Self::BodyForce { density: v }, LoadValue::Vector(new)) => *v = new,
            (Self::Pressure { pressure: v, .. }, LoadValue::Scalar(new))
            | (Self::Cable { tension: v, .. }, LoadValue::Scalar(new))
            | (Self::Chamber { volume: v, .. }, LoadValue::Scalar(new)) => *v = new,
            _ => return Err(self.invalid(VALUE_KINDS)),
        }
        changed.check_value()?;
        *self = changed;
        Ok(())
    }

    /// Checks that the load's nodes exist among `node_count` and that its value is finite (a
    /// tension not negative, a chamber's volume and bulk modulus positive, its surface closed).
    ///
    /// # Errors
    /// [`Error::InvalidLoad`] saying what is wrong.
    pub fn check(&self, node_count: usize) -> Result<(), Error> {
        let in_range =
            |mut nodes: std::slice::Iter<'_, u32>| nodes.all(|&n| (n as usize) < node_count);
        match self {
            Self::Traction { triangles, .. }
            | Self::Pressure { triangles, .. }
            | Self::Chamber { triangles, .. } => {
                if !in_range(triangles.as_flattened().iter()) {
                    return Err(self.invalid("a triangle names a node the body does not have"));
                }
                if triangles.iter().any(|[a, b, c]| a == b || b == c || c == a) {
                    return Err(self.invalid("a triangle names a node twice"));
                }
                if let Self::Chamber { bulk_modulus, .. } = self {
                    if !follower::is_closed(triangles) {
                        return Err(self.invalid(
                            "a chamber's walls must be a closed, consistently oriented surface",
                        ));
                    }
                    if !(bulk_modulus.is_finite() && *bulk_modulus > 0.0) {
                        return Err(self.invalid("a liquid's bulk modulus must be positive"));
                    }
                }
            }
            Self::Cable { path, .. } => {
                if path.len() < 2 {
                    return Err(self.invalid("a cable's path needs at least two nodes"));
                }
                if !in_range(path.iter()) {
                    return Err(self.invalid("the path names a node the body does not have"));
                }
                if path.windows(2).any(|w| w[0] == w[1]) {
                    return Err(self.invalid("the path names a node twice in a row"));
                }
            }
            Self::BodyForce { .. } => {}
        }
        self.check_value()
    }

    /// [`Error::InvalidLoad`] for a non-finite value, a negative tension or a chamber's volume
    /// not positive.
    fn check_value(&self) -> Result<(), Error> {
        let finite = match self.value() {
            LoadValue::Vector(v) => v.is_finite(),
            LoadValue::Scalar(s) => s.is_finite(),
        };
        if !finite {
            return Err(self.invalid("its value must be finite"));
        }
        if let Self::Cable { tension, .. } = self
            && *tension < 0.0
        {
            return Err(self.invalid("a cable's tension cannot be negative (a cable only pulls)"));
        }
        if let Self::Chamber { volume, .. } = self
            && *volume <= 0.0
        {
            return Err(self.invalid("a chamber's volume must be positive"));
        }
        Ok(())
    }

    fn invalid(&self, reason: &str) -> Error {
        Error::InvalidLoad {
            load: self.kind(),
            reason: reason.to_owned(),
        }
    }
}

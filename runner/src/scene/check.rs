//! The checks after parsing: values a type cannot rule out (a negative Young's modulus, ν at
//! 0.5, a zero time step) and references between entries (an attachment to a rigid body that
//! does not exist). The first failure is kept, with its key path, and located in the file.

use super::error::{SceneError, SceneSource};
use rapier_fvm::body::SPEED_OF_LIGHT;
use rapier_fvm::glamx::DVec3;

/// Collects the first failed check.
pub(crate) struct Checker<'a> {
    source: &'a SceneSource,
    first: Option<SceneError>,
}

impl<'a> Checker<'a> {
    /// A checker for the scene in `source`.
    pub(crate) fn new(source: &'a SceneSource) -> Self {
        Self {
            source,
            first: None,
        }
    }

    /// Records that the value at `key` is wrong (only the first failure is kept).
    pub(crate) fn fail(&mut self, key: &str, message: impl Into<String>) {
        if self.first.is_none() {
            self.first = Some(self.source.error(key, message));
        }
    }

    /// Fails unless `value` is finite and positive.
    pub(crate) fn positive(&mut self, key: &str, value: f64, unit: &str) {
        if !(value.is_finite() && value > 0.0) {
            self.fail(
                key,
                format!("must be positive and finite ({unit}), got {value}"),
            );
        }
    }

    /// Fails unless `value` is finite and not negative.
    pub(crate) fn non_negative(&mut self, key: &str, value: f64, unit: &str) {
        if !(value.is_finite() && value >= 0.0) {
            self.fail(
                key,
                format!("must be zero or positive and finite ({unit}), got {value}"),
            );
        }
    }

    /// Fails unless every component is finite.
    pub(crate) fn finite_vector(&mut self, key: &str, value: [f64; 3]) {
        if value.iter().any(|v| !v.is_finite()) {
            self.fail(key, format!("must be finite, got {value:?}"));
        }
    }

    /// Fails unless `value` (m/s) is finite and no faster than light.
    pub(crate) fn speed(&mut self, key: &str, value: [f64; 3]) {
        let speed = DVec3::from_array(value).length();
        if value.iter().any(|v| !v.is_finite()) {
            self.fail(key, format!("must be finite, got {value:?}"));
        } else if speed > SPEED_OF_LIGHT {
            self.fail(
                key,
                format!("{speed:e} m/s is faster than light ({SPEED_OF_LIGHT} m/s)"),
            );
        }
    }

    /// The first failure, if any.
    pub(crate) fn finish(self) -> Result<(), SceneError> {
        self.first.map_or(Ok(()), Err)
    }
}

/// Checks the bodies' names (`soft`, then `rigid`, in the scene's order): none empty, none
/// repeated.
pub(crate) fn check_body_names(soft: &[&str], rigid: &[&str], c: &mut Checker<'_>) {
    let soft_keys = (soft.iter().enumerate()).map(|(i, n)| (format!("soft_body[{i}].name"), *n));
    let rigid_keys = (rigid.iter().enumerate()).map(|(i, n)| (format!("rigid_body[{i}].name"), *n));
    let mut seen: Vec<&str> = Vec::new();
    for (key, name) in soft_keys.chain(rigid_keys) {
        if name.trim().is_empty() {
            c.fail(&key, "must not be empty");
        } else if seen.contains(&name) {
            c.fail(&key, format!("another body is already named {name:?}"));
        }
        seen.push(name);
    }
}

/// Checks the probes' names, `names` in the scene's order: none repeated.
pub(crate) fn check_probe_names<'a>(names: impl IntoIterator<Item = &'a str>, c: &mut Checker<'_>) {
    let mut seen: Vec<&str> = Vec::new();
    for (i, name) in names.into_iter().enumerate() {
        if seen.contains(&name) {
            c.fail(
                &format!("probe[{i}].name"),
                format!("another probe is already named {name:?}"),
            );
        }
        seen.push(name);
    }
}

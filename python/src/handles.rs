//! Handles to a world's bodies and colliders, as rapier gives them: generational indices that
//! stay valid while the body lives, compared and hashed by value.

use pyo3::prelude::*;
use rapier_fvm::body::DeformableBodyHandle;
use rapier3d::prelude::{ColliderHandle, RigidBodyHandle};

/// A soft (deformable) body of a `World`.
#[pyclass(module = "rapier_fvm", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct SoftBody {
    index: u32,
    generation: u32,
}

/// A rigid body of a `World`.
#[pyclass(module = "rapier_fvm", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct RigidBody {
    index: u32,
    generation: u32,
}

/// A collider of a `World` (the ground, or a rigid body's shape).
#[pyclass(module = "rapier_fvm", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Collider {
    index: u32,
    generation: u32,
}

impl SoftBody {
    /// The handle of the library's handle `handle`.
    pub fn of(handle: DeformableBodyHandle) -> Self {
        let (index, generation) = handle.into_raw_parts();
        Self { index, generation }
    }

    /// The library's handle.
    pub fn handle(self) -> DeformableBodyHandle {
        DeformableBodyHandle::from_raw_parts(self.index, self.generation)
    }
}

impl RigidBody {
    /// The handle of rapier's handle `handle`.
    pub fn of(handle: RigidBodyHandle) -> Self {
        let (index, generation) = handle.into_raw_parts();
        Self { index, generation }
    }

    /// rapier's handle.
    pub fn handle(self) -> RigidBodyHandle {
        RigidBodyHandle::from_raw_parts(self.index, self.generation)
    }
}

impl Collider {
    /// The handle of rapier's handle `handle`.
    pub fn of(handle: ColliderHandle) -> Self {
        let (index, generation) = handle.into_raw_parts();
        Self { index, generation }
    }

    /// rapier's handle.
    pub fn handle(self) -> ColliderHandle {
        ColliderHandle::from_raw_parts(self.index, self.generation)
    }
}

/// Each handle prints as Python shows it, `SoftBody(index, generation)`.
macro_rules! debug_as_repr {
    ($($handle:ident),*) => {$(
        impl std::fmt::Debug for $handle {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}({}, {})", stringify!($handle), self.index, self.generation)
            }
        }
    )*};
}
debug_as_repr!(SoftBody, RigidBody, Collider);

#[pymethods]
impl SoftBody {
    /// The handle of raw parts `index` and `generation` (as `__getnewargs__` gives them, for
    /// pickling).
    #[new]
    fn new(index: u32, generation: u32) -> Self {
        Self { index, generation }
    }

    fn __getnewargs__(&self) -> (u32, u32) {
        (self.index, self.generation)
    }

    fn __repr__(&self) -> String {
        format!("{self:?}")
    }
}

#[pymethods]
impl RigidBody {
    /// The handle of raw parts `index` and `generation` (as `__getnewargs__` gives them, for
    /// pickling).
    #[new]
    fn new(index: u32, generation: u32) -> Self {
        Self { index, generation }
    }

    fn __getnewargs__(&self) -> (u32, u32) {
        (self.index, self.generation)
    }

    fn __repr__(&self) -> String {
        format!("{self:?}")
    }
}

#[pymethods]
impl Collider {
    /// The handle of raw parts `index` and `generation` (as `__getnewargs__` gives them, for
    /// pickling).
    #[new]
    fn new(index: u32, generation: u32) -> Self {
        Self { index, generation }
    }

    fn __getnewargs__(&self) -> (u32, u32) {
        (self.index, self.generation)
    }

    fn __repr__(&self) -> String {
        format!("{self:?}")
    }
}

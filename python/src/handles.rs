//! Handles to a world's bodies and colliders, as rapier gives them: generational indices into
//! the world's sets that stay valid while the body lives, compared and hashed by value, printed
//! and pickled as their raw parts `(index, generation)`.

use pyo3::prelude::*;
use rapier_fvm::body::DeformableBodyHandle;
use rapier3d::prelude::{ColliderHandle, RigidBodyHandle};

/// A handle class `$name` over the library's or rapier's handle `$inner`.
macro_rules! handle_class {
    ($(#[$doc:meta])* $name:ident, $inner:ty) => {
        $(#[$doc])*
        #[pyclass(module = "rapier_fvm", frozen, eq, hash, from_py_object)]
        #[derive(Clone, Copy, PartialEq, Eq, Hash)]
        pub struct $name {
            index: u32,
            generation: u32,
        }

        impl $name {
            /// The Python handle of `handle`.
            pub fn of(handle: $inner) -> Self {
                let (index, generation) = handle.into_raw_parts();
                Self { index, generation }
            }

            /// The handle it stands for.
            pub fn handle(self) -> $inner {
                <$inner>::from_raw_parts(self.index, self.generation)
            }
        }

        impl std::fmt::Debug for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}({}, {})", stringify!($name), self.index, self.generation)
            }
        }

        #[pymethods]
        impl $name {
            /// The handle of raw parts `index` and `generation` (as `__getnewargs__` gives
            /// them, for pickling).
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
    };
}

handle_class!(
    /// A soft (deformable) body of a `World`.
    SoftBody,
    DeformableBodyHandle
);
handle_class!(
    /// A rigid body of a `World`.
    RigidBody,
    RigidBodyHandle
);
handle_class!(
    /// A collider of a `World` (the ground, or a rigid body's shape).
    Collider,
    ColliderHandle
);

//! # `rapier_fvm`
//!
//! Physically based soft bodies for the [rapier](https://rapier.rs) physics engine, simulated with
//! the finite-volume method on tetrahedral meshes, in SI units throughout: lengths in m, time in
//! s, Young's modulus and stresses in Pa, densities in kg/m³, damping coefficients in Pa·s.
//!
//! ## The method
//! 1. Each material point has a rest position `p` and a world position `x = X(p)`; the motion is
//!    piecewise linear, so the deformation gradient `F = dX/dp` is constant per tetrahedron
//!    ([`fvm::TetRest::gradient`]).
//! 2. A [`material::HyperelasticModel`] turns `F` into the first Piola–Kirchhoff stress `P`;
//!    [`damping::RayleighDamping`] adds a viscous stress on the strain rate that ignores rigid
//!    motion.
//! 3. The force on a node is the traction integrated over the boundary of its control volume:
//!    `f_i = P b_i` per tetrahedron ([`fvm::tet_forces`]).
//! 4. Mass is lumped on the nodes from the same control volumes.
//! 5. [`integrate::SymplecticEuler`] advances velocities then positions, splitting each frame
//!    into as many substeps as stability requires; [`integrate::ImplicitIntegrator`] takes steps
//!    of any length (backward Euler or BDF2 by Newton's method on the incremental potential);
//!    [`integrate::AutomaticIntegrator`] picks the cheaper of the two each frame; [`statics`]
//!    finds equilibria and natural frequencies directly.
//!
//! ## Rigid and soft bodies together
//! Both preludes import side by side. [`FvmWorld`](world::FvmWorld) holds rapier's
//! `PhysicsWorld` and the deformable bodies; a program with its own `PhysicsPipeline` and sets
//! uses [`coupling::SoftCoupling::step`] instead, with the same result (the stages of a frame are
//! listed in [`coupling`]).
//! ```
//! use rapier3d::prelude::*;
//! use rapier_fvm::prelude::*;
//!
//! let mut world = FvmWorld::default();
//! world.physics.insert_collider(ColliderBuilder::new(SharedShape::halfspace(Vector::Y)), None);
//! // A 20 cm rubber block on the ground, and a 10 cm rigid box dropped on it.
//! let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
//! let block = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [3, 3, 3])?, rubber)
//!     .translation(DVec3::new(0.0, 0.1, 0.0))
//!     .build()?;
//! let block = world.soft_bodies.insert(block);
//! let (rigid_box, _) = world.physics.insert(
//!     RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.3, 0.0)),
//!     ColliderBuilder::cuboid(0.05, 0.05, 0.05),
//! );
//! for _frame in 0..30 {
//!     for (_handle, outcome) in world.step() {
//!         outcome?;
//!     }
//! }
//! // The box has landed on the block (its top at 0.2 m) and the block pushes it up.
//! let height = world.physics.bodies[rigid_box].translation().y;
//! assert!(height > 0.2 && height < 0.26);
//! assert!(world.load_on(block, rigid_box).0.y > 0.0);
//! # Ok::<(), rapier_fvm::Error>(())
//! ```
//!
//! ## A body alone
//! ```
//! use rapier_fvm::prelude::*;
//!
//! // A 1 m rubber beam clamped at x = -0.5 m, sagging under gravity.
//! let mesh = mesh::cuboid(DVec3::new(0.5, 0.05, 0.05), [10, 1, 1])?;
//! let clamped = mesh.nodes_where(|p| p.x <= -0.5 + 1e-9);
//! let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
//! let mut beam = DeformableBodyBuilder::new(mesh, rubber)
//!     .damping(RayleighDamping::stiffness_proportional(0.01, rubber.lame())?)
//!     .pinned_nodes(clamped)
//!     .build()?;
//! let integrator = SymplecticEuler::default();
//! // What acts on the beam from outside (nothing here) and the solver's caches, kept beside it.
//! let (mut constraints, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
//! for _frame in 0..6 {
//!     let gravity = DVec3::new(0.0, -9.81, 0.0);
//!     let report = integrator.step(&mut beam, &mut constraints, &mut workspace, 1.0 / 60.0, gravity)?;
//!     assert!(report.substeps >= 1);
//! }
//! assert!(beam.positions().iter().all(|x| x.is_finite()));
//! # Ok::<(), rapier_fvm::Error>(())
//! ```

mod assembly;
pub mod attachment;
pub mod body;
mod chord;
pub mod constraint;
pub mod contact;
pub mod coupling;
pub mod damping;
pub mod element;
pub mod embedding;
mod error;
pub mod fvm;
pub mod integrate;
mod lanes;
mod limits;
pub mod linear_solver;
pub mod load;
pub mod material;
pub mod mesh;
mod newton;
mod parallel;
pub mod planar;
pub mod query;
mod rigid;
pub mod shape;
pub mod statics;
mod stencil;
pub mod world;

pub use error::{Error, FileLocation, ImportErrorKind};

/// The README's examples, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
/// glam math types, re-exported from rapier. This crate's API uses the f64 types (`DVec3`,
/// `DMat3`, `DQuat`); rapier3d's own `Vec3` and `Quat` are f32, so values crossing between the two
/// are converted (`as_dvec3()`, `as_vec3()`).
pub use rapier3d::glamx;

/// The types most programs need.
pub mod prelude {
    pub use crate::Error;
    pub use crate::body::{
        DeformableBody, DeformableBodyBuilder, DeformableBodyHandle, DeformableBodySet,
        RigidStandIn,
    };
    pub use crate::constraint::BodyConstraints;
    pub use crate::contact::{BodyPoint, ContactSettings, ContactTarget, NodeContact};
    pub use crate::coupling::{
        ColliderLoad, RapierSets, RigidLoad, RigidSets, SleepSettings, SoftCoupling,
    };
    pub use crate::damping::RayleighDamping;
    pub use crate::fvm::VolumetricTreatment;
    pub use crate::integrate::{
        AutomaticIntegrator, ImplicitIntegrator, ImplicitReport, ImplicitScheme, IntegratorKind,
        SolverWorkspace, StepReport, Substeps, SymplecticEuler,
    };
    pub use crate::linear_solver::LinearSolver;
    pub use crate::load::{Load, LoadHandle, LoadValue};
    pub use crate::material::{LameParameters, Material, MaterialModel, YoungPoisson};
    pub use crate::mesh::{self, TetMesh};
    pub use crate::world::FvmWorld;
    pub use rapier3d::glamx::{DMat3, DQuat, DVec3};
}

//! The implicit solver's and the contact pipeline's kernels, each on a fixed state:
//!
//! - one backward Euler frame of 1/60 s of the stiff reference beam (E = 1e9 Pa, stable
//!   Neo-Hookean, 1 600 tetrahedra) under gravity: backward Euler damps the beam within a few
//!   frames, so most measured frames start near equilibrium and take zero or one Newton
//!   iteration, the cost of a body at rest (`examples/implicit_scaling.rs` prints frames in
//!   motion and larger sizes);
//! - one Newton iteration (assembly, direct solve, line search) of a 1/60 s frame of the stiff
//!   reference beam (E = 1e9 Pa, stable Neo-Hookean, 1 600 tetrahedra) released from rest;
//! - the same iteration with its linear system solved by the conjugate gradient capped at 1 and
//!   at 21 iterations: the difference over 20 is the cost of one CG iteration;
//! - contact detection of a 20³-cube soft block (2 402 surface nodes) against a ground
//!   half-space and a box collider, per surface node.

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use rapier_fvm::contact::ContactSettings;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::linear_solver::LinearSolver;
use rapier_fvm::prelude::*;
use rapier3d::prelude::{ColliderBuilder, ColliderSet, RigidBodySet, SharedShape};
use std::hint::black_box;

const GRAVITY: DVec3 = DVec3::new(0.0, -9.81, 0.0);

/// The reference beam at rest, with its solver workspace: the sparsity pattern and symbolic
/// factorization already built.
fn beam() -> (DeformableBody, SolverWorkspace) {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let mesh = mesh::cuboid(half, [20, 4, 4]).expect("valid generator input");
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e9, 0.3, 1000.0).expect("valid material");
    let mut body = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .build()
        .expect("valid body");
    // Builds the pattern; zero gravity leaves the beam at rest.
    let mut workspace = SolverWorkspace::new();
    ImplicitIntegrator::default()
        .step(
            &mut body,
            &mut BodyConstraints::new(),
            &mut workspace,
            1.0 / 60.0,
            DVec3::ZERO,
        )
        .expect("first frame");
    (body, workspace)
}

fn implicit_frame(c: &mut Criterion) {
    let (mut body, mut workspace) = beam();
    let mut free = BodyConstraints::new();
    let integrator = ImplicitIntegrator::default();
    let mut group = c.benchmark_group("implicit_frame");
    group.sample_size(20);
    group.bench_function("stable_neo_hookean_1600_tets_dt_1_60", |b| {
        b.iter(|| {
            integrator
                .step(&mut body, &mut free, &mut workspace, 1.0 / 60.0, GRAVITY)
                .expect("implicit frame")
                .newton_iterations
        })
    });
    group.finish();
}

fn newton_iteration(c: &mut Criterion) {
    let rest = beam();
    let mut group = c.benchmark_group("implicit_kernels_1600_tets");
    group.sample_size(20);
    // One iteration, and no refinement of a frame it does not converge in: the frame's
    // outcome is not what is timed.
    let one_iteration = |linear_solver| ImplicitIntegrator {
        max_newton_iterations: 1,
        max_refinement: 1,
        linear_solver,
        ..ImplicitIntegrator::default()
    };
    let cases = [
        ("newton_iteration_direct", LinearSolver::Direct),
        (
            "newton_iteration_cg_1",
            LinearSolver::ConjugateGradient {
                tolerance: 1e-30,
                max_iterations: 1,
            },
        ),
        (
            "newton_iteration_cg_21",
            LinearSolver::ConjugateGradient {
                tolerance: 1e-30,
                max_iterations: 21,
            },
        ),
    ];
    for (name, solver) in cases {
        let integrator = one_iteration(solver);
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || rest.clone(),
                |(body, workspace)| {
                    integrator
                        .step(
                            body,
                            &mut BodyConstraints::new(),
                            workspace,
                            1.0 / 60.0,
                            GRAVITY,
                        )
                        .map_or(1, |report| report.newton_iterations)
                },
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

fn contact_detection(c: &mut Criterion) {
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).expect("valid material");
    let mesh = mesh::cuboid(DVec3::splat(0.1), [20, 20, 20]).expect("valid generator input");
    let surface_nodes = mesh
        .surface_triangles()
        .iter()
        .flatten()
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    let body = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(0.0, 0.1, 0.0))
        .build()
        .expect("valid body");
    let mut constraints = BodyConstraints::new();
    let bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    colliders.insert(ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)));
    colliders
        .insert(ColliderBuilder::cuboid(0.05, 0.05, 0.05).translation(Vec3::new(0.0, 0.25, 0.0)));
    let settings = ContactSettings::default();
    let mut group = c.benchmark_group("contact_detection_20cubed");
    group.sample_size(20);
    group.throughput(Throughput::Elements(surface_nodes as u64));
    group.bench_function("ground_and_box", |b| {
        b.iter(|| {
            black_box(
                constraints
                    .detect_contacts(&body, &colliders, &bodies, 1.0 / 60.0, GRAVITY, &settings)
                    .expect("valid detection")
                    .len(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, implicit_frame, newton_iteration, contact_detection);
criterion_main!(benches);

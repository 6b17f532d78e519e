//! One backward Euler frame of 1/60 s on the stiff reference beam (E = 1e9 Pa, ν = 0.3, stable
//! Neo-Hookean) at 1 600 tetrahedra, after a first frame has built the sparsity pattern and its
//! symbolic factorization. Backward Euler damps the beam within a few frames, so most measured
//! frames start near equilibrium and take zero or one Newton iteration: this is the cost of a
//! body at rest. `examples/implicit_scaling.rs` prints frames in motion (two Newton iterations)
//! and the larger sizes.

use criterion::{Criterion, criterion_group, criterion_main};
use rapier_fvm::prelude::*;

fn implicit_frame(c: &mut Criterion) {
    let half = DVec3::new(0.5, 0.05, 0.05);
    let mesh = mesh::cuboid(half, [20, 4, 4]).expect("valid generator input");
    let clamped = mesh.nodes_where(|p| p.x <= -half.x + 1e-9);
    let material =
        Material::new(MaterialModel::StableNeoHookean, 1e9, 0.3, 1000.0).expect("valid material");
    let mut body = SoftBodyBuilder::new(mesh, material)
        .translation(DVec3::new(half.x, 0.0, 0.0))
        .pinned_nodes(clamped)
        .build()
        .expect("valid body");
    let gravity = DVec3::new(0.0, -9.81, 0.0);
    let integrator = ImplicitIntegrator::default();
    integrator
        .step(&mut body, 1.0 / 60.0, gravity)
        .expect("first frame");
    let mut group = c.benchmark_group("implicit_frame");
    group.sample_size(20);
    group.bench_function("stable_neo_hookean_1600_tets_dt_1_60", |b| {
        b.iter(|| {
            integrator
                .step(&mut body, 1.0 / 60.0, gravity)
                .expect("implicit frame")
                .newton_iterations
        })
    });
    group.finish();
}

criterion_group!(benches, implicit_frame);
criterion_main!(benches);

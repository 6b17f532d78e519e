//! The finite-volume force kernel in ns per tetrahedron per step: St. Venant–Kirchhoff with
//! Rayleigh damping, f64, on a 40 x 40 x 40-cube box (320 000 tetrahedra), on one thread and on
//! all of rayon's threads. Also the other material models on one thread, and St.
//! Venant–Kirchhoff with nodal averaging of the volumetric term. Then quadratic (10-node)
//! tetrahedra, four quadrature points each, on a 20 x 20 x 20-cube box (40 000 elements), in ns
//! per element per step.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rapier_fvm::prelude::*;
use std::hint::black_box;

/// A deformed, moving 40^3-cube box so every branch of the kernel does real work.
fn box_body(model: MaterialModel, treatment: VolumetricTreatment) -> DeformableBody {
    let mesh = mesh::cuboid(DVec3::splat(0.2), [40, 40, 40]).expect("valid generator input");
    let material = Material::new(model, 1e6, 0.3, 1000.0).expect("valid material");
    let damping =
        RayleighDamping::stiffness_proportional(1e-3, material.lame()).expect("valid damping");
    let mut body = DeformableBodyBuilder::new(mesh, material)
        .damping(damping)
        .volumetric(treatment)
        .build()
        .expect("valid body");
    for x in body.positions_mut() {
        *x += DVec3::new(0.05 * x.y, -0.02 * x.z, 0.03 * x.x);
    }
    for (i, v) in body.velocities_mut().iter_mut().enumerate() {
        *v = DVec3::new((i % 7) as f64, (i % 5) as f64, (i % 3) as f64) * 0.01;
    }
    body
}

fn kernel(c: &mut Criterion) {
    let mut group = c.benchmark_group("force_kernel_40cubed");
    group.sample_size(20);
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("one-thread pool");
    for model in [
        MaterialModel::StVenantKirchhoff,
        MaterialModel::Linear,
        MaterialModel::Corotated,
        MaterialModel::StableNeoHookean,
    ] {
        let mut body = box_body(model, VolumetricTreatment::PerElement);
        // The forces go to one buffer, as the integrators' workspace keeps one.
        let mut forces = Vec::new();
        group.throughput(Throughput::Elements(body.mesh().tet_count() as u64));
        group.bench_function(format!("{model:?}+damping/1_thread"), |b| {
            single.install(|| b.iter(|| black_box(forces_of(&mut body, &mut forces))))
        });
        if model == MaterialModel::StVenantKirchhoff {
            group.bench_function(format!("{model:?}+damping/all_threads"), |b| {
                b.iter(|| black_box(forces_of(&mut body, &mut forces)))
            });
            let mut averaged = box_body(model, VolumetricTreatment::NodalAverage);
            group.bench_function(format!("{model:?}+damping+nodal_average/1_thread"), |b| {
                single.install(|| b.iter(|| black_box(forces_of(&mut averaged, &mut forces))))
            });
        }
    }
    group.finish();
}

/// The internal force on the first node (N), all of them computed into `forces`.
fn forces_of(body: &mut DeformableBody, forces: &mut Vec<DVec3>) -> DVec3 {
    body.internal_forces_into(forces);
    forces[0]
}

/// The quadratic-element force loop (serial), per element per step.
fn quadratic_kernel(c: &mut Criterion) {
    let mut group = c.benchmark_group("quadratic_force_kernel_20cubed");
    group.sample_size(20);
    let linear = mesh::cuboid(DVec3::splat(0.2), [20, 20, 20]).expect("valid generator input");
    let quadratic = mesh::QuadraticTetMesh::from_linear(&linear).expect("valid mesh");
    for model in [MaterialModel::StVenantKirchhoff, MaterialModel::Corotated] {
        let material = Material::new(model, 1e6, 0.3, 1000.0).expect("valid material");
        let damping =
            RayleighDamping::stiffness_proportional(1e-3, material.lame()).expect("valid damping");
        let mut body = DeformableBodyBuilder::quadratic(quadratic.clone(), material)
            .damping(damping)
            .build()
            .expect("valid body");
        for x in body.positions_mut() {
            *x += DVec3::new(0.05 * x.y, -0.02 * x.z, 0.03 * x.x);
        }
        group.throughput(Throughput::Elements(quadratic.element_count() as u64));
        let mut forces = Vec::new();
        group.bench_function(format!("{model:?}+damping"), |b| {
            b.iter(|| black_box(forces_of(&mut body, &mut forces)))
        });
    }
    group.finish();
}

criterion_group!(benches, kernel, quadratic_kernel);
criterion_main!(benches);

//! A soft rubber cube (10 cm, E = 1e5 Pa, ν = 0.3, 1000 kg/m³, 6 x 6 x 6 cells, damped) dropped
//! from 0.5 m onto rapier ground, in an [`FvmWorld`] at 60 frames per second with the automatic
//! choice of integrator: how to add a soft body to a rapier world, and what the coupling costs.
//!
//! Prints the fall every 0.1 s, then the deepest penetration, the height it rests at, and the
//! time per frame of the coupled world beside the same body stepped alone in free fall (no
//! colliders, no rapier step) in the same run. Last line: one JSON object.
//!
//! Run with `cargo run --release --example drop`.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, SharedShape};
use std::time::Instant;

const FRAMES: usize = 120;

fn cube() -> Result<DeformableBody, Error> {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [6, 6, 6])?, rubber)
        .damping(RayleighDamping::stiffness_proportional(
            2e-3,
            rubber.lame(),
        )?)
        .translation(DVec3::new(0.0, 0.55, 0.0))
        .build()
}

fn main() -> Result<(), Error> {
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    let handle = world.soft_bodies.insert(cube()?);
    println!(
        "{:>6} {:>12} {:>12} {:>14} {:>10}",
        "t (s)", "lowest (mm)", "centre (mm)", "fastest (m/s)", "integrator"
    );
    let mut deepest = f64::INFINITY;
    let start = Instant::now();
    for frame in 1..=FRAMES {
        let mut choice = String::new();
        for (_, outcome) in world.step() {
            let report = outcome?;
            choice = format!("{:?}", report.choice);
        }
        let body = &world.soft_bodies[handle];
        let lowest = body
            .positions()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        deepest = deepest.min(lowest);
        if frame % 6 == 0 {
            let fastest = body
                .velocities()
                .iter()
                .map(|v| v.length())
                .fold(0.0, f64::max);
            println!(
                "{:>6.2} {:>12.3} {:>12.3} {:>14.3e} {:>10}",
                frame as f64 / 60.0,
                lowest * 1e3,
                body.center_of_mass().y * 1e3,
                fastest,
                choice
            );
        }
    }
    let coupled_ms = start.elapsed().as_secs_f64() * 1e3 / FRAMES as f64;
    // The same body, same frames and integrator, falling freely: the soft step alone.
    let mut alone = cube()?;
    let gravity = DVec3::new(0.0, -9.81, 0.0);
    let h = 1.0 / 60.0 / f64::from(world.coupling.substeps);
    let (mut free, mut workspace) = (BodyConstraints::new(), SolverWorkspace::new());
    let start = Instant::now();
    for _ in 0..FRAMES * world.coupling.substeps as usize {
        world
            .coupling
            .integrator
            .step(&mut alone, &mut free, &mut workspace, h, gravity)?;
    }
    let alone_ms = start.elapsed().as_secs_f64() * 1e3 / FRAMES as f64;
    let body = &world.soft_bodies[handle];
    let rest = body.center_of_mass().y;
    println!(
        "deepest {:.3} mm (margin {} mm); rests with its centre at {:.3} mm; {:.2} ms/frame coupled, {:.2} ms/frame alone ({:.2}x)",
        deepest * 1e3,
        world.coupling.contact.margin * 1e3,
        rest * 1e3,
        coupled_ms,
        alone_ms,
        coupled_ms / alone_ms
    );
    println!(
        "{{\"deepest_mm\": {:.4}, \"rest_centre_mm\": {:.4}, \"ms_per_frame_coupled\": {coupled_ms:.3}, \"ms_per_frame_alone\": {alone_ms:.3}, \"coupling_cost_ratio\": {:.3}}}",
        deepest * 1e3,
        rest * 1e3,
        coupled_ms / alone_ms
    );
    Ok(())
}

//! A ball hanging from a soft rope, swinging: a 0.5 m rope (1 x 1 cm, 2 x 40 x 2 cells, stable
//! Neo-Hookean, E = 1e6 Pa, ν = 0.3, 1000 kg/m³, Rayleigh damping 0.01 s) clamped at the top,
//! with a 1 kg rigid ball (r = 5 cm) glued 1 cm below its end by `FvmWorld::attach`, released
//! 5° from the vertical in an [`FvmWorld`] at 60 frames per second: how to hang a rigid body from
//! a soft one, and whether the pair swings as the compound pendulum it is.
//!
//! Prints the ball's angle from the vertical through the clamp (degrees) and its distance from
//! the clamp (m) every 0.25 s for 7 s, then the period measured from the ball's downward
//! crossings of the vertical (s) against the compound pendulum's, `2π sqrt(I / (M g d))`, for the
//! rope's length as it hangs stretched (the mean distance of the ball's centre from the clamp,
//! less the gap and the radius). Last line: one JSON object.
//!
//! Run with `cargo run --release --example hanging_rope`.

use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use std::f64::consts::PI;

/// Frames per second (`FvmWorld`'s default frame step) and frames run (7 s).
const FPS: usize = 60;
const FRAMES: usize = 7 * FPS;
/// Frames per table row (0.25 s).
const ROW_FRAMES: usize = FPS / 4;
/// The rope's rest length, the ball's radius and the gap between them (m).
const LENGTH: f64 = 0.5;
const RADIUS: f64 = 0.05;
const GAP: f64 = 0.01;
/// The ball's mass (kg).
const BALL_MASS: f64 = 1.0;

/// The world, the rope's and the ball's handles, and the ball's starting x (m).
struct Scene {
    world: FvmWorld,
    rope: DeformableBodyHandle,
    ball: RigidBodyHandle,
    start_x: f64,
}

/// The rope clamped at the top, tilted 5°, with the ball glued below its end.
fn build_scene() -> Result<Scene, Error> {
    let mut world = FvmWorld::default();
    let tilt = DQuat::from_rotation_z(5f64.to_radians());
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let mesh = mesh::cuboid(DVec3::new(0.005, LENGTH / 2.0, 0.005), [2, 40, 2])?;
    let top = mesh.nodes_where(|p| p.y >= LENGTH / 2.0 - 1e-9);
    let bottom = mesh.nodes_where(|p| p.y <= -LENGTH / 2.0 + 1e-9);
    let rope = DeformableBodyBuilder::new(mesh, material)
        .damping(RayleighDamping::stiffness_proportional(
            0.01,
            material.lame(),
        )?)
        .orientation(tilt)
        .translation(tilt * DVec3::new(0.0, -LENGTH / 2.0, 0.0))
        .pinned_nodes(top)
        .build()?;
    let density = BALL_MASS / (4.0 / 3.0 * PI * RADIUS.powi(3));
    let centre = tilt * DVec3::new(0.0, -(LENGTH + GAP + RADIUS), 0.0);
    let (ball, _) = world.physics.insert(
        RigidBodyBuilder::dynamic().translation(centre.as_vec3()),
        ColliderBuilder::ball(RADIUS as f32).density(density as f32),
    );
    let rope = world.soft_bodies.insert(rope);
    world.attach(rope, bottom, ball)?;
    Ok(Scene {
        world,
        rope,
        ball,
        start_x: centre.x,
    })
}

/// Swings, printing the table; returns the downward crossing times (s) and the mean arm (m).
fn swing(scene: &mut Scene) -> Result<(Vec<f64>, f64), Error> {
    let world = &mut scene.world;
    let dt = f64::from(world.physics.integration_parameters.dt);
    println!("{:>6} {:>12} {:>14}", "t (s)", "angle (°)", "distance (m)");
    let (mut crossings, mut previous_x, mut distance_sum) = (Vec::new(), scene.start_x, 0.0);
    for frame in 1..=FRAMES {
        for (_, outcome) in world.step() {
            outcome?;
        }
        // The clamp's centre is the world origin.
        let x = world.physics.bodies[scene.ball].translation().as_dvec3();
        distance_sum += x.length();
        if previous_x > 0.0 && x.x <= 0.0 {
            // Linear interpolation of the downward crossing of x = 0.
            crossings.push((frame as f64 - x.x.abs() / (previous_x - x.x)) * dt);
        }
        previous_x = x.x;
        if frame % ROW_FRAMES == 0 {
            println!(
                "{:>6.2} {:>12.3} {:>14.5}",
                frame as f64 * dt,
                x.x.atan2(-x.y).to_degrees(),
                x.length()
            );
        }
    }
    Ok((crossings, distance_sum / FRAMES as f64))
}

/// Prints the measured period against the compound pendulum's, then the JSON line.
fn print_summary(scene: &Scene, crossings: &[f64], arm: f64) {
    // The compound pendulum: the ball on its arm plus the rope as a uniform rod.
    let rope_mass = scene.world.soft_bodies[scene.rope].total_mass();
    let rope_length = arm - GAP - RADIUS;
    let inertia = BALL_MASS * (arm * arm + 0.4 * RADIUS * RADIUS)
        + rope_mass * rope_length * rope_length / 3.0;
    let moment = BALL_MASS * arm + rope_mass * rope_length / 2.0;
    let g = scene.world.physics.gravity.as_dvec3().length();
    let expected = 2.0 * PI * (inertia / (moment * g)).sqrt();
    // Whole periods between the first and the last downward crossing.
    let period = match (crossings.first(), crossings.last()) {
        (Some(first), Some(last)) if crossings.len() >= 2 => {
            Some((last - first) / (crossings.len() - 1) as f64)
        }
        _ => None,
    };
    match period {
        Some(period) => println!(
            "period {period:.4} s over {} periods vs compound pendulum {expected:.4} s ({:+.2} %); arm {arm:.4} m (rope stretched by {:.1} mm)",
            crossings.len() - 1,
            100.0 * (period / expected - 1.0),
            (rope_length - LENGTH) * 1e3
        ),
        None => println!(
            "no period: {} downward crossing(s) in {} s",
            crossings.len(),
            FRAMES / FPS
        ),
    }
    let json_or_null = |value: Option<f64>| value.map_or("null".to_string(), |v| format!("{v:.5}"));
    println!(
        "{{\"period_s\": {}, \"expected_period_s\": {expected:.5}, \"period_error\": {}, \"periods_timed\": {}, \"arm_m\": {arm:.5}, \"stretch_mm\": {:.3}}}",
        json_or_null(period),
        json_or_null(period.map(|p| p / expected - 1.0)),
        crossings.len().saturating_sub(1),
        (rope_length - LENGTH) * 1e3
    );
}

fn main() -> Result<(), Error> {
    let mut scene = build_scene()?;
    let (crossings, arm) = swing(&mut scene)?;
    print_summary(&scene, &crossings, arm);
    Ok(())
}

//! Three soft blocks of different materials stacked on rapier ground, a rigid 1 kg box on top,
//! in an [`FvmWorld`] at 60 frames per second: soft bodies resting on soft bodies. Touching soft
//! bodies are stepped together, their contacts solved with both bodies' nodes.
//!
//! Prints, after 2 s, each block's shortening beside the uniaxial estimate `F H/(E A)` for the
//! load on it (what sits above plus half its own weight; the estimate ignores the friction that
//! holds back the lateral expansion, so it is a guide, not a closed form), the ground's reaction
//! over the last second against the total weight, and the deepest overlap between blocks. Last line: one JSON object.
//!
//! Run with `cargo run --release --example soft_stack`.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, RigidBodyBuilder, SharedShape};

/// Side of every block (m).
const SIDE: f64 = 0.1;
const GRAVITY: f64 = 9.81;
const BOX_MASS: f64 = 1.0;

/// A block: its name, Young's modulus (Pa), Poisson's ratio and density (kg/m³).
struct Block {
    name: &'static str,
    young: f64,
    poisson: f64,
    density: f64,
}

const BLOCKS: [Block; 3] = [
    Block {
        name: "stiff rubber",
        young: 1e6,
        poisson: 0.45,
        density: 1100.0,
    },
    Block {
        name: "soft rubber",
        young: 2e5,
        poisson: 0.4,
        density: 1000.0,
    },
    Block {
        name: "foam",
        young: 5e4,
        poisson: 0.1,
        density: 200.0,
    },
];

/// The mean height (m) of the nodes of `body` whose rest height is `rest_y` (m).
fn layer_height(body: &DeformableBody, rest_y: f64) -> f64 {
    let layer = body.mesh().nodes_where(|p| (p.y - rest_y).abs() < 1e-9);
    layer
        .iter()
        .map(|&n| body.positions()[n as usize].y)
        .sum::<f64>()
        / layer.len() as f64
}

/// The world, the ground's collider and the blocks' handles, bottom first.
struct Scene {
    world: FvmWorld,
    ground: ColliderHandle,
    handles: Vec<DeformableBodyHandle>,
}

/// The ground, the three blocks stacked on it (1 mm apart) and the rigid box on top.
fn build_scene() -> Result<Scene, Error> {
    let mut world = FvmWorld::default();
    let ground = world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.8),
        None,
    );
    let mut handles = Vec::new();
    for (level, block) in BLOCKS.iter().enumerate() {
        let material = Material::new(
            MaterialModel::StableNeoHookean,
            block.young,
            block.poisson,
            block.density,
        )?;
        let body =
            DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(SIDE / 2.0), [4; 3])?, material)
                .damping(RayleighDamping::stiffness_proportional(
                    2e-3,
                    material.lame(),
                )?)
                .translation(DVec3::new(
                    0.0,
                    (level as f64 + 0.5) * SIDE + 1e-3 * level as f64,
                    0.0,
                ))
                .friction(0.8)
                .build()?;
        handles.push(world.soft_bodies.insert(body));
    }
    let half = (SIDE / 2.0 * 0.8) as f32;
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(
            0.0,
            (3.0 * SIDE) as f32 + 0.01 + half,
            0.0,
        )),
        ColliderBuilder::cuboid(half, half, half)
            .mass(BOX_MASS as f32)
            .friction(0.8),
    );
    Ok(Scene {
        world,
        ground,
        handles,
    })
}

/// Runs 2 s; returns the deepest overlap between blocks (m) and the last second's reaction (N).
fn run(scene: &mut Scene) -> Result<(f64, f64), Error> {
    let frames = 120;
    let world = &mut scene.world;
    let (mut deepest, mut reaction) = (0.0f64, 0.0);
    for frame in 0..frames {
        for (_, outcome) in world.step() {
            outcome?;
        }
        if frame >= frames - 60 {
            let (force, _) = world.contact_force_on(scene.handles[0], scene.ground)?;
            reaction -= force.y / 60.0;
        }
        for pair in scene.handles.windows(2) {
            let below = layer_height(&world.soft_bodies[pair[0]], SIDE / 2.0);
            let above = world.soft_bodies[pair[1]]
                .positions()
                .iter()
                .map(|x| x.y)
                .fold(f64::INFINITY, f64::min);
            deepest = deepest.max(below - above);
        }
    }
    Ok((deepest, reaction))
}

/// Prints each block's shortening and estimate; returns the total weight (N) and JSON rows.
fn print_blocks(scene: &Scene) -> (f64, Vec<String>) {
    println!(
        "{:<14} {:>10} {:>16} {:>16}",
        "block", "E (Pa)", "shortening (mm)", "uniaxial (mm)"
    );
    let mut load_above = BOX_MASS * GRAVITY;
    let mut rows = Vec::new();
    for (block, handle) in BLOCKS.iter().zip(&scene.handles).rev() {
        let body = &scene.world.soft_bodies[*handle];
        let weight = body.total_mass() * GRAVITY;
        let shortening = SIDE - (layer_height(body, SIDE / 2.0) - layer_height(body, -SIDE / 2.0));
        let estimate = (load_above + weight / 2.0) * SIDE / (block.young * SIDE * SIDE);
        println!(
            "{:<14} {:>10.0e} {:>16.4} {:>16.4}",
            block.name,
            block.young,
            shortening * 1e3,
            estimate * 1e3
        );
        rows.push(format!(
            "{{\"block\": \"{}\", \"shortening_mm\": {:.5}, \"uniaxial_mm\": {:.5}}}",
            block.name,
            shortening * 1e3,
            estimate * 1e3
        ));
        load_above += weight;
    }
    (load_above, rows)
}

fn main() -> Result<(), Error> {
    let mut scene = build_scene()?;
    let (deepest, reaction) = run(&mut scene)?;
    let (total_weight, rows) = print_blocks(&scene);
    println!(
        "ground reaction (mean of the last second) {:.4} N for a total weight of {:.4} N; deepest overlap between blocks {:.4} mm",
        reaction,
        total_weight,
        deepest * 1e3
    );
    println!(
        "{{\"ground_reaction_n\": {:.5}, \"total_weight_n\": {:.5}, \"deepest_overlap_mm\": {:.5}, \"blocks\": [{}]}}",
        reaction,
        total_weight,
        deepest * 1e3,
        rows.join(", ")
    );
    Ok(())
}

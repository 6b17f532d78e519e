//! Deformable bodies beside a program's own rapier pipeline: the program keeps its
//! `PhysicsPipeline` and its sets (rapier's documented way of stepping, and what game-engine
//! plugins do), and [`SoftCoupling::step`] runs the soft steps between rapier's substeps on
//! them. The same scene through [`FvmWorld`] gives the same trajectories, bit for bit.
//!
//! The scene: a 1 kg rigid box (10 cm) dropped from 5 cm onto a soft block (20 cm, stable
//! Neo-Hookean, E = 1e6 Pa, ν = 0.3, 1000 kg/m³, Rayleigh damping 2e-3 s) on a fixed ground,
//! 1 s at 60 frames per second. Prints every 0.25 s the box's height and the block's centre of
//! mass height (mm) for both programs, and the largest difference between them (m).
//!
//! Run with `cargo run --release --example own_pipeline`.

use rapier_fvm::prelude::*;
use rapier3d::prelude::*;

/// Frames of 1/60 s.
const FRAMES: usize = 60;
/// The block's side and the box's (m).
const BLOCK_SIDE: f64 = 0.2;
const BOX_SIDE: f32 = 0.1;

/// A program's own rapier world: the pipeline and every set its step takes, plus the deformable
/// bodies and their coupling.
struct OwnWorld {
    pipeline: PhysicsPipeline,
    gravity: Vector,
    parameters: IntegrationParameters,
    islands: IslandManager,
    broad_phase: DefaultBroadPhase,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    rapier_soft_bodies: SoftBodySet,
    ccd_solver: CCDSolver,
    deformables: DeformableBodySet,
    coupling: SoftCoupling,
}

impl OwnWorld {
    fn new() -> Self {
        Self {
            pipeline: PhysicsPipeline::new(),
            gravity: Vector::Y * -9.81,
            parameters: IntegrationParameters::default(),
            islands: IslandManager::new(),
            broad_phase: DefaultBroadPhase::default(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            rapier_soft_bodies: SoftBodySet::new(),
            ccd_solver: CCDSolver::new(),
            deformables: DeformableBodySet::new(),
            coupling: SoftCoupling::default(),
        }
    }

    /// One frame: rapier's substeps on the program's own sets, the soft steps between them.
    fn step(&mut self) -> Result<(), Error> {
        let rapier = RapierSets {
            gravity: self.gravity,
            integration_parameters: &self.parameters,
            islands: &mut self.islands,
            broad_phase: &mut self.broad_phase,
            narrow_phase: &mut self.narrow_phase,
            bodies: &mut self.bodies,
            colliders: &mut self.colliders,
            impulse_joints: &mut self.impulse_joints,
            multibody_joints: &mut self.multibody_joints,
            rapier_soft_bodies: &mut self.rapier_soft_bodies,
            ccd_solver: &mut self.ccd_solver,
        };
        let results =
            self.coupling
                .step(&mut self.pipeline, rapier, &mut self.deformables, &(), &());
        for (_handle, result) in results {
            result?;
        }
        Ok(())
    }
}

/// The soft block, standing on the ground.
fn block() -> Result<DeformableBody, Error> {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    let cube = mesh::cuboid(DVec3::splat(BLOCK_SIDE / 2.0), [4; 3])?;
    DeformableBodyBuilder::new(cube, rubber)
        .damping(RayleighDamping::stiffness_proportional(
            2e-3,
            rubber.lame(),
        )?)
        .translation(DVec3::new(0.0, BLOCK_SIDE / 2.0, 0.0))
        .build()
}

/// The ground and the box (1 kg: 1000 kg/m³), 5 cm above the block.
fn ground_and_box() -> (Collider, RigidBody, Collider) {
    let ground = ColliderBuilder::new(SharedShape::halfspace(Vector::Y))
        .friction(0.8)
        .build();
    let height = BLOCK_SIDE as f32 + BOX_SIDE / 2.0 + 0.05;
    let body = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.0, height, 0.0))
        .build();
    let half = BOX_SIDE / 2.0;
    let collider = ColliderBuilder::cuboid(half, half, half)
        .density(1000.0)
        .friction(0.8)
        .build();
    (ground, body, collider)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The program's own pipeline and sets.
    let mut own = OwnWorld::new();
    let (ground, body, collider) = ground_and_box();
    own.colliders.insert(ground.clone());
    let own_box = own.bodies.insert(body.clone());
    own.colliders
        .insert_with_parent(collider.clone(), own_box, &mut own.bodies);
    let own_block = own.deformables.insert(block()?);

    // The same scene in an FvmWorld.
    let mut world = FvmWorld::default();
    world.physics.insert_collider(ground, None);
    let (world_box, _) = world.physics.insert(body, collider);
    let world_block = world.soft_bodies.insert(block()?);

    println!(
        "   t (s) | box, own (mm) | box, FvmWorld (mm) | block, own (mm) | block, FvmWorld (mm)"
    );
    let mut largest_difference = 0.0_f64;
    for frame in 1..=FRAMES {
        own.step()?;
        for (_handle, result) in world.step() {
            result?;
        }
        let own_positions = own.deformables[own_block].positions();
        let world_positions = world.soft_bodies[world_block].positions();
        for (a, b) in own_positions.iter().zip(world_positions) {
            largest_difference = largest_difference.max((*a - *b).length());
        }
        let own_box_y = own.bodies[own_box].translation().y;
        let world_box_y = world.physics.bodies[world_box].translation().y;
        largest_difference = largest_difference.max(f64::from((own_box_y - world_box_y).abs()));
        if frame % 15 == 0 {
            println!(
                "{:8.2} | {:13.3} | {:18.3} | {:15.3} | {:20.3}",
                frame as f64 / 60.0,
                own_box_y * 1e3,
                world_box_y * 1e3,
                own.deformables[own_block].center_of_mass().y * 1e3,
                world.soft_bodies[world_block].center_of_mass().y * 1e3,
            );
        }
    }
    println!("largest difference between the two programs: {largest_difference:e} m");
    if largest_difference != 0.0 {
        return Err("the program's own pipeline and FvmWorld stepped apart".into());
    }
    Ok(())
}

//! `SoftCoupling::step` on a program's own `PhysicsPipeline` and sets moves a scene exactly as
//! `FvmWorld` does: the same floating-point operations in the same order, so the trajectories
//! must agree bit for bit (tolerance 0). The scene exercises every coupling path: a soft rod glued
//! to a position-based kinematic body driven around a circle (kinematic paths, attachments), a
//! soft cube on the ground (fixed colliders) carrying a dynamic box (impulses to rapier, loads).

use rapier_fvm::coupling::SoftStepResults;
use rapier_fvm::prelude::*;
use rapier3d::prelude::*;

/// Frames of 1/60 s.
const FRAMES: usize = 40;

/// A program's own rapier sets.
struct OwnSets {
    pipeline: PhysicsPipeline,
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
}

impl OwnSets {
    fn new() -> Self {
        Self {
            pipeline: PhysicsPipeline::new(),
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
        }
    }

    fn step(
        &mut self,
        coupling: &mut SoftCoupling,
        soft: &mut DeformableBodySet,
    ) -> SoftStepResults {
        let rapier = RapierSets {
            gravity: Vector::Y * -9.81,
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
        coupling.step(&mut self.pipeline, rapier, soft, &(), &())
    }
}

/// The scene's handles in one world.
struct Scene {
    driver: RigidBodyHandle,
    carried: RigidBodyHandle,
    rod: DeformableBodyHandle,
    cube: DeformableBodyHandle,
}

/// Builds the scene into `bodies`, `colliders` and `soft`, the rod's attachment into the
/// `coupling` that steps them.
fn build(
    bodies: &mut RigidBodySet,
    colliders: &mut ColliderSet,
    soft: &mut DeformableBodySet,
    coupling: &mut SoftCoupling,
) -> Result<Scene, Error> {
    colliders.insert(ColliderBuilder::new(SharedShape::halfspace(Vector::Y)).friction(0.8));
    let driver = bodies.insert(
        RigidBodyBuilder::kinematic_position_based().translation(Vector::new(0.05, 0.6, 0.0)),
    );
    colliders.insert_with_parent(ColliderBuilder::ball(0.01).sensor(true), driver, bodies);
    let carried =
        bodies.insert(RigidBodyBuilder::dynamic().translation(Vector::new(0.5, 0.25, 0.0)));
    colliders.insert_with_parent(
        ColliderBuilder::cuboid(0.04, 0.04, 0.04).density(500.0),
        carried,
        bodies,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 2e5, 0.3, 1000.0)?;
    let damping = RayleighDamping::stiffness_proportional(2e-3, rubber.lame())?;
    let rod_mesh = mesh::cuboid(DVec3::new(0.02, 0.1, 0.02), [1, 5, 1])?;
    let root = rod_mesh.nodes_where(|p| p.y >= 0.1 - 1e-9);
    let rod = DeformableBodyBuilder::new(rod_mesh, rubber)
        .damping(damping)
        .translation(DVec3::new(0.05, 0.5, 0.0))
        .build()?;
    let rod = soft.insert(rod);
    coupling.attach(soft, rod, root, driver, bodies)?;
    let cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [3; 3])?, rubber)
        .damping(damping)
        .translation(DVec3::new(0.5, 0.1, 0.0))
        .build()?;
    let cube = soft.insert(cube);
    Ok(Scene {
        driver,
        carried,
        rod,
        cube,
    })
}

/// Where the kinematic driver is told to be at the end of `frame`: a 5 cm circle once a second.
fn driver_target(frame: usize) -> Vector {
    let angle = std::f32::consts::TAU * frame as f32 / 60.0;
    Vector::new(0.05 * angle.cos(), 0.6, 0.05 * angle.sin())
}

/// The scene built twice: on a program's own sets, and in an `FvmWorld`, each stepped with
/// `substeps` coupling substeps per frame.
struct Pair {
    own: OwnSets,
    own_soft: DeformableBodySet,
    own_coupling: SoftCoupling,
    own_scene: Scene,
    world: FvmWorld,
    world_scene: Scene,
}

impl Pair {
    fn new(substeps: u32) -> Result<Self, Error> {
        let mut own = OwnSets::new();
        let mut own_soft = DeformableBodySet::new();
        let mut own_coupling = SoftCoupling::default();
        own_coupling.substeps = substeps;
        let own_scene = build(
            &mut own.bodies,
            &mut own.colliders,
            &mut own_soft,
            &mut own_coupling,
        )?;
        let mut world = FvmWorld::default();
        world.coupling.substeps = substeps;
        let physics = &mut world.physics;
        let world_scene = build(
            &mut physics.bodies,
            &mut physics.colliders,
            &mut world.soft_bodies,
            &mut world.coupling,
        )?;
        Ok(Self {
            own,
            own_soft,
            own_coupling,
            own_scene,
            world,
            world_scene,
        })
    }
}

#[test]
fn own_pipeline_and_fvm_world_step_a_scene_bit_identically() -> Result<(), Error> {
    let Pair {
        mut own,
        mut own_soft,
        mut own_coupling,
        own_scene,
        mut world,
        world_scene,
    } = Pair::new(4)?;

    for frame in 1..=FRAMES {
        own.bodies[own_scene.driver].set_next_kinematic_translation(driver_target(frame));
        world.physics.bodies[world_scene.driver]
            .set_next_kinematic_translation(driver_target(frame));
        for (handle, result) in own.step(&mut own_coupling, &mut own_soft) {
            result.unwrap_or_else(|e| panic!("own pipeline, {handle:?}: {e}"));
        }
        for (handle, result) in world.step() {
            result.unwrap_or_else(|e| panic!("FvmWorld, {handle:?}: {e}"));
        }
        for (own_body, world_body) in [
            (own_scene.rod, world_scene.rod),
            (own_scene.cube, world_scene.cube),
        ] {
            assert_eq!(
                own_soft[own_body].positions(),
                world.soft_bodies[world_body].positions(),
                "frame {frame}"
            );
            assert_eq!(
                own_soft[own_body].velocities(),
                world.soft_bodies[world_body].velocities(),
                "frame {frame}"
            );
        }
        let (own_box, world_box) = (
            &own.bodies[own_scene.carried],
            &world.physics.bodies[world_scene.carried],
        );
        assert_eq!(own_box.position(), world_box.position(), "frame {frame}");
        assert_eq!(own_box.linvel(), world_box.linvel(), "frame {frame}");
        assert_eq!(
            own_coupling.rigid_loads(),
            world.rigid_loads(),
            "frame {frame}"
        );
        assert_eq!(
            own_coupling.collider_loads(),
            world.collider_loads(),
            "frame {frame}"
        );
    }
    // The scene did what it is for: the box rests on the cube (its weight, 2.5 N, comes through
    // the cube's contacts within 20 %, a loose bound on a frame's mean load while it settles).
    let (force, _) = world.load_on(world_scene.cube, world_scene.carried);
    let weight = 500.0 * 0.08f64.powi(3) * 9.81;
    assert!(
        (force.y - weight).abs() < 0.2 * weight,
        "load {force} N for weight {weight} N"
    );
    assert!(!world.rigid_loads().is_empty());
    Ok(())
}

/// One rapier step of the frame's `dt` on `sets`, as a program that steps rapier itself does.
fn rapier_step(sets: &mut OwnSets) {
    sets.pipeline.step(
        Vector::Y * -9.81,
        &sets.parameters,
        &mut sets.islands,
        &mut sets.broad_phase,
        &mut sets.narrow_phase,
        &mut sets.bodies,
        &mut sets.colliders,
        &mut sets.impulse_joints,
        &mut sets.multibody_joints,
        &mut sets.rapier_soft_bodies,
        &mut sets.ccd_solver,
        &(),
        &(),
    );
}

#[test]
fn a_soft_substep_between_own_rapier_steps_matches_a_world_of_one_substep() -> Result<(), Error> {
    // `SoftCoupling::substep` then the program's own rapier step is what `FvmWorld` does with one
    // coupling substep per frame (the kinematic driver stays put: its path is the frame's), the
    // rapier step running one solver iteration as `substep` asks when implicit steps move
    // dynamic rigid bodies (the cube under the carried box steps implicitly: with rapier's
    // default four iterations the box ended frame 2 1.0 mm higher than `FvmWorld`, which
    // corrects rapier's carry and a program's own step cannot).
    let Pair {
        mut own,
        mut own_soft,
        mut own_coupling,
        own_scene,
        mut world,
        world_scene,
    } = Pair::new(1)?;
    own.parameters.num_solver_iterations = 1;
    world.physics.integration_parameters.num_solver_iterations = 1;
    let dt = f64::from(own.parameters.dt);
    // Gravity as rapier holds it (f32), as the world hands it to its soft bodies.
    let gravity = (Vector::Y * -9.81).as_dvec3();
    for frame in 1..=FRAMES {
        let rigid = RigidSets {
            bodies: &mut own.bodies,
            colliders: &own.colliders,
            narrow_phase: &own.narrow_phase,
        };
        for (handle, result) in own_coupling.substep(&mut own_soft, rigid, dt, gravity) {
            result.unwrap_or_else(|e| panic!("own substep, {handle:?}: {e}"));
        }
        rapier_step(&mut own);
        for (handle, result) in world.step() {
            result.unwrap_or_else(|e| panic!("FvmWorld, {handle:?}: {e}"));
        }
        assert_eq!(
            own_soft[own_scene.cube].positions(),
            world.soft_bodies[world_scene.cube].positions(),
            "frame {frame}"
        );
        assert_eq!(
            own.bodies[own_scene.carried].position(),
            world.physics.bodies[world_scene.carried].position(),
            "frame {frame}"
        );
        assert_eq!(
            own_coupling.rigid_loads(),
            world.rigid_loads(),
            "frame {frame}"
        );
    }
    Ok(())
}

//! Two rigid fingers lifting a soft cube by friction: a 5 cm soft cube (stable Neo-Hookean,
//! E = 1e5 Pa, ν = 0.3, 1000 kg/m³, 4 x 4 x 4 cells, stiffness-proportional Rayleigh damping
//! 2e-3 s) rests on a fixed half-space ground (friction 0.5) between two position-based
//! kinematic fingers (cuboids 1 x 4 x 4 cm, friction 1.0) that start 2 mm from its faces, in an
//! [`FvmWorld`] at 60 frames per second with the automatic choice of integrator. After 0.25 s to
//! settle, the fingers close over 0.5 s to squeeze the cube by 2 mm a side, lift 10 cm over 1 s
//! and hold for 0.5 s, told their pose once a frame (`set_next_kinematic_translation`): how
//! kinematic rigid bodies drive a soft body, and whether friction alone carries it.
//!
//! Prints every 0.25 s the phase, the fingers' centre height (mm), the cube's centre of mass and
//! lowest node heights (mm), the squeeze (the x force on the right finger, N), the lift (the
//! upward force of both fingers on the cube, N) and the integrator of the row's last frame. Then
//! how far the cube slipped down the fingers during the lift and hold (mm), its lowest node at
//! the end (mm), the deepest any node ever was inside a finger (mm), and the lift averaged over
//! the hold's frames and at the end against the cube's weight (N). The forces are each frame's
//! mean ([`FvmWorld::load_on`]), so the hold's average is short of the weight by the cube's
//! momentum lost as the fingers stop, m Δv / T = 0.125 kg x 0.1 m/s / 0.5 s = 0.025 N.
//! Last line: one JSON object.
//!
//! Run with `cargo run --release --example grasp`.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, RigidBodyBuilder, RigidBodyHandle, SharedShape,
};

/// The cube's half side and the fingers' half thickness (m).
const HALF: f64 = 0.025;
const FINGER_HALF: f64 = 0.005;
/// The fingers' half height and half depth (m).
const FINGER_HALF_SIDE: f32 = 0.02;
/// The fingers' initial gap to the cube's faces and the squeeze per side (m).
const GAP: f64 = 2e-3;
const SQUEEZE: f64 = 2e-3;
/// How high the fingers lift (m).
const LIFT_HEIGHT: f64 = 0.1;
/// The phases' durations (s).
const SETTLE: f64 = 0.25;
const CLOSE: f64 = 0.5;
const LIFT: f64 = 1.0;
const HOLD: f64 = 0.5;
/// Frames per table row (0.25 s at 60 frames per second).
const ROW_FRAMES: usize = 15;

/// What the fingers do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Settle,
    Close,
    Lift,
    Hold,
}

impl Phase {
    /// The phase at `t` (s) after the settling.
    fn at(t: f64) -> Self {
        if t < 0.0 {
            Self::Settle
        } else if t < CLOSE {
            Self::Close
        } else if t < CLOSE + LIFT {
            Self::Lift
        } else {
            Self::Hold
        }
    }
}

/// Steps the world one frame, failing on the first soft body that failed; returns the
/// integrator of the last soft body's last substep.
fn step(world: &mut FvmWorld) -> Result<Option<IntegratorKind>, Error> {
    let mut choice = None;
    for (_, outcome) in world.step() {
        choice = Some(outcome?.choice);
    }
    Ok(choice)
}

/// The deepest (m) any of `positions` lies inside `collider`, 0 if none does.
fn depth_inside(world: &FvmWorld, collider: ColliderHandle, positions: &[DVec3]) -> f64 {
    let collider = &world.physics.colliders[collider];
    positions
        .iter()
        .map(|x| {
            let projection =
                collider
                    .shape()
                    .project_point(collider.position(), x.as_vec3(), false);
            if projection.is_inside {
                (projection.point.as_dvec3() - *x).length()
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// The scene: the world, the cube's handle and the fingers' body and collider handles.
struct Scene {
    world: FvmWorld,
    cube: DeformableBodyHandle,
    fingers: [(RigidBodyHandle, ColliderHandle); 2],
}

/// Left (x < 0) then right.
const SIDES: [f64; 2] = [-1.0, 1.0];

/// The ground, the soft cube on it and the two kinematic fingers beside it.
fn build_scene() -> Result<Scene, Error> {
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
    let cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(HALF), [4; 3])?, rubber)
        .damping(RayleighDamping::stiffness_proportional(
            2e-3,
            rubber.lame(),
        )?)
        .translation(DVec3::new(0.0, HALF, 0.0))
        .friction(1.0)
        .build()?;
    let cube = world.soft_bodies.insert(cube);
    let fingers = SIDES.map(|side| {
        let x = side * (HALF + FINGER_HALF + GAP);
        world.physics.insert(
            RigidBodyBuilder::kinematic_position_based().translation(Vec3::new(
                x as f32,
                HALF as f32,
                0.0,
            )),
            ColliderBuilder::cuboid(FINGER_HALF as f32, FINGER_HALF_SIDE, FINGER_HALF_SIDE)
                .friction(1.0),
        )
    });
    Ok(Scene {
        world,
        cube,
        fingers,
    })
}

/// What the run measured, frame by frame and at its end.
#[derive(Debug, Default)]
struct Tally {
    /// The cube's centre of mass and the fingers' heights (m) when the lift starts.
    lift_start: (f64, f64),
    /// The deepest (m) any node was inside a finger.
    deepest: f64,
    /// The lift and squeeze (N) summed over the hold's frames, and their count.
    hold_lift: f64,
    hold_squeeze: f64,
    hold_frames: usize,
    /// Frames the automatic integrator stepped explicitly and implicitly.
    explicit_frames: usize,
    implicit_frames: usize,
    /// The lift (N) of the last frame.
    end_lift: f64,
}

impl Scene {
    /// The fingers' height (m).
    fn finger_height(&self) -> f64 {
        f64::from(self.world.physics.bodies[self.fingers[0].0].translation().y)
    }

    /// The cube's centre of mass and the fingers' heights (m).
    fn heights(&self) -> (f64, f64) {
        (
            self.world.soft_bodies[self.cube].center_of_mass().y,
            self.finger_height(),
        )
    }

    /// Tells the fingers their pose at `t` (s) after the settling.
    fn move_fingers(&mut self, t: f64) {
        let closing = (t / CLOSE).clamp(0.0, 1.0);
        let lifting = ((t - CLOSE) / LIFT).clamp(0.0, 1.0);
        for ((finger, _), side) in self.fingers.iter().zip(SIDES) {
            let x = side * (HALF + FINGER_HALF + GAP - (GAP + SQUEEZE) * closing);
            let y = HALF + LIFT_HEIGHT * lifting;
            self.world.physics.bodies[*finger]
                .set_next_kinematic_translation(Vec3::new(x as f32, y as f32, 0.0));
        }
    }

    /// The frame's lift and squeeze (N) on the fingers; notes the deepest node inside one.
    fn measure(&self, tally: &mut Tally) -> (f64, f64) {
        let body = &self.world.soft_bodies[self.cube];
        let mut lift = 0.0;
        for (finger, collider) in &self.fingers {
            tally.deepest =
                tally
                    .deepest
                    .max(depth_inside(&self.world, *collider, body.positions()));
            lift -= self.world.load_on(self.cube, *finger).0.y;
        }
        let squeeze = self.world.load_on(self.cube, self.fingers[1].0).0.x;
        (lift, squeeze)
    }
}

/// The lowest node height (m) of `body`.
fn lowest_node(body: &DeformableBody) -> f64 {
    body.positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min)
}

/// Prints the table's header.
fn print_header() {
    println!(
        "{:>6} {:>7} {:>12} {:>12} {:>13} {:>12} {:>9} {:>10}",
        "t (s)",
        "phase",
        "finger (mm)",
        "centre (mm)",
        "lowest (mm)",
        "squeeze (N)",
        "lift (N)",
        "integrator"
    );
}

/// Prints the table row of `frame`.
fn print_row(
    scene: &Scene,
    frame: usize,
    phase: Phase,
    (lift, squeeze): (f64, f64),
    choice: Option<IntegratorKind>,
) {
    let dt = f64::from(scene.world.physics.integration_parameters.dt);
    let body = &scene.world.soft_bodies[scene.cube];
    let choice = choice.map_or_else(|| "-".to_owned(), |kind| format!("{kind:?}"));
    println!(
        "{:>6.2} {:>7} {:>12.3} {:>12.3} {:>13.3} {:>12.3} {:>9.4} {:>10}",
        frame as f64 * dt,
        format!("{phase:?}"),
        scene.world.physics.bodies[scene.fingers[0].0]
            .translation()
            .y
            * 1e3,
        body.center_of_mass().y * 1e3,
        lowest_node(body) * 1e3,
        squeeze,
        lift,
        choice
    );
}

/// Runs the settling, closing, lift and hold, printing a table row every [`ROW_FRAMES`] frames.
fn run(scene: &mut Scene) -> Result<Tally, Error> {
    let dt = f64::from(scene.world.physics.integration_parameters.dt);
    let frames = ((SETTLE + CLOSE + LIFT + HOLD) / dt).round() as usize;
    let mut tally = Tally {
        lift_start: scene.heights(),
        ..Tally::default()
    };
    for frame in 1..=frames {
        let t = frame as f64 * dt - SETTLE;
        // The frame's phase, going by its middle.
        let phase = Phase::at(t - dt / 2.0);
        scene.move_fingers(t);
        let choice = step(&mut scene.world)?;
        match choice {
            Some(IntegratorKind::Explicit) => tally.explicit_frames += 1,
            Some(IntegratorKind::Implicit) => tally.implicit_frames += 1,
            None => {}
        }
        let (lift, squeeze) = scene.measure(&mut tally);
        tally.end_lift = lift;
        if phase == Phase::Close {
            tally.lift_start = scene.heights();
        }
        if phase == Phase::Hold {
            tally.hold_lift += lift;
            tally.hold_squeeze += squeeze;
            tally.hold_frames += 1;
        }
        if frame % ROW_FRAMES == 0 {
            print_row(scene, frame, phase, (lift, squeeze), choice);
        }
    }
    Ok(tally)
}

/// Prints the slip, lowest and deepest nodes, lift against the weight, then the JSON line.
fn print_summary(scene: &Scene, tally: &Tally) {
    let body = &scene.world.soft_bodies[scene.cube];
    let g = scene.world.physics.gravity.as_dvec3().length();
    let weight = body.total_mass() * g;
    let margin = scene.world.coupling.contact.margin;
    let (cube_start, finger_start) = tally.lift_start;
    let finger_rise = scene.finger_height() - finger_start;
    let slip = finger_rise - (body.center_of_mass().y - cube_start);
    let lowest = lowest_node(body);
    let deepest = tally.deepest;
    let hold_frames = tally.hold_frames.max(1) as f64;
    let (lift, squeeze) = (
        tally.hold_lift / hold_frames,
        tally.hold_squeeze / hold_frames,
    );
    let (end_lift, explicit_frames, implicit_frames) =
        (tally.end_lift, tally.explicit_frames, tally.implicit_frames);
    println!(
        "slip {:.3} mm down the fingers over a {:.1} mm lift; lowest node {:.2} mm; deepest in a finger {:.3} mm (margin {:.1} mm); lift over the hold {lift:.4} N and at the end {end_lift:.4} N vs weight {weight:.4} N ({:+.2} %, {:+.3} %), squeeze {squeeze:.3} N; {explicit_frames} explicit and {implicit_frames} implicit frames",
        slip * 1e3,
        finger_rise * 1e3,
        lowest * 1e3,
        deepest * 1e3,
        margin * 1e3,
        100.0 * (lift / weight - 1.0),
        100.0 * (end_lift / weight - 1.0)
    );
    println!(
        "{{\"slip_mm\": {:.4}, \"lowest_node_mm\": {:.3}, \"deepest_in_finger_mm\": {:.4}, \"margin_mm\": {:.2}, \"hold_lift_n\": {lift:.5}, \"end_lift_n\": {end_lift:.5}, \"weight_n\": {weight:.5}, \"lift_error\": {:.3e}, \"hold_squeeze_n\": {squeeze:.4}, \"explicit_frames\": {explicit_frames}, \"implicit_frames\": {implicit_frames}}}",
        slip * 1e3,
        lowest * 1e3,
        deepest * 1e3,
        margin * 1e3,
        lift / weight - 1.0
    );
}

fn main() -> Result<(), Error> {
    let mut scene = build_scene()?;
    print_header();
    let tally = run(&mut scene)?;
    print_summary(&scene, &tally);
    Ok(())
}

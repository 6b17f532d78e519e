//! Scenes 4-5: a soft cube dropped on the ground (`drop`) and a rigid box resting on a soft
//! block whose bottom face is pinned (`box_on_block`). Rapier's soft bodies collide through
//! their boundary surface with a contact skin, the particle radius: by default half the
//! smallest particle spacing; each scene also runs the coarse grid with a 2 mm skin.

use crate::budget::{Budget, CASE_LIMIT_S};
use crate::record::{self, Record};
use crate::setup::{self, DEFAULT_DAMPING, Grid, SOFT, SOLVERS, Solver};
use compare_common::contact::{BoxTrace, DT, DropTrace};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use rapier3d::prelude::*;
use serde_json::json;
use std::time::Instant;

/// The explicit thin skin (m), the flex radius of the `MuJoCo` runs.
const THIN_SKIN: f64 = 0.002;

/// A contact case: the grid's particles per axis and the skin (`None`: rapier's default).
type ContactCase = ([usize; 3], Option<f64>);

/// The grid as a colliding soft body (friction 0.5), with the skin `radius` if given.
fn colliding_body(grid: &Grid, radius: Option<f64>, solver: Solver) -> SoftBodyBuilder {
    let builder = setup::grid_body(grid, SOFT, DEFAULT_DAMPING, solver)
        .surface_collider(ColliderBuilder::ball(0.05).friction(FRICTION as Real));
    match radius {
        Some(r) => builder.particle_radius(r as Real),
        None => builder,
    }
}

/// Settings shared by the contact scenes.
fn contact_settings(
    world: &PhysicsWorld,
    solver: Solver,
    grid: &Grid,
    builder: &SoftBodyBuilder,
    radius: Option<f64>,
) -> Record {
    let mut s = setup::settings(world, solver, grid, SOFT, DEFAULT_DAMPING);
    s.extend(record::object(json!({
        "damping_beta": null,
        "damping_note": "the scene's beta = 0.01 s has no rapier counterpart (no Rayleigh input); \
                         rapier's default elastic_damping_ratio 1 (per-cell beta = 2 zeta/omega_cell)",
        "particle_radius": builder.particle_radius as f64,
        "particle_radius_is": if radius.is_some() { "set explicitly" } else {
            "rapier's default: half the smallest particle spacing (SoftBodyBuilder::cuboid)" },
        "contact_stiffening": world.integration_parameters.soft_bodies.contact_stiffening as f64,
        "allowed_linear_error": world.integration_parameters.allowed_linear_error() as f64,
        "friction": FRICTION,
    })));
    s
}

fn case_name(grid: &Grid, radius: Option<f64>, solver: Solver) -> String {
    let skin = radius.map_or("default skin".to_string(), |r| format!("skin={r}"));
    format!("{} {skin} {}", grid.label(), solver.label())
}

/// Runs `cases` with both solvers, skipping a resolution the previous one predicts over budget.
fn run_cases(
    scene: &str,
    cases: &[ContactCase],
    grid_of: fn([usize; 3]) -> Grid,
    run: fn(&Grid, Option<f64>, Solver) -> f64,
) {
    for solver in SOLVERS {
        let mut budget = Budget::new(solver, CASE_LIMIT_S);
        for &(particles, radius) in cases {
            let g = grid_of(particles);
            match budget.check(g.num_particles()) {
                Ok(()) => budget.record(g.num_particles(), run(&g, radius, solver)),
                Err(reason) => {
                    let world = setup::world(DT, solver);
                    let settings = contact_settings(
                        &world,
                        solver,
                        &g,
                        &colliding_body(&g, radius, solver),
                        radius,
                    );
                    record::skipped(
                        scene,
                        &case_name(&g, radius, solver),
                        settings,
                        g.elements(),
                        &reason,
                    );
                }
            }
        }
    }
}

/// The dropped cube: 0.2 m, bottom face at 0.5 m.
fn drop_grid(particles: [usize; 3]) -> Grid {
    Grid {
        center: [0.0, 0.0, DROP_HEIGHT + DROP_SIZE / 2.0],
        size: [DROP_SIZE; 3],
        particles,
    }
}

/// Scene 4: the cube falls, bounces and rests; its resting centroid height against the
/// uniaxial-stress closed form.
pub fn scene_drop(quick: bool) {
    let cases: &[ContactCase] = if quick {
        &[([5; 3], None)]
    } else {
        &[([5; 3], None), ([5; 3], Some(THIN_SKIN)), ([9; 3], None)]
    };
    run_cases("drop", cases, drop_grid, drop_case);
}

/// One drop; returns its wall time.
fn drop_case(g: &Grid, radius: Option<f64>, solver: Solver) -> f64 {
    const T_END: f64 = 2.5;
    let start = Instant::now();
    let mut world = setup::world(DT, solver);
    setup::add_ground(&mut world);
    let builder = colliding_body(g, radius, solver);
    let mut settings = contact_settings(&world, solver, g, &builder, radius);
    let skin = builder.particle_radius as f64;
    let handle = world.insert_soft_body(builder);
    let mut timer = Timer::new(CpuClock::Thread);
    let (mut trace, mut stable) = (DropTrace::default(), true);
    for _ in 0..(T_END / DT).round() as usize {
        timer.time(|| world.step());
        let sb = &world.soft_bodies[handle];
        if !setup::body_ok(sb) {
            stable = false;
            break;
        }
        let z: Vec<f64> = sb.particle_positions().map(|p| p.z as f64).collect();
        trace.push(&z);
    }
    settings.extend(record::object(json!({
        "drop_height_bottom": DROP_HEIGHT, "duration_s": T_END,
        "ground": "fixed cuboid collider, top face at z = 0",
    })));
    let mut r = record::base(
        "drop",
        &case_name(g, radius, solver),
        settings,
        g.elements(),
    );
    record::extend(&mut r, trace.fields(stable));
    record::extend(
        &mut r,
        json!({
            "peak_penetration_into_margin": stable.then(|| (skin - trace.lowest()).max(0.0)),
        }),
    );
    record::extend(&mut r, timer.fields());
    record::emit(r);
    start.elapsed().as_secs_f64()
}

/// The soft block: 0.3 x 0.3 x 0.1 m, centred on the z axis, bottom face on z = 0.
fn block_grid(particles: [usize; 3]) -> Grid {
    Grid {
        center: [0.0, 0.0, BLOCK_SIZE[2] / 2.0],
        size: BLOCK_SIZE,
        particles,
    }
}

/// Scene 5: a rigid 1 kg box released 1 mm above the block's contact skin; how far it sinks
/// and how still it rests (no closed form).
pub fn scene_box_on_block(quick: bool) {
    let cases: &[ContactCase] = if quick {
        &[([7, 7, 3], None)]
    } else {
        &[
            ([7, 7, 3], None),
            ([7, 7, 3], Some(THIN_SKIN)),
            ([13, 13, 5], None),
        ]
    };
    run_cases("box_on_block", cases, block_grid, box_case);
}

/// One box on the block; returns its wall time.
fn box_case(g: &Grid, radius: Option<f64>, solver: Solver) -> f64 {
    const T_END: f64 = 2.0;
    let start = Instant::now();
    let (bz, hb) = (BLOCK_SIZE[2], BOX_SIZE / 2.0);
    let mut world = setup::world(DT, solver);
    let builder = colliding_body(g, radius, solver);
    let mut settings = contact_settings(&world, solver, g, &builder, radius);
    let skin = builder.particle_radius as f64;
    let pinned = setup::particles_where(&builder, |p| p.z < 1e-4);
    let under_box =
        |p: Vector| (p.z as f64) > bz - 1e-4 && p.x.abs().max(p.y.abs()) as f64 <= hb + 1e-4;
    let top = setup::particles_where(&builder, under_box);
    let top_z0: Vec<f64> = top.iter().map(|&i| builder.positions[i].z as f64).collect();
    let handle = world.insert_soft_body(builder.pinned_particles(pinned.iter().map(|&i| i as u32)));
    let start_z = bz + skin + hb + 0.001;
    let (rb, _) = world.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, 0.0, start_z as Real))
            .can_sleep(false),
        ColliderBuilder::cuboid(hb as Real, hb as Real, hb as Real)
            .mass(BOX_MASS as Real)
            .friction(FRICTION as Real),
    );
    let mut timer = Timer::new(CpuClock::Thread);
    let (mut trace, mut stable) = (BoxTrace::default(), true);
    for _ in 0..(T_END / DT).round() as usize {
        timer.time(|| world.step());
        let sb = &world.soft_bodies[handle];
        let z = world.bodies[rb].translation().z as f64;
        if !setup::body_ok(sb) || !z.is_finite() || z.abs() > 100.0 {
            stable = false;
            break;
        }
        let top_z: Vec<f64> = top
            .iter()
            .map(|&i| sb.particle_position(i).z as f64)
            .collect();
        trace.push(z, world.bodies[rb].linvel().z as f64, &top_z, &top_z0);
    }
    settings.extend(record::object(json!({
        "block": BLOCK_SIZE, "block_support": "bottom face pinned", "box_size": BOX_SIZE,
        "box_mass": BOX_MASS, "duration_s": T_END, "box_start_bottom": start_z - hb,
        "box_start_is": "1 mm above the block's contact skin (top face + particle_radius)",
    })));
    let mut r = record::base(
        "box_on_block",
        &case_name(g, radius, solver),
        settings,
        g.elements(),
    );
    record::extend(&mut r, trace.fields(stable));
    record::extend(&mut r, timer.fields());
    record::emit(r);
    start.elapsed().as_secs_f64()
}

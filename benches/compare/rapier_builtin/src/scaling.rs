//! Scene 6: the cost of a step as the resting 0.2 m cube is refined, from ~1k tets up. Three
//! warm-up steps, then up to 20 timed steps (at most 10 s); the next size is skipped when the
//! last case's wall time scaled by the element ratio exceeds the budget.

use crate::record::{self, Record};
use crate::setup::{self, DEFAULT_DAMPING, Grid, SOFT, SOLVERS, Solver};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use rapier3d::prelude::*;
use serde_json::json;
use std::time::Instant;

/// Cells per axis of the cube sizes (the peers' list).
const SIZES: [usize; 7] = [6, 8, 11, 14, 19, 24, 28];
const DT: f64 = 1.0 / 240.0;
const WARM_UP_STEPS: usize = 3;
const MAX_TIMED_STEPS: usize = 20;
const MAX_TIMED_S: f64 = 10.0;
/// Depth below the ground (m) past which the cube has fallen through it.
const FELL_THROUGH_M: f64 = 0.01;

/// The cube at `cells` per axis; its bottom is placed later, on its contact skin.
fn grid(cells: usize) -> Grid {
    Grid {
        center: [0.0, 0.0, DROP_SIZE / 2.0],
        size: [DROP_SIZE; 3],
        particles: [cells + 1; 3],
    }
}

/// Runs the sizes with both solvers.
pub fn scene_scaling(quick: bool) {
    let sizes = if quick { &SIZES[..1] } else { &SIZES[..] };
    for solver in SOLVERS {
        let mut predicted = 0.0;
        for (i, &n) in sizes.iter().enumerate() {
            if predicted > SCALING_CASE_BUDGET_S {
                let reason = format!(
                    "predicted {predicted:.0} s, over the {SCALING_CASE_BUDGET_S:.0} s budget"
                );
                let g = grid(n);
                let skin = cube_body(&g, solver).particle_radius;
                let settings = settings(&setup::world(DT, solver), solver, &g, skin);
                record::skipped(
                    "scaling",
                    &case_name(&g, solver),
                    settings,
                    g.elements(),
                    &reason,
                );
                break;
            }
            let case_s = scaling_case(&grid(n), solver);
            let next = sizes.get(i + 1).copied().unwrap_or(n);
            predicted = case_s * (next as f64 / n as f64).powi(3);
        }
    }
}

fn case_name(g: &Grid, solver: Solver) -> String {
    format!("{} {}", g.label(), solver.label())
}

/// The colliding cube (friction 0.5, rapier's default skin), not yet lifted onto its skin.
fn cube_body(g: &Grid, solver: Solver) -> SoftBodyBuilder {
    setup::grid_body(g, SOFT, DEFAULT_DAMPING, solver)
        .surface_collider(ColliderBuilder::ball(0.05).friction(FRICTION as Real))
}

fn settings(world: &PhysicsWorld, solver: Solver, g: &Grid, skin: Real) -> Record {
    let mut s = setup::settings(world, solver, g, SOFT, DEFAULT_DAMPING);
    s.extend(record::object(json!({
        "scene": "0.2 m cube E=1e5 resting on a box ground, bottom 1 mm above its contact skin",
        "particle_radius": skin as f64,
        "particle_radius_is": "rapier's default: half the smallest particle spacing",
        "threads": 1,
    })));
    s
}

/// One size: setup, warm-up, timed steps; emits the line and returns the case's wall time.
fn scaling_case(g: &Grid, solver: Solver) -> f64 {
    let w0 = Instant::now();
    let mut world = setup::world(DT, solver);
    setup::add_ground(&mut world);
    let builder = cube_body(g, solver);
    let skin = builder.particle_radius;
    let lift = Vector::new(0.0, 0.0, skin + 0.001);
    let handle = world.insert_soft_body(builder.translated(lift));
    let setup_s = w0.elapsed().as_secs_f64();
    for _ in 0..WARM_UP_STEPS {
        world.step();
    }
    let mut timer = Timer::new(CpuClock::Thread);
    let t0 = Instant::now();
    while timer.steps_timed() < MAX_TIMED_STEPS && t0.elapsed().as_secs_f64() < MAX_TIMED_S {
        timer.time(|| world.step());
    }
    let case_wall_s = w0.elapsed().as_secs_f64();
    let sb = &world.soft_bodies[handle];
    // A cube that sank through the ground steps without contacts: its time is not the scene's.
    let lowest = sb
        .particle_positions()
        .map(|p| p.z as f64)
        .fold(f64::MAX, f64::min);
    let on_ground = lowest > -FELL_THROUGH_M;
    let mut r = record::base(
        "scaling",
        &case_name(g, solver),
        settings(&world, solver, g, skin),
        g.elements(),
    );
    record::extend(
        &mut r,
        json!({
            "reference": null, "error": null, "nodes": sb.num_particles(),
            "setup_s": setup_s, "case_wall_s": case_wall_s, "lowest_particle_z": lowest,
            "stable": setup::body_ok(sb) && on_ground,
            "failure": (!on_ground).then_some("fell through the ground (no contact left)"),
        }),
    );
    record::extend(&mut r, timer.fields());
    record::emit(r);
    case_wall_s
}

//! Scene 6: the cost of a frame as the resting 0.2 m cube is refined, from ~1k tets past 100k.
//! Three series: the implicit integrator with one coupling substep (a fixed ground needs no
//! more) on one thread and on all of them (rayon pools of 1 and of every CPU; the library's
//! `parallel` feature runs its element loops on the current pool), and the world's defaults
//! (automatic integrator, 4 coupling substeps) on one thread. Three warm-up frames, then up to
//! 20 timed frames (at most 10 s), as the peers; the multi-thread series times the same frames
//! as the one-thread series at each size, since the cube lands during the first ones and a
//! frame's cost depends on when it is. Within a series, the next size is skipped when the last
//! case's wall time scaled by the element ratio exceeds the budget.

use crate::contact::{self, Contact, FrameWork};
use crate::knobs::{self, Body};
use crate::record::{self, Record};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use rapier_fvm::element::ElementOrder;
use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, SharedShape};
use serde_json::json;
use std::time::Instant;

/// Cubes per axis of the sizes (the peers' list, then one past 100k tets).
const SIZES: [usize; 7] = [6, 8, 11, 14, 19, 24, 28];
/// Untimed frames before the timed ones.
const WARM_UP_FRAMES: usize = 3;
/// Timed frames at most.
const MAX_TIMED_FRAMES: usize = 20;
/// Timed wall time after which no further frame is timed (s).
const MAX_TIMED_S: f64 = 10.0;

/// A series of sizes: the world's settings, the thread count (`None`: every CPU), and whether
/// it times the frames the previous series timed at each size.
struct Series {
    force: Option<IntegratorKind>,
    coupling_substeps: u32,
    threads: Option<usize>,
    same_frames_as_previous: bool,
}

/// The series, in running order.
const SERIES: [Series; 3] = [
    Series {
        force: Some(IntegratorKind::Implicit),
        coupling_substeps: 1,
        threads: Some(1),
        same_frames_as_previous: false,
    },
    Series {
        force: Some(IntegratorKind::Implicit),
        coupling_substeps: 1,
        threads: None,
        same_frames_as_previous: true,
    },
    Series {
        force: None,
        coupling_substeps: 4,
        threads: Some(1),
        same_frames_as_previous: false,
    },
];

/// How many frames a case times: at most `frames`, and no more once `seconds` have passed.
#[derive(Clone, Copy)]
struct Window {
    frames: usize,
    seconds: f64,
}

/// The peers' window: up to 20 frames within 10 s.
const PEERS_WINDOW: Window = Window {
    frames: MAX_TIMED_FRAMES,
    seconds: MAX_TIMED_S,
};

/// Runs every series over the sizes.
pub fn scene_scaling(quick: bool) {
    let sizes = if quick { &SIZES[..1] } else { &SIZES[..] };
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut previous: Vec<Option<usize>> = Vec::new();
    for series in &SERIES {
        let threads = series.threads.unwrap_or(all);
        if series.threads.is_none() && threads == 1 {
            eprintln!("[scaling] one CPU: no multi-thread series");
            continue;
        }
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(pool) => pool,
            Err(e) => {
                eprintln!("[scaling] no pool of {threads} threads: {e}");
                continue;
            }
        };
        let windows: Vec<Window> = (0..sizes.len())
            .map(|i| match previous.get(i).copied().flatten() {
                Some(frames) if series.same_frames_as_previous => Window {
                    frames,
                    seconds: f64::INFINITY,
                },
                _ => PEERS_WINDOW,
            })
            .collect();
        previous = pool.install(|| run_sizes(series, sizes, &windows, threads));
    }
}

/// The sizes in order on the current pool of `threads` threads, each timed within its window;
/// returns the frames each size timed (`None`: skipped).
fn run_sizes(
    series: &Series,
    sizes: &[usize],
    windows: &[Window],
    threads: usize,
) -> Vec<Option<usize>> {
    let mut predicted = 0.0;
    let mut timed = Vec::new();
    for (i, (&n, &window)) in sizes.iter().zip(windows).enumerate() {
        let case = cube_case(series, n);
        if predicted > SCALING_CASE_BUDGET_S {
            let reason =
                format!("predicted {predicted:.0} s, over the {SCALING_CASE_BUDGET_S:.0} s budget");
            record::skipped(head(&case, n, threads, &case.world()), &reason);
            timed.push(None);
            continue;
        }
        let (case_s, frames) = scaling_case(&case, n, threads, window);
        timed.push(Some(frames));
        let next = sizes.get(i + 1).copied().unwrap_or(n);
        predicted = case_s * (next as f64 / n as f64).powi(3);
    }
    timed
}

/// The cube of `n` cubes per axis, stable Neo-Hookean, in the series' world settings.
fn cube_case(series: &Series, n: usize) -> Contact {
    Contact {
        body: Body::new(
            ElementOrder::Linear,
            [n; 3],
            MaterialModel::StableNeoHookean,
        ),
        force: series.force,
        coupling_substeps: series.coupling_substeps,
    }
}

/// Which CPU clock measures a frame on `threads` threads.
fn clock(threads: usize) -> CpuClock {
    if threads == 1 {
        CpuClock::Thread
    } else {
        CpuClock::Process
    }
}

/// The line's head; the series also names the thread count.
fn head(case: &Contact, n: usize, threads: usize, world: &FvmWorld) -> Record {
    let mut r = case.record("scaling", &format!("{n}^3 threads={threads}"), world);
    r.insert(
        "series".into(),
        json!(format!("{} threads={threads}", case.series())),
    );
    if let Some(settings) = r.get_mut("settings").and_then(|s| s.as_object_mut()) {
        settings.extend(record::object(json!({
            "scene": "0.2 m cube E=1e5 resting on a half-space ground, bottom 1 mm above it",
            "threads": threads,
            "time_clock": clock(threads).name(),
        })));
    }
    r
}

/// One size: setup, warm-up, timed frames within `window`; emits the line and returns the
/// case's wall time and the frames it timed.
fn scaling_case(case: &Contact, n: usize, threads: usize, window: Window) -> (f64, usize) {
    let w0 = Instant::now();
    let mut world = case.world();
    let mut r = head(case, n, threads, &world);
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(FRICTION as f32),
        None,
    );
    let half = DVec3::splat(DROP_SIZE / 2.0);
    let at = DVec3::new(0.0, DROP_SIZE / 2.0 + 0.001, 0.0);
    let built = Material::new(case.body.model, SOFT_E, SOFT_NU, SOFT_RHO)
        .and_then(|m| case.body.build(half, at, m, Some(SOFT_BETA), |_| false))
        .and_then(|b| b.friction(FRICTION).build());
    let body = match built {
        Ok(body) => body,
        Err(e) => {
            record::skipped(r, &format!("could not build the cube: {e}"));
            return (w0.elapsed().as_secs_f64(), 0);
        }
    };
    let nodes = body.node_count();
    let handle = world.soft_bodies.insert(body);
    let setup_s = w0.elapsed().as_secs_f64();
    let (mut warm_up, mut work) = (Timer::new(clock(threads)), FrameWork::default());
    let mut failure = (0..WARM_UP_FRAMES)
        .find_map(|_| contact::step(&mut world, &mut warm_up, &mut FrameWork::default()).err());
    let mut timer = Timer::new(clock(threads));
    while failure.is_none()
        && timer.steps_timed() < window.frames
        && timer.wall_total_s() < window.seconds
    {
        failure = contact::step(&mut world, &mut timer, &mut work).err();
    }
    let case_wall_s = w0.elapsed().as_secs_f64();
    let body = &world.soft_bodies[handle];
    let lowest = body
        .positions()
        .iter()
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min);
    let stable = failure.is_none() && knobs::body_ok(body) && lowest > -0.01;
    record::extend(
        &mut r,
        json!({
            "reference": null, "error": null, "nodes": nodes,
            "setup_s": setup_s, "case_wall_s": case_wall_s, "lowest_node_y": lowest,
            "stable": stable, "failure": failure, "solver_work": work.to_json(),
            "timed_window": if window.seconds.is_finite() {
                "up to 20 frames within 10 s (the peers' window)"
            } else {
                "the frames the one-thread series timed at this size"
            },
        }),
    );
    let frames = timer.steps_timed();
    record::extend(&mut r, timer.fields());
    record::emit(r);
    (case_wall_s, frames)
}

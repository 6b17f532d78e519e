//! Scenes 4-5 in an [`FvmWorld`]: a soft cube dropped on a half-space ground (`drop`) and a
//! rigid box resting on a soft block whose bottom face is pinned (`box_on_block`). The knobs:
//! element order and resolution, material model, the integrator choice (automatic or forced)
//! and the coupling substeps per frame.

use crate::beam::GRAVITY;
use crate::budget::{CASE_LIMIT_S, Deadline};
use crate::knobs::{self, Body};
use crate::record::{self, Record};
use compare_common::contact::{BoxTrace, DT, DropTrace};
use compare_common::reference::*;
use compare_common::timing::{CpuClock, Timer};
use rapier_fvm::element::ElementOrder::{Linear as Lin, Quadratic as Quad};
use rapier_fvm::glamx::Vec3;
use rapier_fvm::integrate::AutomaticReport;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};
use serde_json::json;

/// The stable Neo-Hookean model (the crate's default).
const SNH: MaterialModel = MaterialModel::StableNeoHookean;
/// The corotated model.
const COROTATED: MaterialModel = MaterialModel::Corotated;

/// A contact case: the body, the forced integrator (`None`: the automatic choice) and the
/// coupling substeps per frame.
#[derive(Clone, Copy)]
pub struct Contact {
    /// The soft body's knobs.
    pub body: Body,
    /// The integrator forced on every frame, or `None` for [`AutomaticIntegrator`]'s choice.
    pub force: Option<IntegratorKind>,
    /// [`SoftCoupling::substeps`].
    pub coupling_substeps: u32,
}

impl Contact {
    /// The automatic integrator with the world's default 4 coupling substeps.
    pub const fn new(body: Body) -> Self {
        Contact {
            body,
            force: None,
            coupling_substeps: 4,
        }
    }

    /// The same case with `n` coupling substeps.
    const fn substeps(self, n: u32) -> Self {
        Contact {
            coupling_substeps: n,
            ..self
        }
    }

    /// The same case with the integrator forced.
    const fn forced(self, kind: IntegratorKind) -> Self {
        Contact {
            force: Some(kind),
            ..self
        }
    }

    /// `automatic` / `implicit` / `explicit`.
    fn integrator_label(&self) -> &'static str {
        match self.force {
            None => "automatic",
            Some(IntegratorKind::Implicit) => "implicit",
            Some(IntegratorKind::Explicit) => "explicit",
        }
    }

    /// The knobs other than the resolution.
    pub fn series(&self) -> String {
        format!(
            "{} {} cs={}",
            self.body.series(),
            self.integrator_label(),
            self.coupling_substeps
        )
    }

    /// A world at frame step `DT` with this case's integrator and coupling. Bodies never sleep:
    /// every engine compared steps every frame, so the time per step is the solver's.
    pub fn world(&self) -> FvmWorld {
        let mut world = FvmWorld::default();
        world.coupling.sleep = SleepSettings::never();
        world.physics.integration_parameters.dt = DT as f32;
        world.physics.gravity = GRAVITY.as_vec3();
        world.coupling.substeps = self.coupling_substeps;
        world.coupling.integrator.force = self.force;
        world
    }

    /// The line's head: `label` names the resolution in the peers' axis order.
    pub fn record(&self, scene: &str, label: &str, world: &FvmWorld) -> Record {
        let case = format!(
            "{} {label} {} {} cs={}",
            self.body.order_name(),
            self.body.constitutive(),
            self.integrator_label(),
            self.coupling_substeps
        );
        let mut settings = record::object(self.body.settings());
        settings.extend(record::object(json!({
            "integrator": format!("AutomaticIntegrator, force {:?}", self.force),
            "coupling_substeps": self.coupling_substeps,
            "dt": DT,
            "E": SOFT_E, "nu": SOFT_NU, "damping_beta": SOFT_BETA, "friction": FRICTION,
            "contact_margin": world.coupling.contact.margin,
            "contact_margin_is": "detection reach only: contacts act at the surface, no rest gap",
            "gravity": "-y",
            "time_clock": CpuClock::Thread.name(),
        })));
        record::base(scene, &case, &self.series(), settings, self.body.elements())
    }
}

/// What the soft steps of a run did: the automatic integrator's choices and the work of each
/// step. [`FvmWorld::step`] reports each frame's last soft step (of its coupling substeps), so
/// these are counted over one soft step per frame.
#[derive(Default)]
pub struct FrameWork {
    explicit: usize,
    implicit: usize,
    fell_back: usize,
    substeps: usize,
    newton: usize,
    cg: usize,
}

impl FrameWork {
    /// Adds one soft step's report.
    fn add(&mut self, report: &AutomaticReport) {
        match report.choice {
            IntegratorKind::Explicit => self.explicit += 1,
            IntegratorKind::Implicit => self.implicit += 1,
        }
        self.fell_back += usize::from(report.fell_back);
        if let Some(explicit) = report.explicit {
            self.substeps += explicit.substeps as usize;
        }
        if let Some(implicit) = report.implicit {
            self.newton += implicit.newton_iterations;
            self.cg += implicit.linear_iterations;
        }
    }

    /// The counts and the mean work per step, for the line.
    pub fn to_json(&self) -> serde_json::Value {
        let per = |n: usize, of: usize| (of > 0).then(|| n as f64 / of as f64);
        json!({
            "counted": "the last soft step of each frame",
            "explicit_frames": self.explicit,
            "implicit_frames": self.implicit,
            "fell_back": self.fell_back,
            "explicit_substeps_per_step": per(self.substeps, self.explicit),
            "newton_iterations_per_step": per(self.newton, self.implicit),
            "cg_iterations_per_step": per(self.cg, self.implicit),
        })
    }
}

/// Steps `world` one frame, timed; the first soft body's failure, if any.
pub fn step(world: &mut FvmWorld, timer: &mut Timer, work: &mut FrameWork) -> Result<(), String> {
    let outcomes = timer.time(|| world.step());
    for (_, outcome) in outcomes {
        work.add(&outcome.map_err(|e| e.to_string())?);
    }
    Ok(())
}

/// The cases of scene 4: the peers' resolutions, a quadratic cube, the integrator forced each
/// way, one coupling substep, and the corotated model.
const DROP: &[Contact] = &[
    Contact::new(Body::new(Lin, [4, 4, 4], SNH)),
    Contact::new(Body::new(Lin, [8, 8, 8], SNH)),
    Contact::new(Body::new(Lin, [4, 4, 4], SNH)).substeps(1),
    Contact::new(Body::new(Lin, [4, 4, 4], SNH)).forced(IntegratorKind::Implicit),
    Contact::new(Body::new(Lin, [4, 4, 4], SNH)).forced(IntegratorKind::Explicit),
    Contact::new(Body::new(Lin, [4, 4, 4], COROTATED)),
    Contact::new(Body::new(Quad, [2, 2, 2], SNH)),
];

/// Scene 4: the cube falls, bounces and rests; its resting centroid height (mean node height)
/// against the uniaxial-stress closed form.
pub fn scene_drop(quick: bool) {
    let cases = if quick { &DROP[..1] } else { DROP };
    for case in cases {
        drop_case(case);
    }
}

/// One drop.
fn drop_case(case: &Contact) {
    /// Simulated time (s).
    const T_END: f64 = 2.5;
    let mut world = case.world();
    let [n, _, _] = case.body.cells;
    let r = case.record("drop", &format!("{n}^3"), &world);
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(FRICTION as f32),
        None,
    );
    let half = DVec3::splat(DROP_SIZE / 2.0);
    let start = DVec3::new(0.0, DROP_HEIGHT + DROP_SIZE / 2.0, 0.0);
    let built = Material::new(case.body.model, SOFT_E, SOFT_NU, SOFT_RHO)
        .and_then(|m| case.body.build(half, start, m, Some(SOFT_BETA), |_| false))
        .and_then(|b| b.friction(FRICTION).build());
    let body = match built {
        Ok(body) => body,
        Err(e) => return record::skipped(r, &format!("could not build the cube: {e}")),
    };
    let handle = world.soft_bodies.insert(body);
    let deadline = Deadline::start(CASE_LIMIT_S);
    let frames = (T_END / DT).round() as usize;
    let (mut timer, mut work) = (Timer::new(CpuClock::Thread), FrameWork::default());
    let (mut trace, mut failure) = (DropTrace::default(), None);
    for k in 0..frames {
        if let Err(e) = step(&mut world, &mut timer, &mut work) {
            failure = Some(e);
            break;
        }
        let body = &world.soft_bodies[handle];
        if !knobs::body_ok(body) {
            failure = Some("a node went non-finite or beyond 100 m".into());
            break;
        }
        let ys: Vec<f64> = body.positions().iter().map(|x| x.y).collect();
        trace.push(&ys);
        if let Err(reason) = deadline.check(k + 1, frames) {
            return record::skipped(r, &reason);
        }
    }
    let measures = trace.fields(failure.is_none());
    emit_run(r, measures, failure, &work, &timer);
}

/// The cases of scene 5: two resolutions of linear tetrahedra with the default and 16
/// coupling substeps (the README's advice for a light box on a stiff surface), and a coarse
/// quadratic block (finer ones take many explicit substeps under the scene's damping).
const BOX_ON_BLOCK: &[Contact] = &[
    Contact::new(Body::new(Lin, [6, 2, 6], SNH)),
    Contact::new(Body::new(Lin, [6, 2, 6], SNH)).substeps(16),
    Contact::new(Body::new(Lin, [12, 4, 12], SNH)),
    Contact::new(Body::new(Lin, [12, 4, 12], SNH)).substeps(16),
    Contact::new(Body::new(Quad, [3, 1, 3], SNH)),
];

/// Scene 5: a rigid 1 kg box released 1 mm above the block; how far it sinks and how still it
/// rests (no closed form).
pub fn scene_box_on_block(quick: bool) {
    let cases = if quick {
        &BOX_ON_BLOCK[..1]
    } else {
        BOX_ON_BLOCK
    };
    for case in cases {
        box_case(case);
    }
}

/// One box on the block.
fn box_case(case: &Contact) {
    /// Simulated time (s).
    const T_END: f64 = 2.0;
    let (height, hb) = (BLOCK_SIZE[2], BOX_SIZE / 2.0);
    let mut world = case.world();
    let [x, y, z] = case.body.cells;
    let mut r = case.record("box_on_block", &format!("{x}x{z}x{y}"), &world);
    let half = DVec3::new(BLOCK_SIZE[0], BLOCK_SIZE[2], BLOCK_SIZE[1]) / 2.0;
    let built = Material::new(case.body.model, SOFT_E, SOFT_NU, SOFT_RHO)
        .and_then(|m| {
            let at = DVec3::new(0.0, half.y, 0.0);
            case.body
                .build(half, at, m, Some(SOFT_BETA), |p| p.y <= 1e-9)
        })
        .and_then(|b| b.friction(FRICTION).build());
    let block = match built {
        Ok(body) => body,
        Err(e) => return record::skipped(r, &format!("could not build the block: {e}")),
    };
    let under_box = |p: DVec3| p.y >= height - 1e-9 && p.x.abs().max(p.z.abs()) <= hb + 1e-9;
    let top = knobs::nodes_where(&block, under_box);
    let top_y0: Vec<f64> = top.iter().map(|&n| block.positions()[n].y).collect();
    let handle = world.soft_bodies.insert(block);
    let start_y = height + hb + 0.001;
    let (rb, _) = world.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vec3::new(0.0, start_y as f32, 0.0))
            .can_sleep(false),
        ColliderBuilder::cuboid(hb as f32, hb as f32, hb as f32)
            .mass(BOX_MASS as f32)
            .friction(FRICTION as f32),
    );
    let deadline = Deadline::start(CASE_LIMIT_S);
    let frames = (T_END / DT).round() as usize;
    let (mut timer, mut work) = (Timer::new(CpuClock::Thread), FrameWork::default());
    let (mut trace, mut failure) = (BoxTrace::default(), None);
    for k in 0..frames {
        if let Err(e) = step(&mut world, &mut timer, &mut work) {
            failure = Some(e);
            break;
        }
        let block = &world.soft_bodies[handle];
        let rigid = &world.physics.bodies[rb];
        let y = f64::from(rigid.translation().y);
        if !knobs::body_ok(block) || !y.is_finite() || y.abs() > 100.0 {
            failure = Some("a node or the box went non-finite or beyond 100 m".into());
            break;
        }
        let top_y: Vec<f64> = top.iter().map(|&n| block.positions()[n].y).collect();
        trace.push(y, f64::from(rigid.linvel().y), &top_y, &top_y0);
        if let Err(reason) = deadline.check(k + 1, frames) {
            return record::skipped(r, &reason);
        }
    }
    if let Some(settings) = r.get_mut("settings").and_then(|s| s.as_object_mut()) {
        settings.extend(record::object(json!({
            "block": BLOCK_SIZE, "block_support": "bottom face pinned", "box_size": BOX_SIZE,
            "box_mass": BOX_MASS, "duration_s": T_END, "box_start_bottom": start_y - hb,
            "resolution_peer_order": [x, z, y],
        })));
    }
    let measures = trace.fields(failure.is_none());
    emit_run(r, measures, failure, &work, &timer);
}

/// Completes a contact case's line with `measures`, the run's failure, work and times, and
/// emits it.
fn emit_run(
    mut r: Record,
    measures: serde_json::Value,
    failure: Option<String>,
    work: &FrameWork,
    timer: &Timer,
) {
    record::extend(&mut r, measures);
    record::extend(
        &mut r,
        json!({ "failure": failure, "solver_work": work.to_json() }),
    );
    record::extend(&mut r, timer.fields());
    record::emit(r);
}

//! `[[probe]]` of a 2D scene: a quantity sampled after every frame, written to the report as a
//! time series with its final value, and plotted.
//!
//! ```toml
//! [[probe]]
//! name = "tip deflection"
//! kind = "displacement"   # of the node nearest `point` (m, mesh coordinates) of soft `body`
//! body = "beam"
//! point = [1.0, 0.05]
//! component = "y"         # "x", "y" or "norm" (default)
//!
//! [[probe]]
//! name = "ground reaction"
//! kind = "contact_force"  # mean force (N) the soft bodies' contacts and attachments exerted
//! rigid = "ground"        # on rigid body `rigid` over the frame
//! component = "y"
//! ```
//! Other kinds: `position` and `velocity` of rigid body `rigid` (m, m/s); `energy` of soft `body`
//! or of all (J; `energy = "elastic"`, `"kinetic"`, `"gravity"` (`−Σ m g·x`) or `"total"`);
//! `momentum` of soft `body` or of all (kg m/s); `angular_momentum` of soft `body` about its
//! centre of mass, or of all about theirs (N m s, counter-clockwise; a scalar in the plane).

use super::build::PlanarSimulation;
use crate::output::TimeSeries;
use crate::scene::check::Checker;
use crate::scene::probe::{Component, EnergyKind};
use rapier_fvm::glamx::DVec2;
use rapier_fvm::planar::PlanarBody;
use serde::Deserialize;

/// A probe as written.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanarProbeSpec {
    /// Its name (report key and plot title), unique among probes.
    pub name: String,
    /// What it measures.
    pub kind: PlanarProbeKind,
    /// The soft body (displacement: required; energy, momenta: optional, default all).
    pub body: Option<String>,
    /// The rigid body (position, velocity, contact force: required).
    pub rigid: Option<String>,
    /// The rest point whose nearest node is followed (m, mesh coordinates; displacement).
    pub point: Option<[f64; 2]>,
    /// Which component of a vector; default the norm.
    #[serde(default)]
    pub component: Component,
    /// Which energy (energy probes).
    pub energy: Option<EnergyKind>,
}

/// What a 2D probe measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanarProbeKind {
    /// A soft node's displacement from where it started (m).
    Displacement,
    /// A rigid body's translation (m).
    Position,
    /// A rigid body's linear velocity (m/s).
    Velocity,
    /// The force soft bodies exert on a rigid body through contact and attachments (N).
    ContactForce,
    /// An energy of soft bodies (J).
    Energy,
    /// The linear momentum of soft bodies (kg m/s).
    Momentum,
    /// The angular momentum of soft bodies about their centre of mass (N m s).
    AngularMomentum,
}

impl PlanarProbeKind {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Displacement => "displacement",
            Self::Position => "position",
            Self::Velocity => "velocity",
            Self::ContactForce => "contact_force",
            Self::Energy => "energy",
            Self::Momentum => "momentum",
            Self::AngularMomentum => "angular_momentum",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Self::Displacement | Self::Position => "m",
            Self::Velocity => "m/s",
            Self::ContactForce => "N",
            Self::Energy => "J",
            Self::Momentum => "kg m/s",
            Self::AngularMomentum => "N m s",
        }
    }
}

impl PlanarProbeSpec {
    /// Checks that the fields the kind needs are given and no other, and that the bodies
    /// exist; `key` is the probe's key path.
    pub(crate) fn check(&self, key: &str, soft: &[&str], rigid: &[&str], c: &mut Checker<'_>) {
        use PlanarProbeKind::{
            AngularMomentum, ContactForce, Displacement, Energy, Momentum, Position, Velocity,
        };
        // (body, rigid, point, energy): Some(true) required, Some(false) forbidden, None optional.
        let needs = match self.kind {
            Displacement => [Some(true), Some(false), Some(true), Some(false)],
            Position | Velocity | ContactForce => {
                [Some(false), Some(true), Some(false), Some(false)]
            }
            Energy => [None, Some(false), Some(false), Some(true)],
            Momentum | AngularMomentum => [None, Some(false), Some(false), Some(false)],
        };
        let given = [
            self.body.is_some(),
            self.rigid.is_some(),
            self.point.is_some(),
            self.energy.is_some(),
        ];
        let kind = self.kind.name();
        for ((name, given), need) in ["body", "rigid", "point", "energy"]
            .iter()
            .zip(given)
            .zip(needs)
        {
            match (given, need) {
                (false, Some(true)) => c.fail(key, format!("a `{kind}` probe needs `{name}`")),
                (true, Some(false)) => c.fail(
                    &format!("{key}.{name}"),
                    format!("a `{kind}` probe takes no `{name}`"),
                ),
                _ => {}
            }
        }
        let scalar = matches!(self.kind, Energy | AngularMomentum);
        match self.component {
            Component::Norm => {}
            _ if scalar => c.fail(&format!("{key}.component"), "a scalar has no component"),
            Component::Z => c.fail(&format!("{key}.component"), "a 2D vector has x and y only"),
            Component::X | Component::Y => {}
        }
        if let Some(body) = self.body.as_deref().filter(|b| !soft.contains(b)) {
            c.fail(
                &format!("{key}.body"),
                format!("no soft body is named {body:?}"),
            );
        }
        if let Some(name) = self.rigid.as_deref().filter(|r| !rigid.contains(r)) {
            c.fail(
                &format!("{key}.rigid"),
                format!("no rigid body is named {name:?}"),
            );
        }
        if let Some([x, y]) = self.point {
            c.finite_vector(&format!("{key}.point"), [x, y, 0.0]);
        }
    }
}

/// A probe bound to a simulation's bodies, and the samples taken so far.
#[derive(Debug, Clone)]
pub struct PlanarProbe {
    spec: PlanarProbeSpec,
    /// The soft body's index, the rigid body's index and the followed node, as the kind needs.
    soft: Option<usize>,
    rigid: Option<usize>,
    node: usize,
    /// The samples: name, unit and `(time (s), value)` pairs.
    pub series: TimeSeries,
}

impl PlanarProbe {
    /// `spec` bound to `sim`'s bodies (the scene's check has made sure they exist).
    pub(crate) fn new(spec: &PlanarProbeSpec, sim: &PlanarSimulation) -> Self {
        let soft = spec
            .body
            .as_ref()
            .and_then(|b| sim.soft.iter().position(|e| e.name == *b));
        let rigid = spec
            .rigid
            .as_ref()
            .and_then(|r| sim.rigid.iter().position(|e| e.name == *r));
        let node = match (soft, spec.point) {
            (Some(i), Some([x, y])) => nearest(sim.bodies[i].rest_positions(), DVec2::new(x, y)),
            _ => 0,
        };
        Self {
            soft,
            rigid,
            node,
            series: TimeSeries {
                name: spec.name.clone(),
                unit: spec.kind.unit().to_owned(),
                samples: Vec::new(),
            },
            spec: spec.clone(),
        }
    }

    /// The kind's scene-file name.
    pub fn kind(&self) -> &'static str {
        self.spec.kind.name()
    }

    /// Samples the probe at time `t` (s).
    pub(crate) fn sample(&mut self, t: f64, sim: &PlanarSimulation) {
        let bodies: Vec<&PlanarBody> = match self.soft {
            Some(i) => vec![&sim.bodies[i]],
            None => sim.bodies.iter().collect(),
        };
        let rigid = self
            .rigid
            .and_then(|i| sim.physics.bodies.get(sim.rigid[i].handle));
        let vector = |v: DVec2| match self.spec.component {
            Component::X => v.x,
            Component::Y => v.y,
            Component::Z | Component::Norm => v.length(),
        };
        let value = match self.spec.kind {
            PlanarProbeKind::Displacement => self.soft.map_or(f64::NAN, |i| {
                vector(sim.bodies[i].positions()[self.node] - sim.soft[i].start[self.node])
            }),
            PlanarProbeKind::Position => {
                rigid.map_or(f64::NAN, |r| vector(r.translation().as_dvec2()))
            }
            PlanarProbeKind::Velocity => rigid.map_or(f64::NAN, |r| vector(r.linvel().as_dvec2())),
            PlanarProbeKind::ContactForce => self.rigid.map_or(f64::NAN, |i| {
                let entry = &sim.rigid[i];
                vector(
                    sim.coupling.force_on(entry.collider) + sim.coupling.glue_force(entry.handle),
                )
            }),
            PlanarProbeKind::Energy => (bodies.iter())
                .map(|b| energy(b, self.spec.energy, sim.gravity))
                .sum(),
            PlanarProbeKind::Momentum => vector(bodies.iter().map(|b| b.linear_momentum()).sum()),
            PlanarProbeKind::AngularMomentum => bodies.iter().map(|b| spin(b)).sum(),
        };
        self.series.samples.push((t, value));
    }
}

/// The index of the point of `points` nearest `p`.
fn nearest(points: &[DVec2], p: DVec2) -> usize {
    (points.iter().enumerate())
        .min_by(|(_, a), (_, b)| a.distance_squared(p).total_cmp(&b.distance_squared(p)))
        .map_or(0, |(i, _)| i)
}

/// `body`'s energy of kind `kind` (J) under `gravity` (m/s²).
fn energy(body: &PlanarBody, kind: Option<EnergyKind>, gravity: DVec2) -> f64 {
    let elastic = || body.elastic_energy();
    let kinetic = || body.kinetic_energy();
    let potential = || {
        (body.masses().iter().zip(body.positions()))
            .map(|(m, x)| -m * gravity.dot(*x))
            .sum::<f64>()
    };
    match kind {
        Some(EnergyKind::Elastic) => elastic(),
        Some(EnergyKind::Kinetic) => kinetic(),
        Some(EnergyKind::Gravity) => potential(),
        Some(EnergyKind::Total) | None => elastic() + kinetic() + potential(),
    }
}

/// `body`'s angular momentum about its centre of mass (N m s): about the origin, less the
/// centre's `c × p`.
fn spin(body: &PlanarBody) -> f64 {
    let mass = body.total_mass();
    let centre: DVec2 = (body.masses().iter().zip(body.positions()))
        .map(|(m, x)| *x * *m)
        .sum::<DVec2>()
        / mass;
    body.angular_momentum() - centre.perp_dot(body.linear_momentum())
}

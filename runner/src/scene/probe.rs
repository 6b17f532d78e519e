//! `[[probe]]`: a quantity sampled every frame, written to the report as a time series with its
//! final value, and plotted.
//!
//! ```toml
//! [[probe]]
//! name = "tip deflection"
//! kind = "displacement"     # of the node nearest `point` (m, rest coordinates) of soft `body`
//! body = "beam"
//! point = [0.5, 0.0, 0.0]
//! component = "y"           # "x", "y", "z" or "norm" (default)
//!
//! [[probe]]
//! name = "box height"
//! kind = "position"         # or "velocity": of rigid body `rigid` (m, m/s)
//! rigid = "box"
//! component = "y"
//!
//! [[probe]]
//! name = "ground reaction"
//! kind = "contact_force"    # force (N) on rigid body `rigid` from soft `body`, or from all
//! rigid = "ground"
//! component = "y"
//!
//! [[probe]]
//! name = "block pushed by the box"
//! kind = "contact_force_on_soft" # force (N) on soft `body` from rigid body `rigid`, or from all
//! body = "block"
//! rigid = "box"
//! component = "x"
//!
//! [[probe]]
//! name = "elastic energy"
//! kind = "energy"           # of soft `body`, or of all soft bodies (J)
//! energy = "elastic"        # "elastic", "kinetic", "gravity" or "total"
//!
//! [[probe]]
//! name = "block momentum"
//! kind = "momentum"         # linear momentum Σ m v of soft `body`, or of all (kg m/s)
//! body = "block"
//! component = "x"
//!
//! [[probe]]
//! name = "block spin"
//! kind = "angular_momentum" # Σ m (x - c) × v of soft `body` about its centre of mass c, or of
//! body = "block"            # all about theirs (N m s)
//! component = "z"
//!
//! [[probe]]
//! name = "chamber pressure"
//! kind = "cavity_pressure"  # or "cavity_volume": the pressure (Pa) or enclosed volume (m³) of
//! body = "finger"           # soft `body`'s load number `load` (from 0, in the order of its
//! load = 0                  # `loads`), a pressure or a chamber
//! ```
//! The contact force is the frame's mean force the soft bodies' contacts and attachments
//! exerted on the rigid body (`FvmWorld::load_on`); the force on a soft body is its opposite.
//! The gravity energy is `-m g·x` summed over the nodes, zero at the origin.

use super::check::Checker;
use serde::Deserialize;

/// A probe.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Its name (report key and plot title), unique among probes.
    pub name: String,
    /// What it measures.
    pub kind: ProbeKind,
    /// The soft body (displacement, contact force on soft: required; contact force, energy,
    /// momentum, angular momentum: optional, default all).
    pub body: Option<String>,
    /// The rigid body (position, velocity, contact force: required; contact force on soft:
    /// optional, default all).
    pub rigid: Option<String>,
    /// The rest point whose nearest node is followed (m, mesh rest coordinates; displacement).
    pub point: Option<[f64; 3]>,
    /// Which component of a vector; default the norm.
    #[serde(default)]
    pub component: Component,
    /// Which energy (energy probes).
    pub energy: Option<EnergyKind>,
    /// The soft body's load, by its index in the body's `loads` (cavity probes).
    pub load: Option<usize>,
}

/// What a probe measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeKind {
    /// A soft node's displacement from its rest position (m).
    Displacement,
    /// A rigid body's translation (m).
    Position,
    /// A rigid body's linear velocity (m/s).
    Velocity,
    /// The force soft bodies exert on a rigid body (N).
    ContactForce,
    /// The force rigid bodies exert on a soft body (N).
    ContactForceOnSoft,
    /// An energy of soft bodies (J).
    Energy,
    /// The linear momentum of soft bodies (kg m/s).
    Momentum,
    /// The angular momentum of soft bodies about their centre of mass (N m s).
    AngularMomentum,
    /// The pressure a soft body's pressure or chamber load pushes with (Pa).
    CavityPressure,
    /// The volume a soft body's pressure or chamber load encloses (m³).
    CavityVolume,
}

/// A component of a vector quantity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
    /// The Euclidean norm.
    #[default]
    Norm,
}

/// Which energy an energy probe sums.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyKind {
    /// Elastic (strain) energy.
    Elastic,
    /// Kinetic energy.
    Kinetic,
    /// Gravity potential energy.
    Gravity,
    /// The sum of the three.
    Total,
}

impl ProbeKind {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Displacement => "displacement",
            Self::Position => "position",
            Self::Velocity => "velocity",
            Self::ContactForce => "contact_force",
            Self::ContactForceOnSoft => "contact_force_on_soft",
            Self::Energy => "energy",
            Self::Momentum => "momentum",
            Self::AngularMomentum => "angular_momentum",
            Self::CavityPressure => "cavity_pressure",
            Self::CavityVolume => "cavity_volume",
        }
    }

    /// The unit of the measured values.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Displacement | Self::Position => "m",
            Self::Velocity => "m/s",
            Self::ContactForce | Self::ContactForceOnSoft => "N",
            Self::Energy => "J",
            Self::Momentum => "kg m/s",
            Self::AngularMomentum => "N m s",
            Self::CavityPressure => "Pa",
            Self::CavityVolume => "m³",
        }
    }
}

impl ProbeSpec {
    /// Checks that the fields the kind needs are given and no other, and that the bodies
    /// exist; `key` is the probe's key path.
    pub(crate) fn check(&self, key: &str, soft: &[&str], rigid: &[&str], c: &mut Checker<'_>) {
        use Need::{Forbidden, Optional, Required};
        use ProbeKind::{
            AngularMomentum, CavityPressure, CavityVolume, ContactForce, ContactForceOnSoft,
            Displacement, Energy, Momentum, Position, Velocity,
        };
        let (body, rigid_body, point, energy) = match self.kind {
            Displacement => (Required, Forbidden, Required, Forbidden),
            Position | Velocity => (Forbidden, Required, Forbidden, Forbidden),
            ContactForce => (Optional, Required, Forbidden, Forbidden),
            ContactForceOnSoft => (Required, Optional, Forbidden, Forbidden),
            Energy => (Optional, Forbidden, Forbidden, Required),
            Momentum | AngularMomentum => (Optional, Forbidden, Forbidden, Forbidden),
            CavityPressure | CavityVolume => (Required, Forbidden, Forbidden, Forbidden),
        };
        let load = match self.kind {
            CavityPressure | CavityVolume => Required,
            _ => Forbidden,
        };
        let kind = self.kind.name();
        let presence = [
            ("body", self.body.is_some(), body),
            ("rigid", self.rigid.is_some(), rigid_body),
            ("point", self.point.is_some(), point),
            ("energy", self.energy.is_some(), energy),
            ("load", self.load.is_some(), load),
        ];
        for (name, given, need) in presence {
            match (given, need) {
                (false, Need::Required) => {
                    c.fail(key, format!("a `{kind}` probe needs `{name}`"));
                }
                (true, Need::Forbidden) => {
                    c.fail(
                        &format!("{key}.{name}"),
                        format!("a `{kind}` probe takes no `{name}`"),
                    );
                }
                _ => {}
            }
        }
        if matches!(self.kind, Energy | CavityPressure | CavityVolume)
            && self.component != Component::Norm
        {
            c.fail(&format!("{key}.component"), "a scalar has no component");
        }
        if let Some(body) = &self.body
            && !soft.contains(&body.as_str())
        {
            c.fail(
                &format!("{key}.body"),
                format!("no soft body is named {body:?}"),
            );
        }
        if let Some(name) = &self.rigid
            && !rigid.contains(&name.as_str())
        {
            c.fail(
                &format!("{key}.rigid"),
                format!("no rigid body is named {name:?}"),
            );
        }
        if let Some(point) = self.point {
            c.finite_vector(&format!("{key}.point"), point);
        }
    }
}

/// Whether a probe kind needs a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Need {
    Required,
    Optional,
    Forbidden,
}

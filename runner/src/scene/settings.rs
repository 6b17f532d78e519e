//! `[contact]`, `[integrator]` and `[output]`: how contacts are enforced, which integrator
//! steps the soft bodies, and what the runner writes. Every key is optional.
//!
//! ```toml
//! [contact]
//! margin = 1e-3              # m
//! penalty_factor = 1e3       # implicit penalty stiffness in units of m/h², at least
//! resting_depth = 1e-3       # m: a contact pressed deeper by its load stiffens
//! depenetration_speed = 0.1  # m/s
//! velocity_iterations = 4
//! stiction_speed = 1e-4      # m/s
//!
//! [integrator]
//! kind = "automatic"         # "automatic" (cheaper per frame), "explicit" or "implicit"
//! safety_factor = 0.5        # explicit: fraction of the critical step
//! max_substeps = 100000      # explicit: most substeps per frame
//! implicit_substeps = 1      # implicit: Newton solves per frame
//! scheme = "backward_euler"  # implicit: or "bdf2"
//! tolerance = 1e-6           # implicit: Newton's relative tolerance
//! max_newton_iterations = 100 # implicit: per substep; a failed solve redoes the frame in more substeps
//! reuse_factorization = true # implicit: reuse earlier factorizations while they converge fast
//!
//! [integrator.cost]          # the automatic choice's cost model: `rapier-fvm calibrate` prints
//! explicit_tet = 32e-9       # the measured table for this machine (seconds per unit of work;
//! newton_tet = 1e-6          # keys left out keep the library's CostModel::default)
//!
//! [output]
//! save_every = 3             # frames between saved ParaView/OBJ frames (frame 0 always saved)
//! pictures = [0.0, 1.0, 2.0] # times (s) of the rendered views; default: start, 1/3, 2/3, end
//! picture_size = [1000, 700] # pixels
//! ground_patch = 0.5         # half size of the drawn square of a half-space (m)
//! ```

use super::check::Checker;
use rapier_fvm::contact::ContactSettings;
use rapier_fvm::integrate::{
    AutomaticIntegrator, CostModel, ImplicitIntegrator, ImplicitScheme, IntegratorKind,
    SymplecticEuler,
};
use serde::Deserialize;

/// Contact settings; unset keys keep [`ContactSettings::default`].
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Detection margin (m).
    pub margin: Option<f64>,
    /// Implicit penalty stiffness in units of a node's `m/h²`, at least.
    pub penalty_factor: Option<f64>,
    /// The depth (m) past which a contact's implicit penalty stiffens under its load.
    pub resting_depth: Option<f64>,
    /// Speed at which nodes found inside a collider are pushed out (m/s).
    pub depenetration_speed: Option<f64>,
    /// Sweeps per explicit substep over contacts with dynamic bodies.
    pub velocity_iterations: Option<u32>,
    /// Implicit stiction speed (m/s).
    pub stiction_speed: Option<f64>,
}

impl ContactSpec {
    /// The library's settings.
    pub fn settings(&self) -> ContactSettings {
        let d = ContactSettings::default();
        ContactSettings {
            margin: self.margin.unwrap_or(d.margin),
            penalty_factor: self.penalty_factor.unwrap_or(d.penalty_factor),
            resting_depth: self.resting_depth.unwrap_or(d.resting_depth),
            depenetration_speed: self.depenetration_speed.unwrap_or(d.depenetration_speed),
            velocity_iterations: self.velocity_iterations.unwrap_or(d.velocity_iterations),
            stiction_speed: self.stiction_speed.unwrap_or(d.stiction_speed),
        }
    }

    pub(crate) fn check(&self, c: &mut Checker<'_>) {
        for (name, value, unit) in [
            ("margin", self.margin, "m"),
            ("depenetration_speed", self.depenetration_speed, "m/s"),
            ("stiction_speed", self.stiction_speed, "m/s"),
        ] {
            if let Some(value) = value {
                c.non_negative(&format!("contact.{name}"), value, unit);
            }
        }
        if let Some(value) = self.penalty_factor {
            c.positive("contact.penalty_factor", value, "dimensionless");
        }
        if let Some(value) = self.resting_depth {
            c.positive("contact.resting_depth", value, "m");
        }
        if self.velocity_iterations == Some(0) {
            c.fail("contact.velocity_iterations", "must be at least 1");
        }
    }
}

/// Which integrator steps the soft bodies.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorChoice {
    /// The cheaper of explicit and implicit, per body per frame.
    #[default]
    Automatic,
    /// Always symplectic Euler with automatic substeps.
    Explicit,
    /// Always the implicit integrator.
    Implicit,
}

/// The implicit time discretisation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SchemeSpec {
    /// Backward Euler.
    #[default]
    BackwardEuler,
    /// Second-order backward differentiation.
    Bdf2,
}

/// Integrator settings; unset keys keep the library's defaults.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// Which integrator; default automatic.
    #[serde(default)]
    pub kind: IntegratorChoice,
    /// Explicit: fraction of the critical step, in (0, 1].
    pub safety_factor: Option<f64>,
    /// Explicit: most substeps per frame.
    pub max_substeps: Option<u32>,
    /// Implicit: equal substeps (Newton solves) per frame.
    pub implicit_substeps: Option<u32>,
    /// Implicit: the scheme.
    pub scheme: Option<SchemeSpec>,
    /// Implicit: Newton's relative tolerance.
    pub tolerance: Option<f64>,
    /// Implicit: Newton iterations per substep at most.
    pub max_newton_iterations: Option<usize>,
    /// Implicit: whether Newton may reuse earlier factorizations (the chord method).
    pub reuse_factorization: Option<bool>,
    /// The automatic choice's cost model.
    #[serde(default)]
    pub cost: CostSpec,
}

/// The automatic choice's cost model (see [`CostModel`]); unset keys keep its default.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostSpec {
    /// Seconds per tetrahedron per explicit substep.
    pub explicit_tet: Option<f64>,
    /// The same, corotated model.
    pub explicit_tet_corotated: Option<f64>,
    /// A damped tetrahedron's explicit cost over an undamped one's (at least 1).
    pub explicit_damped_factor: Option<f64>,
    /// Seconds per contact point per velocity sweep per explicit substep.
    pub explicit_contact_point: Option<f64>,
    /// Seconds per tetrahedron per Newton iteration beyond its factorization, at a thousand
    /// tetrahedra.
    pub newton_tet: Option<f64>,
    /// The exponent of the per-tetrahedron Newton and factorization costs' growth with size,
    /// in [0, 1].
    pub newton_size_exponent: Option<f64>,
    /// The same, corotated model.
    pub newton_tet_corotated: Option<f64>,
    /// Seconds per tetrahedron per factorization with its tangent's assembly, at a thousand
    /// tetrahedra.
    pub factorization_tet: Option<f64>,
    /// Seconds per energy evaluation.
    pub energy_evaluation: Option<f64>,
    /// Seconds per energy evaluation per dynamic rigid body touched.
    pub partner_evaluation: Option<f64>,
    /// Seconds per conjugate gradient iteration whatever the size.
    pub conjugate_gradient_iteration: Option<f64>,
    /// Seconds per tetrahedron per conjugate gradient iteration.
    pub conjugate_gradient_tet: Option<f64>,
    /// Newton iterations per implicit substep before a body has its own.
    pub newton_iterations: Option<f64>,
}

impl CostSpec {
    /// The library's cost model.
    pub fn model(&self) -> CostModel {
        let d = CostModel::default();
        CostModel {
            explicit_tet: self.explicit_tet.unwrap_or(d.explicit_tet),
            explicit_tet_corotated: self
                .explicit_tet_corotated
                .unwrap_or(d.explicit_tet_corotated),
            explicit_damped_factor: self
                .explicit_damped_factor
                .unwrap_or(d.explicit_damped_factor),
            explicit_contact_point: self
                .explicit_contact_point
                .unwrap_or(d.explicit_contact_point),
            newton_tet: self.newton_tet.unwrap_or(d.newton_tet),
            newton_size_exponent: self.newton_size_exponent.unwrap_or(d.newton_size_exponent),
            newton_tet_corotated: self.newton_tet_corotated.unwrap_or(d.newton_tet_corotated),
            factorization_tet: self.factorization_tet.unwrap_or(d.factorization_tet),
            energy_evaluation: self.energy_evaluation.unwrap_or(d.energy_evaluation),
            partner_evaluation: self.partner_evaluation.unwrap_or(d.partner_evaluation),
            conjugate_gradient_iteration: self
                .conjugate_gradient_iteration
                .unwrap_or(d.conjugate_gradient_iteration),
            conjugate_gradient_tet: self
                .conjugate_gradient_tet
                .unwrap_or(d.conjugate_gradient_tet),
            newton_iterations: self.newton_iterations.unwrap_or(d.newton_iterations),
        }
    }

    /// Checks every key given: finite, positive (the contact cost and the implicit work's
    /// parts may be zero), the damping factor at least 1, the size exponent in [0, 1].
    fn check(&self, c: &mut Checker<'_>) {
        for (key, value) in [
            ("explicit_contact_point", self.explicit_contact_point),
            ("newton_tet", self.newton_tet),
            ("newton_tet_corotated", self.newton_tet_corotated),
            ("factorization_tet", self.factorization_tet),
            ("energy_evaluation", self.energy_evaluation),
            ("partner_evaluation", self.partner_evaluation),
            (
                "conjugate_gradient_iteration",
                self.conjugate_gradient_iteration,
            ),
            ("conjugate_gradient_tet", self.conjugate_gradient_tet),
        ] {
            if let Some(value) = value {
                c.non_negative(&format!("integrator.cost.{key}"), value, "s");
            }
        }
        for (key, value) in [
            ("explicit_tet", self.explicit_tet),
            ("explicit_tet_corotated", self.explicit_tet_corotated),
            ("newton_iterations", self.newton_iterations),
        ] {
            if let Some(value) = value {
                c.positive(&format!("integrator.cost.{key}"), value, "s or iterations");
            }
        }
        if let Some(a) = self.newton_size_exponent
            && !(0.0..=1.0).contains(&a)
        {
            c.fail(
                "integrator.cost.newton_size_exponent",
                format!("must lie in [0, 1], got {a}"),
            );
        }
        if let Some(f) = self.explicit_damped_factor
            && !(f.is_finite() && f >= 1.0)
        {
            c.fail(
                "integrator.cost.explicit_damped_factor",
                format!("must be a finite number of at least 1, got {f}"),
            );
        }
    }
}

impl IntegratorSpec {
    /// The library's integrator.
    pub fn integrator(&self) -> AutomaticIntegrator {
        let explicit = SymplecticEuler::default();
        let implicit = ImplicitIntegrator::default();
        AutomaticIntegrator {
            explicit: SymplecticEuler {
                safety_factor: self.safety_factor.unwrap_or(explicit.safety_factor),
                max_substeps: self.max_substeps.unwrap_or(explicit.max_substeps),
                ..explicit
            },
            implicit: ImplicitIntegrator {
                scheme: match self.scheme.unwrap_or_default() {
                    SchemeSpec::BackwardEuler => ImplicitScheme::BackwardEuler,
                    SchemeSpec::Bdf2 => ImplicitScheme::Bdf2,
                },
                tolerance: self.tolerance.unwrap_or(implicit.tolerance),
                max_newton_iterations: self
                    .max_newton_iterations
                    .unwrap_or(implicit.max_newton_iterations),
                substeps: self.implicit_substeps.unwrap_or(implicit.substeps),
                reuse_factorization: self
                    .reuse_factorization
                    .unwrap_or(implicit.reuse_factorization),
                ..implicit
            },
            force: match self.kind {
                IntegratorChoice::Automatic => None,
                IntegratorChoice::Explicit => Some(IntegratorKind::Explicit),
                IntegratorChoice::Implicit => Some(IntegratorKind::Implicit),
            },
            cost: self.cost.model(),
        }
    }

    pub(crate) fn check(&self, c: &mut Checker<'_>) {
        self.cost.check(c);
        if let Some(f) = self.safety_factor
            && !(f > 0.0 && f <= 1.0)
        {
            c.fail(
                "integrator.safety_factor",
                format!("must lie in (0, 1], got {f}"),
            );
        }
        if let Some(t) = self.tolerance {
            c.positive("integrator.tolerance", t, "dimensionless");
        }
        for (name, value) in [
            ("max_substeps", self.max_substeps.map(|v| v as usize)),
            (
                "implicit_substeps",
                self.implicit_substeps.map(|v| v as usize),
            ),
            ("max_newton_iterations", self.max_newton_iterations),
        ] {
            if value == Some(0) {
                c.fail(&format!("integrator.{name}"), "must be at least 1");
            }
        }
    }
}

/// What the runner writes.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Frames between saved ParaView and OBJ frames; default 3.
    #[serde(default = "default_save_every")]
    pub save_every: usize,
    /// Times (s) of the rendered views; default: start, a third, two thirds and end.
    pub pictures: Option<Vec<f64>>,
    /// Size of the rendered views (pixels); default 1000 x 700.
    #[serde(default = "default_picture_size")]
    pub picture_size: [u32; 2],
    /// Half size of the drawn square standing for a half-space (m); default 0.5.
    #[serde(default = "default_ground_patch")]
    pub ground_patch: f64,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            save_every: default_save_every(),
            pictures: None,
            picture_size: default_picture_size(),
            ground_patch: default_ground_patch(),
        }
    }
}

fn default_save_every() -> usize {
    3
}

fn default_picture_size() -> [u32; 2] {
    [1000, 700]
}

fn default_ground_patch() -> f64 {
    0.5
}

impl OutputSpec {
    pub(crate) fn check(&self, duration: f64, c: &mut Checker<'_>) {
        if self.save_every == 0 {
            c.fail("output.save_every", "must be at least 1");
        }
        for (i, &t) in self.pictures.iter().flatten().enumerate() {
            if !(t.is_finite() && (0.0..=duration + 1e-9).contains(&t)) {
                c.fail(
                    &format!("output.pictures[{i}]"),
                    format!("must lie between 0 and the duration {duration} s, got {t}"),
                );
            }
        }
        let [w, h] = self.picture_size;
        if !(64..=8192).contains(&w) || !(64..=8192).contains(&h) {
            c.fail(
                "output.picture_size",
                "each side must lie in 64 to 8192 pixels",
            );
        }
        c.positive("output.ground_patch", self.ground_patch, "m");
    }
}

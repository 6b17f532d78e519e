//! What the report shows of each scene: its description, the panels of its plot (which cases,
//! which quantity against which), and the extra columns of its table.

use crate::data::Case;

/// Which cases a panel shows.
#[derive(Clone, Copy)]
pub enum Filter {
    /// Every case of the scene.
    All,
    /// Cases at this step (s).
    Dt(f64),
    /// Cases at this Poisson's ratio.
    Nu(f64),
}

impl Filter {
    /// Whether `case` belongs to the panel.
    pub fn accepts(self, case: &Case) -> bool {
        let near =
            |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() <= 1e-4 * b.abs().max(1e-3));
        match self {
            Filter::All => true,
            Filter::Dt(dt) => near(case.setting("dt"), dt),
            Filter::Nu(nu) => near(case.setting("nu"), nu),
        }
    }
}

/// A plotted quantity.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// CPU ms per step (median), or the wall ms for a case on more than one thread.
    Ms,
    /// Elements (tetrahedra).
    Elements,
    /// `|error|`.
    AbsError,
    /// `|value|` of a top-level field.
    Abs(&'static str),
}

impl Metric {
    /// The quantity for `case`, if it has one.
    pub fn of(self, case: &Case) -> Option<f64> {
        match self {
            Metric::Ms if case.threads() > 1.0 => case.num("wall_ms_per_step"),
            Metric::Ms => case.ms(),
            Metric::Elements => case.num("elements"),
            Metric::AbsError => case.num("error").map(f64::abs),
            Metric::Abs(key) => case.num(key).map(f64::abs),
        }
    }

    /// The axis label.
    pub fn label(self) -> &'static str {
        match self {
            Metric::Ms => "ms per step (CPU median; on >1 thread: wall)",
            Metric::Elements => "elements (tets)",
            Metric::AbsError => "|relative error|",
            Metric::Abs("vertical_velocity_std") => "box vertical velocity std (m/s)",
            Metric::Abs("penetration") => "|box penetration into the block| (m)",
            Metric::Abs(_) => "value",
        }
    }
}

/// One panel of a scene's plot: lower-left is better unless `x` is [`Metric::Elements`].
pub struct Panel {
    /// Its title.
    pub title: String,
    /// Which cases.
    pub filter: Filter,
    /// Horizontal and vertical quantities (both log scale).
    pub x: Metric,
    /// Vertical quantity.
    pub y: Metric,
}

impl Panel {
    /// Whether the panel is a trade-off (cost against a quantity to keep low), so that a
    /// Pareto front means something.
    pub fn is_trade_off(&self) -> bool {
        self.x == Metric::Ms
    }
}

/// A column of a scene's table beyond the common ones.
pub struct Column {
    /// Its header.
    pub header: &'static str,
    /// Its cell for a case.
    pub cell: fn(&Case) -> String,
}

/// A scene as the report shows it.
pub struct Scene {
    /// The name in the JSON lines.
    pub name: &'static str,
    /// The section title.
    pub title: &'static str,
    /// What is simulated and measured, and against what.
    pub about: &'static str,
    /// The panels of its plot.
    pub panels: Vec<Panel>,
    /// The extra columns of its table.
    pub columns: Vec<Column>,
}

/// `value * scale` with `digits` decimals, or `-`.
fn fixed(value: Option<f64>, scale: f64, digits: usize) -> String {
    value.map_or("-".into(), |v| format!("{:.digits$}", v * scale))
}

/// `1/240` for a step of 1/240 s.
fn per_second(dt: f64) -> String {
    format!("1/{}", (1.0 / dt).round())
}

/// The columns of the static beam scenes: the tip deflection and whether it settled.
fn static_columns() -> Vec<Column> {
    vec![
        Column {
            header: "tip (mm)",
            cell: |c| fixed(c.num("tip_deflection"), 1e3, 3),
        },
        Column {
            header: "settled",
            cell: |c| match c.raw.get("settled").and_then(|v| v.as_bool()) {
                Some(true) => "yes".into(),
                Some(false) => "no".into(),
                None => "-".into(),
            },
        },
    ]
}

/// The six scenes, in the order of the report.
pub fn scenes() -> Vec<Scene> {
    vec![
        cantilever(),
        poisson(),
        vibration(),
        drop(),
        box_on_block(),
        scaling(),
    ]
}

/// A panel of error magnitude against CPU time per step.
fn error_panel(title: String, filter: Filter) -> Panel {
    Panel {
        title,
        filter,
        x: Metric::Ms,
        y: Metric::AbsError,
    }
}

/// A table column of a field times `scale`, with `digits` decimals.
macro_rules! column {
    ($header:literal, $field:literal, $scale:expr, $digits:expr) => {
        Column {
            header: $header,
            cell: |c| fixed(c.num($field), $scale, $digits),
        }
    };
}

/// Scene 1: one panel per step.
fn cantilever() -> Scene {
    Scene {
        name: "cantilever",
        title: "1. Cantilever: static tip deflection",
        about: "L = 1 m, 0.1 x 0.1 m, E = 1e8 Pa, nu = 0.3, rho = 1000 kg/m^3, clamped face \
                pinned, settled under gravity for 1.5 s with the first mode critically damped \
                (stiffness-proportional beta = 2/omega_1); tip averaged over the last 0.25 s. \
                Error against Timoshenko's 14.865 mm.",
        panels: [1.0 / 240.0, 1.0 / 60.0]
            .map(|dt| error_panel(format!("dt = {}", per_second(dt)), Filter::Dt(dt)))
            .into(),
        columns: static_columns(),
    }
}

/// Scene 2: one panel per Poisson's ratio.
fn poisson() -> Scene {
    Scene {
        name: "poisson",
        title: "2. Poisson sweep: static tip deflection over nu",
        about: "The cantilever of scene 1 at nu = 0, 0.3, 0.45, 0.49, 0.499 (dt = 1/240); error \
                against Timoshenko's deflection at that nu. Volumetric locking shows as an error \
                growing toward -100 %.",
        panels: [0.0, 0.3, 0.45, 0.49, 0.499]
            .map(|nu| error_panel(format!("nu = {nu}"), Filter::Nu(nu)))
            .into(),
        columns: static_columns(),
    }
}

/// Scene 3: one panel per step.
fn vibration() -> Scene {
    Scene {
        name: "vibration",
        title: "3. Free vibration: first bending frequency",
        about: "The cantilever released straight under gravity, undamped where the engine allows \
                it, 2 s; a damped-sine fit gives the natural frequency (error against \
                Timoshenko's 5.069 Hz) and the damping ratio, here all numerical (pybullet needs \
                damping beta >= dt/2 to be stable).",
        panels: [1.0 / 1000.0, 1.0 / 240.0, 1.0 / 60.0]
            .map(|dt| error_panel(format!("dt = {}", per_second(dt)), Filter::Dt(dt)))
            .into(),
        columns: vec![
            column!("f1 (Hz)", "first_frequency_hz", 1.0, 3),
            column!("numerical damping ratio", "numerical_damping_ratio", 1.0, 4),
        ],
    }
}

/// Scene 4: the resting height's error.
fn drop() -> Scene {
    Scene {
        name: "drop",
        title: "4. Drop: a soft cube falls 0.5 m onto the ground",
        about: "0.2 m cube, E = 1e5 Pa, nu = 0.3, rho = 1000 kg/m^3, damping beta = 0.01 s, \
                friction 0.5, dt = 1/240, 2.5 s. Error of the resting centroid height (mean node \
                height over the last 0.5 s) against the uniaxial closed form 98.69 mm; a \
                collision margin or skin lifts the body by its thickness.",
        panels: vec![error_panel("resting centroid height".into(), Filter::All)],
        columns: vec![
            column!("rest height (mm)", "resting_centroid_height", 1e3, 2),
            column!("peak penetration (mm)", "peak_penetration", 1e3, 2),
            column!("resting penetration (mm)", "resting_penetration", 1e3, 2),
        ],
    }
}

/// Scene 5: jitter and penetration against cost.
fn box_on_block() -> Scene {
    let panel = |title: &str, field| Panel {
        title: title.into(),
        filter: Filter::All,
        x: Metric::Ms,
        y: Metric::Abs(field),
    };
    Scene {
        name: "box_on_block",
        title: "5. Rigid box on a soft block",
        about: "A rigid 1 kg, 0.1 m box released 1 mm above a 0.3 x 0.3 x 0.1 m block \
                (E = 1e5 Pa, nu = 0.3, bottom face pinned), dt = 1/240, 2 s. No closed form: the \
                plots show how still the box rests (its vertical velocity's standard deviation \
                over the last 0.5 s) and how far the block's top nodes under it pass its bottom \
                face (negative: a gap, the box hovering on a margin).",
        panels: vec![
            panel("jitter", "vertical_velocity_std"),
            panel("penetration", "penetration"),
        ],
        columns: vec![
            column!("sink (mm)", "sink", 1e3, 3),
            column!("penetration (mm)", "penetration", 1e3, 3),
            column!("dent (mm)", "surface_sink", 1e3, 3),
            column!("v std (mm/s)", "vertical_velocity_std", 1e3, 4),
        ],
    }
}

/// Scene 6: cost against size.
fn scaling() -> Scene {
    Scene {
        name: "scaling",
        title: "6. Scaling: cost of a step as the resting cube is refined",
        about: "The 0.2 m cube of scene 4 resting on the ground, from ~1k tets up; 3 warm-up \
                steps (the cube starts 1 mm above the ground, so the timed steps include its \
                landing), then up to 20 timed steps within 10 s. Cases on more than one thread \
                are plotted at their wall time (their CPU time sums the threads).",
        panels: vec![Panel {
            title: "ms per step".into(),
            filter: Filter::All,
            x: Metric::Elements,
            y: Metric::Ms,
        }],
        columns: vec![
            column!("nodes", "nodes", 1.0, 0),
            Column {
                header: "threads",
                cell: |c| format!("{}", c.threads()),
            },
        ],
    }
}

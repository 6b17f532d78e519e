//! This crate's knobs, swept as separate cases so that each is a point on the Pareto plots:
//! element order and resolution, material model, volumetric treatment, and the integrator with
//! its tolerance. Also how a box-shaped body is built from them.

use rapier_fvm::element::ElementOrder;
use rapier_fvm::prelude::*;
use serde_json::{Value, json};

/// Default Newton tolerance of [`ImplicitIntegrator`] (kept, unless a case says otherwise).
pub const DEFAULT_TOLERANCE: f64 = 1e-6;

/// How a body is stepped.
#[derive(Clone, Copy)]
pub enum Stepper {
    /// [`ImplicitIntegrator`] with this scheme and Newton tolerance.
    Implicit(ImplicitScheme, f64),
    /// [`SymplecticEuler`] with its automatic substeps below the stability limit.
    Explicit,
}

impl Stepper {
    /// Implicit backward Euler at the default tolerance.
    pub const BE: Stepper = Stepper::Implicit(ImplicitScheme::BackwardEuler, DEFAULT_TOLERANCE);
    /// Implicit BDF2 at the default tolerance.
    pub const BDF2: Stepper = Stepper::Implicit(ImplicitScheme::Bdf2, DEFAULT_TOLERANCE);

    /// Short label: `BE`, `BDF2` (with `tol=` when not the default) or `explicit`.
    pub fn label(self) -> String {
        match self {
            Stepper::Implicit(scheme, tolerance) => {
                let name = match scheme {
                    ImplicitScheme::BackwardEuler => "BE",
                    ImplicitScheme::Bdf2 => "BDF2",
                };
                if tolerance == DEFAULT_TOLERANCE {
                    name.to_string()
                } else {
                    format!("{name} tol={tolerance:e}")
                }
            }
            Stepper::Explicit => "explicit".to_string(),
        }
    }

    /// Advances `body` by `dt` (s) under `gravity` (m/s²), with `workspace` its solver caches;
    /// returns the Newton iterations (implicit) or substeps (explicit) the step took and whether
    /// it converged.
    pub fn step(
        self,
        body: &mut DeformableBody,
        workspace: &mut SolverWorkspace,
        dt: f64,
        gravity: DVec3,
    ) -> Result<Work, Error> {
        let free = &mut BodyConstraints::new();
        match self {
            Stepper::Implicit(scheme, tolerance) => {
                let integrator = ImplicitIntegrator {
                    scheme,
                    tolerance,
                    ..ImplicitIntegrator::default()
                };
                let report = integrator.step(body, free, workspace, dt, gravity)?;
                Ok(Work {
                    iterations: report.newton_iterations,
                    converged: report.converged,
                })
            }
            Stepper::Explicit => {
                let report = SymplecticEuler::default().step(body, free, workspace, dt, gravity)?;
                Ok(Work {
                    iterations: report.substeps as usize,
                    converged: true,
                })
            }
        }
    }

    /// The integrator's fields in `settings`.
    pub fn settings(self) -> Value {
        match self {
            Stepper::Implicit(scheme, tolerance) => json!({
                "integrator": format!("ImplicitIntegrator {scheme:?}"),
                "newton_tolerance": tolerance,
                "max_newton_iterations": ImplicitIntegrator::default().max_newton_iterations,
                "linear_solver": "Automatic (sparse Cholesky or block-Jacobi CG, by predicted cost)",
            }),
            Stepper::Explicit => json!({
                "integrator": "SymplecticEuler (automatic substeps, safety factor 0.5)",
            }),
        }
    }
}

/// What one step cost: Newton iterations (implicit) or substeps (explicit), and whether Newton
/// met its tolerance.
#[derive(Clone, Copy)]
pub struct Work {
    /// Newton iterations or explicit substeps.
    pub iterations: usize,
    /// Whether the step met its tolerance (explicit steps always do).
    pub converged: bool,
}

/// The discretization and constitutive knobs of a body.
#[derive(Clone, Copy)]
pub struct Body {
    /// Linear (4-node) or quadratic (10-node) tetrahedra.
    pub order: ElementOrder,
    /// Cubes per axis, five tetrahedra each.
    pub cells: [usize; 3],
    /// The material model.
    pub model: MaterialModel,
    /// How the volumetric term is evaluated.
    pub volumetric: VolumetricTreatment,
}

impl Body {
    /// Per-element volumetric term, the given order, resolution and model.
    pub const fn new(order: ElementOrder, cells: [usize; 3], model: MaterialModel) -> Self {
        Body {
            order,
            cells,
            model,
            volumetric: VolumetricTreatment::PerElement,
        }
    }

    /// The same body with another volumetric treatment.
    pub const fn with_volumetric(self, volumetric: VolumetricTreatment) -> Self {
        Body { volumetric, ..self }
    }

    /// `linear` / `quadratic`.
    pub fn order_name(&self) -> &'static str {
        match self.order {
            ElementOrder::Linear => "linear",
            ElementOrder::Quadratic => "quadratic",
        }
    }

    /// `10x1x1`.
    pub fn resolution(&self) -> String {
        let [x, y, z] = self.cells;
        format!("{x}x{y}x{z}")
    }

    /// The material model, and the volumetric treatment when not per element.
    pub fn constitutive(&self) -> String {
        match self.volumetric {
            VolumetricTreatment::PerElement => format!("{:?}", self.model),
            v => format!("{:?} {v:?}", self.model),
        }
    }

    /// The knobs other than the resolution: order, model and volumetric treatment.
    pub fn series(&self) -> String {
        format!("{} {}", self.order_name(), self.constitutive())
    }

    /// Elements simulated: tetrahedra of either order, five per cube.
    pub fn elements(&self) -> usize {
        5 * self.cells.iter().product::<usize>()
    }

    /// The body's fields in `settings`.
    pub fn settings(&self) -> Value {
        json!({
            "element_order": self.order_name(),
            "resolution": self.cells,
            "resolution_is": "cubes per axis, 5 tets each (mesh::cuboid; quadratic: + mid-edge nodes)",
            "model": format!("{:?}", self.model),
            "volumetric": format!("{:?}", self.volumetric),
            "mass_lumping": "control volumes (linear), HRZ (quadratic)",
        })
    }

    /// A box of `half` extents (m) made of these elements, translated by `translation` (m), with
    /// the nodes where `pinned(rest position in the world)` holds pinned.
    ///
    /// # Errors
    /// The library's, for an invalid mesh, material or damping.
    pub fn build(
        &self,
        half: DVec3,
        translation: DVec3,
        material: Material,
        beta: Option<f64>,
        pinned: impl Fn(DVec3) -> bool,
    ) -> Result<DeformableBodyBuilder, Error> {
        let linear = mesh::cuboid(half, self.cells)?;
        let pin = |p: DVec3| pinned(p + translation);
        let builder = match self.order {
            ElementOrder::Linear => {
                let pins = linear.nodes_where(pin);
                DeformableBodyBuilder::new(linear, material).pinned_nodes(pins)
            }
            ElementOrder::Quadratic => {
                let quadratic = mesh::QuadraticTetMesh::from_linear(&linear)?;
                let pins = quadratic.nodes_where(pin);
                DeformableBodyBuilder::quadratic(quadratic, material).pinned_nodes(pins)
            }
        };
        let builder = match beta {
            Some(beta) => builder.damping(RayleighDamping::stiffness_proportional(
                beta,
                material.lame(),
            )?),
            None => builder,
        };
        Ok(builder.volumetric(self.volumetric).translation(translation))
    }
}

/// The nodes of `body` whose current position satisfies `select`.
pub fn nodes_where(body: &DeformableBody, select: impl Fn(DVec3) -> bool) -> Vec<usize> {
    (0..body.node_count())
        .filter(|&n| select(body.positions()[n]))
        .collect()
}

/// Free degrees of freedom of `body`.
pub fn dofs(body: &DeformableBody) -> usize {
    3 * (0..body.node_count())
        .filter(|&n| !body.is_pinned(n))
        .count()
}

/// Whether every node is finite and within 100 m of the origin.
pub fn body_ok(body: &DeformableBody) -> bool {
    body.positions()
        .iter()
        .all(|x| x.is_finite() && x.length() < 100.0)
}

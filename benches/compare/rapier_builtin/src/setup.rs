//! Rapier worlds and built-in soft bodies as the scenes need them: z up, the scene's dt, a grid
//! of corotational tets (`SoftBodyBuilder::cuboid`, five per cube) with explicit lumped masses,
//! and one of rapier's two soft-body solvers.

use crate::record::{self, Record};
use compare_common::reference::{FRICTION, G, SOFT_E, SOFT_NU, SOFT_RHO};
use rapier3d::prelude::*;
use serde_json::json;

/// The conjugate-gradient cap of the `fem` solver's runs (rapier's default is 20).
pub const FEM_CG_CAP: usize = 256;
/// The raised caps a static `fem` case is re-run with to check that [`FEM_CG_CAP`] converged.
pub const FEM_CG_CAP_CHECKS: [usize; 2] = [1024, 4096];

/// One of rapier's soft-body solvers.
#[derive(Clone, Copy, Debug)]
pub enum Solver {
    /// `SoftBodySolver::Constraints` (default): elements as compliant constraint rows, swept
    /// Gauss-Seidel with the contacts once per substep.
    Constraints,
    /// `SoftBodySolver::Fem` (`fem` feature): implicit Euler per substep, `(M + hD + h^2 K) dv = b`
    /// by conjugate gradient stopped at `cg_cap` iterations.
    Fem {
        /// `integration_parameters.soft_bodies.fem.max_linear_iterations`.
        cg_cap: usize,
    },
}

/// The two variants every case runs.
pub const SOLVERS: [Solver; 2] = [Solver::Constraints, Solver::Fem { cg_cap: FEM_CG_CAP }];

impl Solver {
    /// Short label for the case name: `constraints` or `fem cg<=256`.
    pub fn label(self) -> String {
        match self {
            Solver::Constraints => "constraints".into(),
            Solver::Fem { cg_cap } => format!("fem cg<={cg_cap}"),
        }
    }

    /// How a step's cost grows with the particle count, for predicting the next resolution's
    /// time: linear for the sweeps, and about n^(4/3) for CG (iterations grow like 1/h).
    pub fn cost_exponent(self) -> f64 {
        match self {
            Solver::Constraints => 1.0,
            Solver::Fem { .. } => 4.0 / 3.0,
        }
    }

    fn rapier(self) -> SoftBodySolver {
        match self {
            Solver::Constraints => SoftBodySolver::Constraints,
            Solver::Fem { .. } => SoftBodySolver::Fem,
        }
    }
}

/// An isotropic material as the scenes give it.
#[derive(Clone, Copy)]
pub struct Material {
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio (rapier clamps it to [0, 0.499]).
    pub poisson: f64,
    /// Density (kg/m^3); rapier takes masses, not densities: see [`lumped_masses`].
    pub density: f64,
}

/// The contact scenes' soft material (E = 1e5 Pa, nu = 0.3, rho = 1000 kg/m^3).
pub const SOFT: Material = Material {
    young: SOFT_E,
    poisson: SOFT_NU,
    density: SOFT_RHO,
};

/// Rapier's damping knobs: it has no Rayleigh beta input.
#[derive(Clone, Copy)]
pub struct Damping {
    /// `SoftBodyMaterial::elastic_damping_ratio`: a damping ratio rapier turns into a per-cell
    /// stiffness-proportional `beta = 2 zeta / omega_cell` (`omega_cell`: the cell's own frequency).
    pub elastic_ratio: f64,
    /// `SoftBodyMaterial::deformation_damping` (1/s): rate at which velocities are pulled to the
    /// body's best-fit rigid motion (mass-proportional damping of every deformation mode).
    pub deformation_rate: f64,
}

/// Rapier's defaults: each cell critically damped, no deformation damping.
pub const DEFAULT_DAMPING: Damping = Damping {
    elastic_ratio: 1.0,
    deformation_rate: 0.0,
};

/// A box of `particles[k]` particles along axis k (`SoftBodyBuilder::cuboid`).
#[derive(Clone, Copy)]
pub struct Grid {
    /// Centre of the box (m).
    pub center: [f64; 3],
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Particles per axis (cells per axis + 1).
    pub particles: [usize; 3],
}

impl Grid {
    /// Number of tets: five per cube.
    pub fn elements(&self) -> usize {
        5 * self.particles.iter().map(|n| n - 1).product::<usize>()
    }

    /// Number of particles.
    pub fn num_particles(&self) -> usize {
        self.particles.iter().product()
    }

    /// `NxMxK particles` for case names.
    pub fn label(&self) -> String {
        let [x, y, z] = self.particles;
        format!("{x}x{y}x{z} particles")
    }
}

/// An empty world with gravity along -z, step `dt` and the solver's CG cap; every other
/// integration parameter at rapier's default (4 substeps).
pub fn world(dt: f64, solver: Solver) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -G as Real);
    world.integration_parameters.dt = dt as Real;
    if let Solver::Fem { cg_cap } = solver {
        world
            .integration_parameters
            .soft_bodies
            .fem
            .max_linear_iterations = cg_cap;
    }
    world
}

/// A fixed 10 x 10 x 1 m box whose top face is the plane z = 0.
pub fn add_ground(world: &mut PhysicsWorld) {
    world.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, 0.0, -0.5)),
        ColliderBuilder::cuboid(5.0, 5.0, 0.5).friction(FRICTION as Real),
    );
}

/// The grid as a corotational soft body with lumped masses, never sleeping, without a collider
/// (add one with `surface_collider`).
pub fn grid_body(
    grid: &Grid,
    material: Material,
    damping: Damping,
    solver: Solver,
) -> SoftBodyBuilder {
    let [px, py, pz] = grid.particles;
    let half = Vector::new(
        grid.size[0] as Real,
        grid.size[1] as Real,
        grid.size[2] as Real,
    ) * 0.5;
    let center = Vector::new(
        grid.center[0] as Real,
        grid.center[1] as Real,
        grid.center[2] as Real,
    );
    let builder = SoftBodyBuilder::cuboid(center, half, px, py, pz)
        .cell_model(SoftBodyCellModel::Corotational)
        .material(SoftBodyMaterial {
            young_modulus: material.young as Real,
            poisson_ratio: material.poisson as Real,
            elastic_damping_ratio: damping.elastic_ratio as Real,
            deformation_damping: damping.deformation_rate as Real,
            ..Default::default()
        })
        .solver(solver.rapier())
        .no_surface_collider()
        .can_sleep(false);
    let masses = lumped_masses(&builder.positions, &builder.cells, material.density);
    builder.masses(masses)
}

/// Row-sum lumped masses of linear tets: each tet gives a quarter of `rho * V_tet` to each vertex.
fn lumped_masses(positions: &[Vector], cells: &[[u32; 4]], density: f64) -> Vec<Real> {
    let mut masses = vec![0.0_f64; positions.len()];
    let p = |i: u32| {
        let v = positions[i as usize];
        [v.x as f64, v.y as f64, v.z as f64]
    };
    for c in cells {
        let [a, b, cc, d] = c.map(p);
        let e = |q: [f64; 3]| [q[0] - a[0], q[1] - a[1], q[2] - a[2]];
        let (u, v, w) = (e(b), e(cc), e(d));
        let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]);
        for &i in c {
            masses[i as usize] += density * det.abs() / 6.0 / 4.0;
        }
    }
    masses.into_iter().map(|m| m as Real).collect()
}

/// Indices of the builder's particles whose position satisfies `keep`.
pub fn particles_where(builder: &SoftBodyBuilder, keep: impl Fn(Vector) -> bool) -> Vec<usize> {
    (0..builder.positions.len())
        .filter(|&i| keep(builder.positions[i]))
        .collect()
}

/// Still simulated (not quarantined by rapier's NaN guard), finite and within 100 m.
pub fn body_ok(sb: &SoftBody) -> bool {
    sb.is_enabled()
        && sb
            .particle_positions()
            .all(|p| p.is_finite() && p.abs().max_element() < 100.0)
}

/// The settings every line carries: solver and its knobs, step, grid, material, damping, masses.
pub fn settings(
    world: &PhysicsWorld,
    solver: Solver,
    grid: &Grid,
    material: Material,
    damping: Damping,
) -> Record {
    let p = &world.integration_parameters;
    let fem = &p.soft_bodies.fem;
    let (name, cap) = match solver {
        Solver::Constraints => ("constraints", None),
        Solver::Fem { cg_cap } => ("fem", Some(cg_cap)),
    };
    record::object(json!({
        "solver": name,
        "fem_max_linear_iterations": cap,
        "fem_linear_tolerance": cap.map(|_| fem.linear_tolerance),
        "fem_max_dense_dofs": cap.map(|_| fem.max_dense_dofs),
        // rapier's f32 step, in its shortest decimal form (0.004166667, not 0.004166666883975267).
        "dt": p.dt.to_string().parse::<f64>().unwrap_or(f64::NAN),
        "num_solver_iterations": p.num_solver_iterations,
        "substeps_note": "num_solver_iterations is rapier's substep count per step",
        "num_internal_pgs_iterations": p.num_internal_pgs_iterations,
        "soft_additional_pgs_iterations": SoftBodyParticleSettings::default().additional_pgs_iterations,
        "soft_max_extra_substeps": p.soft_bodies.max_extra_substeps,
        "model": "SoftBodyCellModel::Corotational (linear elasticity in the cell's rotated frame + exact volume row)",
        "resolution": grid.particles,
        "resolution_is": "particles per axis (SoftBodyBuilder::cuboid, 5 tets per cube)",
        "E": material.young,
        "nu": material.poisson,
        "rho": material.density,
        "elastic_damping_ratio": damping.elastic_ratio,
        "deformation_damping": damping.deformation_rate,
        "mass_lumping": "row-sum lumped: each tet gives rho*V_tet/4 to each of its particles (SoftBodyBuilder::masses)",
        "precision": "f32",
        "can_sleep": false,
    }))
}

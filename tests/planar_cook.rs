//! Cook's membrane in plane stress against the converged value of the literature, and its
//! large-deformation counterpart solved by Newton's method with every model.

use rapier_fvm::fvm::VolumetricTreatment;
use rapier_fvm::glamx::DVec2;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{
    Diagonals, PlanarBodyBuilder, PlaneModel, TriangleMesh, edge_loads, solve_planar_equilibrium,
};
use rapier_fvm::statics::StaticSettings;

/// `u_y` at (48, 52) (Cook, Malkus and Plesha 1989), for E = 1, ν = 1/3, a total shear of 1.
const REFERENCE: f64 = 23.96;
const CORNERS: [DVec2; 4] = [
    DVec2::new(0.0, 0.0),
    DVec2::new(48.0, 44.0),
    DVec2::new(48.0, 60.0),
    DVec2::new(0.0, 44.0),
];

/// A formulation of the membrane: material, plane model, volumetric term, mesh pattern.
#[derive(Clone, Copy)]
struct Setup {
    model: MaterialModel,
    young: f64,
    poisson: f64,
    plane: PlaneModel,
    volumetric: VolumetricTreatment,
    diagonals: Diagonals,
    quadratic: bool,
}

/// Plane stress, `E = 1`, `ν = 1/3`, on alternating diagonals.
fn plane_stress(model: MaterialModel) -> Setup {
    Setup {
        model,
        young: 1.0,
        poisson: 1.0 / 3.0,
        plane: PlaneModel::PlaneStress,
        volumetric: VolumetricTreatment::PerElement,
        diagonals: Diagonals::Alternating,
        quadratic: false,
    }
}

/// The vertical displacement at (48, 52) on `cells` × `cells` quadrilaterals of two triangles,
/// under a total shear `load`, and the Newton iterations taken.
fn membrane(cells: usize, setup: Setup, load: f64) -> (f64, usize) {
    let mesh = TriangleMesh::quadrilateral_with(CORNERS, [cells, cells], setup.diagonals).unwrap();
    let material = Material::new(setup.model, setup.young, setup.poisson, 1.0).unwrap();
    let builder = PlanarBodyBuilder::new(mesh, material)
        .plane(setup.plane)
        .volumetric(setup.volumetric);
    let mut body = if setup.quadratic {
        builder.quadratic()
    } else {
        builder
    }
    .build()
    .unwrap();
    for node in body.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9) {
        body.pin(node, [true, true]).unwrap();
    }
    let loaded = body.nodes_on_line(DVec2::new(48.0, 0.0), DVec2::Y, 1e-9);
    let middle = (body.rest_positions().iter())
        .position(|p| p.distance(DVec2::new(48.0, 52.0)) < 1e-9)
        .unwrap();
    let loads = edge_loads(&body, &loaded, DVec2::new(0.0, load), true);
    let total: DVec2 = loads.iter().sum();
    assert!((total - DVec2::new(0.0, load)).length() < 1e-12 * load);
    let report = solve_planar_equilibrium(&mut body, &loads, &StaticSettings::default()).unwrap();
    let rest = body.rest_positions()[middle];
    (body.positions()[middle].y - rest.y, report.iterations)
}

/// Linear triangles converge to 23.96 from below at second order; the finest mesh tested
/// (64 × 64 cells, 8 192 triangles) within 1 % (the tolerance; it reaches -0.24 %).
#[test]
fn cooks_membrane_converges_to_the_reference() {
    let mut errors = Vec::new();
    for cells in [8, 16, 32, 64] {
        let (displacement, iterations) = membrane(cells, plane_stress(MaterialModel::Linear), 1.0);
        let error = displacement / REFERENCE - 1.0;
        println!(
            "{cells:3} cells: u_y(48, 52) = {displacement:.4} ({:+.2} %), {iterations} Newton",
            100.0 * error
        );
        assert_eq!(iterations, 1, "the linear law is solved in one Newton step");
        errors.push(error);
    }
    assert!(
        errors.windows(2).all(|w| w[0] < w[1] && w[1] < 0.0),
        "{errors:?}"
    );
    assert!(errors.last().unwrap().abs() < 0.01, "{errors:?}");
}

/// Under a load a thousand times smaller the large-deformation models agree with the linear law
/// (small strain and rotation: to 1e-3 relative, the order of the strains), and Newton converges
/// in a few iterations with each.
#[test]
fn large_deformation_models_agree_at_small_load() {
    let (linear, _) = membrane(16, plane_stress(MaterialModel::Linear), 1e-3);
    for model in [
        MaterialModel::StVenantKirchhoff,
        MaterialModel::Corotated,
        MaterialModel::StableNeoHookean,
    ] {
        let (displacement, iterations) = membrane(16, plane_stress(model), 1e-3);
        assert!(
            (displacement / linear - 1.0).abs() < 1e-3,
            "{model:?}: {displacement} against {linear}"
        );
        assert!(iterations <= 6, "{model:?}: {iterations} Newton iterations");
    }
}

/// Nearly incompressible plane strain, `λ = 7500`, `μ = 0.375` (ν = 0.499975), total shear 1:
/// `u_y(48, 52)` = 16.4326 (Krysl's `FinEtools`, quadratic NICE-T6 triangles with Richardson
/// extrapolation). On parallel diagonals, linear triangles with the volumetric term per
/// triangle lock (about -69 % at 8 192 triangles, reported); averaged on node patches they
/// converge within 2 % (the tolerance; -1.42 %). Quadratic triangles lock less (-2.31 %
/// at 512 elements) and, averaged over each element (mean dilatation), converge within 2 % too
/// (+0.23 %). The averaged energies are quadratic for the linear law, so at ν = 0.3 one Newton
/// step solves them: that checks the averaging's tangents (at ν = 0.499975 a step lands at the
/// round-off floor of `λ/μ = 20 000`, accepted after two more).
#[test]
fn nodal_averaging_frees_nearly_incompressible_plane_strain() {
    const REFERENCE: f64 = 16.4326;
    let (lambda, mu) = (7500.0, 0.375);
    let setup = |volumetric| Setup {
        model: MaterialModel::Linear,
        young: mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
        poisson: lambda / (2.0 * (lambda + mu)),
        plane: PlaneModel::PlaneStrain,
        volumetric,
        diagonals: Diagonals::Parallel,
        quadratic: false,
    };
    let (locked, _) = membrane(64, setup(VolumetricTreatment::PerElement), 1.0);
    let (averaged, _) = membrane(64, setup(VolumetricTreatment::NodalAverage), 1.0);
    let (locked_error, averaged_error) = (locked / REFERENCE - 1.0, averaged / REFERENCE - 1.0);
    println!(
        "per triangle {locked:.4} ({:+.2} %), averaged {averaged:.4} ({:+.2} %)",
        100.0 * locked_error,
        100.0 * averaged_error
    );
    assert!(
        locked_error < -0.5,
        "the per-triangle term should lock: {locked_error}"
    );
    assert!(averaged_error.abs() < 0.02, "averaged: {averaged_error}");
    // Quadratic triangles, averaged over each element (mean dilatation), on 512 elements.
    let quadratic = |volumetric| Setup {
        quadratic: true,
        ..setup(volumetric)
    };
    let (quadratic_plain, _) = membrane(16, quadratic(VolumetricTreatment::PerElement), 1.0);
    let (quadratic_averaged, _) = membrane(16, quadratic(VolumetricTreatment::ElementAverage), 1.0);
    let plain_error = quadratic_plain / REFERENCE - 1.0;
    let averaged_error = quadratic_averaged / REFERENCE - 1.0;
    println!(
        "quadratic: per element {:+.2} %, averaged {:+.2} %",
        100.0 * plain_error,
        100.0 * averaged_error
    );
    assert!(
        averaged_error.abs() < 0.02,
        "quadratic averaged: {averaged_error}"
    );
    // At ν = 0.3 the averaged linear laws are solved in one Newton step: their tangents are exact.
    let averaged = [
        (quadratic(VolumetricTreatment::ElementAverage), 8),
        (setup(VolumetricTreatment::NodalAverage), 16),
    ];
    for (averaged, cells) in averaged {
        let compressible = Setup {
            poisson: 0.3,
            young: 1.0,
            ..averaged
        };
        let (_, iterations) = membrane(cells, compressible, 1.0);
        assert_eq!(iterations, 1, "{:?}", compressible.volumetric);
    }
}

/// Quadratic (6-node) triangles reach the reference far sooner: within 1 % at 32 elements
/// (-0.76 %) and 0.2 % at 128 (-0.14 %), where linear triangles are -31.9 % and -11.9 % off;
/// the linear law in one Newton step.
#[test]
fn quadratic_triangles_converge_sooner() {
    let quadratic = Setup {
        quadratic: true,
        ..plane_stress(MaterialModel::Linear)
    };
    let (coarse, iterations) = membrane(4, quadratic, 1.0);
    let (finer, _) = membrane(8, quadratic, 1.0);
    let (coarse_error, finer_error) = (coarse / REFERENCE - 1.0, finer / REFERENCE - 1.0);
    println!(
        "quadratic: {coarse:.4} ({:+.2} %), {finer:.4} ({:+.2} %)",
        100.0 * coarse_error,
        100.0 * finer_error
    );
    assert!(coarse_error.abs() < 0.01 && finer_error.abs() < 0.002);
    assert_eq!(iterations, 1);
}

/// The averaged volumetric term carries the same pressure across the plane as in it: for the
/// linear law with `ε₃₃ = 0` and the volumetric part `K θ̄` averaged, `P = K θ̄ I + 2μ dev ε`,
/// so `P₃₃ − (P₁₁ + P₂₂)/2 = −μ tr ε` at every point, whatever `θ̄`, to round-off (1e-8 of the
/// largest stress; the pressure is λ/μ = 20 000 times the shear stiffness). The nearly
/// incompressible membrane, averaged on node patches on the locking parallel diagonals, where
/// `θ̄` and `tr ε` differ most.
#[test]
fn an_averaged_volumetric_term_gives_the_same_pressure_across_the_plane() {
    let (lambda, mu) = (7500.0, 0.375);
    let material = Material::new(
        MaterialModel::Linear,
        mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
        lambda / (2.0 * (lambda + mu)),
        1.0,
    )
    .unwrap();
    let mesh = TriangleMesh::quadrilateral_with(CORNERS, [16, 16], Diagonals::Parallel).unwrap();
    let mut body = PlanarBodyBuilder::new(mesh, material)
        .plane(PlaneModel::PlaneStrain)
        .volumetric(VolumetricTreatment::NodalAverage)
        .build()
        .unwrap();
    for node in body.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9) {
        body.pin(node, [true, true]).unwrap();
    }
    let loaded = body.nodes_on_line(DVec2::new(48.0, 0.0), DVec2::Y, 1e-9);
    let loads = edge_loads(&body, &loaded, DVec2::new(0.0, 1.0), true);
    solve_planar_equilibrium(&mut body, &loads, &StaticSettings::default()).unwrap();
    let stresses: Vec<_> = (0..body.mesh().triangles().len())
        .map(|q| (body.stress(q), body.deformation_gradient(q)))
        .collect();
    let largest = (stresses.iter())
        .map(|(s, _)| {
            let p = s.p.to_cols_array();
            p.iter().fold(s.p33.abs(), |m, v| m.max(v.abs()))
        })
        .fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (stress, f) in &stresses {
        let trace = f.x_axis.x + f.y_axis.y - 2.0;
        let across = stress.p33 - 0.5 * (stress.p.x_axis.x + stress.p.y_axis.y);
        worst = worst.max((across + mu * trace).abs());
    }
    println!("largest stress {largest:.4e}, worst mismatch {worst:.3e}");
    assert!(worst < 1e-8 * largest, "{worst} against {largest}");
}

//! 2D bodies (plane stress and plane strain on triangles) against closed-form results: the
//! patch test, uniaxial tension, the reduced laws, control-volume independence of the forces,
//! forces and tangents as derivatives of the energy, and typed errors for bad meshes.

use rapier_fvm::Error;
use rapier_fvm::fvm::VolumetricTreatment;
use rapier_fvm::glamx::{DMat2, DVec2};
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{
    ControlVolumes, PlanarBody, PlanarBodyBuilder, PlaneModel, TriangleMesh, TriangleRest,
    edge_loads, solve_planar_equilibrium, traction_along,
};
use rapier_fvm::statics::StaticSettings;

const MODELS: [MaterialModel; 4] = [
    MaterialModel::Linear,
    MaterialModel::StVenantKirchhoff,
    MaterialModel::Corotated,
    MaterialModel::StableNeoHookean,
];
const PLANES: [PlaneModel; 2] = [PlaneModel::PlaneStress, PlaneModel::PlaneStrain];

/// The plane, volumetric treatment and element order a body can have: both planes per element
/// on linear and quadratic triangles, and plane strain averaged on node patches (linear) or
/// over elements (quadratic).
const SETUPS: [(PlaneModel, VolumetricTreatment, bool); 6] = [
    (
        PlaneModel::PlaneStress,
        VolumetricTreatment::PerElement,
        false,
    ),
    (
        PlaneModel::PlaneStrain,
        VolumetricTreatment::PerElement,
        false,
    ),
    (
        PlaneModel::PlaneStrain,
        VolumetricTreatment::NodalAverage,
        false,
    ),
    (
        PlaneModel::PlaneStress,
        VolumetricTreatment::PerElement,
        true,
    ),
    (
        PlaneModel::PlaneStrain,
        VolumetricTreatment::PerElement,
        true,
    ),
    (
        PlaneModel::PlaneStrain,
        VolumetricTreatment::ElementAverage,
        true,
    ),
];

/// A body of `mesh` and `material` with a setup of [`SETUPS`].
fn body_with(
    mesh: &TriangleMesh,
    material: Material,
    (plane, volumetric, quadratic): (PlaneModel, VolumetricTreatment, bool),
) -> PlanarBodyBuilder {
    let builder = PlanarBodyBuilder::new(mesh.clone(), material)
        .plane(plane)
        .volumetric(volumetric);
    if quadratic {
        builder.quadratic()
    } else {
        builder
    }
}

/// A deterministic pseudo-random number in [-1, 1) for `i`.
fn jitter(i: usize) -> f64 {
    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// The unit square in 6 × 6 cells with every interior node moved by up to a quarter cell.
fn distorted_square() -> TriangleMesh {
    let mesh = TriangleMesh::rectangle(DVec2::ONE, [6, 6]).unwrap();
    let h = 1.0 / 6.0;
    let rest: Vec<DVec2> = (mesh.rest_positions().iter().enumerate())
        .map(|(i, p)| {
            let interior = p.x > 1e-9 && p.x < 1.0 - 1e-9 && p.y > 1e-9 && p.y < 1.0 - 1e-9;
            let shift = DVec2::new(jitter(2 * i), jitter(2 * i + 1)) * 0.25 * h;
            if interior { *p + shift } else { *p }
        })
        .collect();
    TriangleMesh::new(rest, mesh.triangles().to_vec()).unwrap()
}

fn material(model: MaterialModel, poisson: f64) -> Material {
    Material::new(model, 1e6, poisson, 1000.0).unwrap()
}

/// Patch test: the boundary moved by an affine map `x = A p + c`, every interior node of a
/// distorted mesh must follow the same map (a uniform deformation is an equilibrium of every
/// model, and linear triangles represent it exactly). Tolerance 1e-9 of the cell size: the
/// solve's round-off, far below any discretization error.
#[test]
fn the_patch_test_holds_on_a_distorted_mesh() {
    let mesh = distorted_square();
    let a = DMat2::from_cols(DVec2::new(1.08, 0.03), DVec2::new(-0.05, 0.93));
    let c = DVec2::new(0.2, -0.1);
    let on_boundary = |p: &DVec2| p.x < 1e-9 || p.x > 1.0 - 1e-9 || p.y < 1e-9 || p.y > 1.0 - 1e-9;
    for model in MODELS {
        for setup in SETUPS {
            let mut body = body_with(&mesh, material(model, 0.3), setup)
                .thickness(0.05)
                .build()
                .unwrap();
            let rest = body.rest_positions().to_vec();
            let boundary: Vec<usize> = (0..rest.len()).filter(|&i| on_boundary(&rest[i])).collect();
            for &i in &boundary {
                body.pin(i, [true, true]).unwrap();
            }
            for (i, x) in body.positions_mut().iter_mut().enumerate() {
                *x = a * rest[i] + c + DVec2::new(jitter(7 * i), jitter(7 * i + 3)) * 1e-3;
            }
            for &i in &boundary {
                body.positions_mut()[i] = a * rest[i] + c;
            }
            let loads = vec![DVec2::ZERO; rest.len()];
            let settings = StaticSettings {
                tolerance: 1e-12,
                max_iterations: 50,
            };
            solve_planar_equilibrium(&mut body, &loads, &settings)
                .unwrap_or_else(|e| panic!("{model:?} {setup:?}: {e}"));
            let worst = (body.positions().iter().zip(&rest))
                .map(|(x, p)| x.distance(a * *p + c))
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-9 / 6.0,
                "{model:?} {setup:?}: {worst:e} m off the affine map"
            );
        }
    }
}

/// A 2 m × 1 m sheet, rollers on its left edge, pulled by `force` (N) on its right edge.
fn pulled_sheet(plane: PlaneModel, poisson: f64, force: f64) -> PlanarBody {
    let mesh = TriangleMesh::rectangle(DVec2::new(2.0, 1.0), [8, 4]).unwrap();
    let left = mesh.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9);
    let right = mesh.nodes_on_line(DVec2::new(2.0, 0.0), DVec2::Y, 1e-9);
    let mut body = PlanarBodyBuilder::new(mesh, material(MaterialModel::Linear, poisson))
        .plane(plane)
        .thickness(0.1)
        .pinned_along(left, 0)
        .pinned_along([0], 1)
        .build()
        .unwrap();
    let loads = edge_loads(&body, &right, DVec2::new(force, 0.0), true);
    solve_planar_equilibrium(&mut body, &loads, &StaticSettings::default()).unwrap();
    body
}

/// Uniaxial tension, linear law, `σ₁₁ = F / (H t)`: plane stress gives `ε₁₁ = σ₁₁/E` and
/// `ε₂₂ = −ν ε₁₁`; plane strain `ε₁₁ = (1 − ν²) σ₁₁/E`, `ε₂₂/ε₁₁ = −ν/(1 − ν)` and
/// `σ₃₃ = ν σ₁₁`. Every triangle, to 1e-6 relative (the solve reaches about 1e-12).
#[test]
fn uniaxial_tension_follows_the_plane_laws() {
    let (e, nu, force) = (1e6, 0.3, 100.0);
    let sigma = force / (1.0 * 0.1);
    for plane in PLANES {
        let body = pulled_sheet(plane, nu, force);
        for t in 0..body.mesh().triangles().len() {
            let f = body.deformation_gradient(t);
            let (e11, e22) = (f.x_axis.x - 1.0, f.y_axis.y - 1.0);
            let stress = body.stress(t);
            let (expected_e11, ratio) = match plane {
                PlaneModel::PlaneStress => (sigma / e, -nu),
                PlaneModel::PlaneStrain => ((1.0 - nu * nu) * sigma / e, -nu / (1.0 - nu)),
            };
            assert!(
                (e11 / expected_e11 - 1.0).abs() < 1e-6,
                "{plane:?} ε₁₁ {e11:e}"
            );
            assert!(
                (e22 / e11 / ratio - 1.0).abs() < 1e-6,
                "{plane:?} ε₂₂/ε₁₁ {}",
                e22 / e11
            );
            match plane {
                PlaneModel::PlaneStress => assert!(stress.p33.abs() < 1e-9 * sigma),
                PlaneModel::PlaneStrain => {
                    assert!((stress.p33 / (nu * stress.p.x_axis.x) - 1.0).abs() < 1e-6)
                }
            }
        }
    }
}

/// The Cauchy stress of the pulled sheet: the force over the deformed section,
/// `σ₁₁ (H F₂₂) (t s) = F`, to 1e-9 relative (the solve reaches about 1e-12), the other
/// in-plane components zero to 1e-9 of `σ₁₁`, and `σ₃₃` zero in plane stress and `ν σ₁₁` in
/// plane strain to twice the strain `ε₁₁` (the linear law gives `P₃₃ = ν P₁₁`; Cauchy and
/// nominal stresses differ at the order of the strain).
#[test]
fn cauchy_stress_is_the_force_over_the_deformed_section() {
    let (nu, force) = (0.3, 100.0);
    for plane in PLANES {
        let body = pulled_sheet(plane, nu, force);
        for (t, sigma) in body.cauchy_stresses().iter().enumerate() {
            let f = body.deformation_gradient(t);
            let stretch = body.stress(t).stretch;
            let carried = sigma.x_axis.x * (1.0 * f.y_axis.y) * (0.1 * stretch);
            assert!((carried / force - 1.0).abs() < 1e-9, "{plane:?} {carried}");
            for off in [sigma.x_axis.y, sigma.y_axis.x, sigma.y_axis.y] {
                assert!(off.abs() < 1e-9 * sigma.x_axis.x, "{plane:?} {sigma:?}");
            }
            let expected_33 = match plane {
                PlaneModel::PlaneStress => 0.0,
                PlaneModel::PlaneStrain => nu * sigma.x_axis.x,
            };
            let strain = f.x_axis.x - 1.0;
            assert!(
                (sigma.z_axis.z - expected_33).abs() <= 2.0 * strain * sigma.x_axis.x,
                "{plane:?} σ₃₃ {}",
                sigma.z_axis.z
            );
        }
    }
}

/// The reduced linear law of plane stress is `λ* tr ε I + 2μ ε` with `λ* = 2λμ/(λ + 2μ)`, to
/// round-off (1e-12 of the largest term cancelled, `(|λ| + 2μ) |ε|`), also at ν = 0.4999
/// where `λ` is 2 500 times `μ` and `λ*` stays below `2μ`.
#[test]
fn plane_stress_reduces_the_linear_law() {
    for nu in [0.0, 0.3, 0.45, 0.4999, -0.5] {
        let m = material(MaterialModel::Linear, nu);
        let (lambda, mu) = (m.lame().lambda, m.lame().mu);
        let reduced = 2.0 * lambda * mu / (lambda + 2.0 * mu);
        let law = rapier_fvm::planar::PlanarLaw {
            model: rapier_fvm::material::LinearElastic(m.lame()),
            plane: PlaneModel::PlaneStress,
        };
        let strain = DMat2::from_cols(DVec2::new(1e-3, 2e-4), DVec2::new(2e-4, -4e-4));
        let stress = law.stress(&(DMat2::IDENTITY + strain)).p;
        let tr = strain.x_axis.x + strain.y_axis.y;
        let expected = DMat2::IDENTITY * (reduced * tr) + strain * (2.0 * mu);
        let error = (stress - expected)
            .to_cols_array()
            .iter()
            .map(|v| v.abs())
            .fold(0.0, f64::max);
        let largest_term = (lambda.abs() + 2.0 * mu) * 1e-3;
        assert!(
            error < 1e-12 * largest_term,
            "ν = {nu}: off by {error:e} Pa"
        );
        assert!(reduced < 2.0 * mu + 1e-9 * mu);
    }
}

/// With the stress constant in a triangle, the traction over a node's control-volume boundary
/// depends only on where the boundary meets the edges: the median and the circumcentric paths
/// give `P b_i` to 1e-12 (relative), on acute, right and obtuse triangles. Their areas differ
/// and each sums to the triangle's.
#[test]
fn the_forces_do_not_depend_on_the_control_volumes() {
    let triangles = [
        [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.1),
            DVec2::new(0.4, 0.9),
        ],
        [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 1.0),
        ],
        [
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.0),
            DVec2::new(1.0, 0.4),
        ],
    ];
    let p = DMat2::from_cols(DVec2::new(3.0e5, -1.2e5), DVec2::new(0.7e5, -2.2e5));
    for corners in triangles {
        let rest = TriangleRest::new(corners);
        let mut areas = [0.0; 2];
        for i in 0..3 {
            let expected = rest.forces(&p, 1.0)[i];
            for (k, cv) in [ControlVolumes::Median, ControlVolumes::Circumcentric]
                .into_iter()
                .enumerate()
            {
                let traction = traction_along(&p, &cv.boundary(corners, i));
                assert!((traction - expected).length() < 1e-12 * expected.length().max(1.0));
                areas[k] += cv.corner_area(corners, i);
            }
        }
        for area in areas {
            assert!((area - rest.area()).abs() < 1e-12 * rest.area());
        }
    }
}

/// Masses: `ρ t A` in all, for both control volumes and for quadratic triangles (HRZ);
/// circumcentric control volumes refuse a mesh whose obtuse triangles leave a node a negative
/// area, with the node named.
#[test]
fn masses_follow_the_control_volumes() {
    let mesh = TriangleMesh::disk(0.5, 4).unwrap();
    for cv in [ControlVolumes::Median, ControlVolumes::Circumcentric] {
        let body = PlanarBodyBuilder::new(mesh.clone(), material(MaterialModel::Corotated, 0.3))
            .thickness(0.02)
            .control_volumes(cv)
            .build()
            .unwrap();
        let expected = 1000.0 * 0.02 * mesh.area();
        assert!((body.total_mass() - expected).abs() < 1e-12 * expected);
        assert!(body.masses().iter().all(|&m| m > 0.0));
    }
    let quadratic = PlanarBodyBuilder::new(mesh.clone(), material(MaterialModel::Corotated, 0.3))
        .thickness(0.02)
        .quadratic()
        .build()
        .unwrap();
    let expected = 1000.0 * 0.02 * mesh.area();
    assert!((quadratic.total_mass() - expected).abs() < 1e-12 * expected);
    assert!(quadratic.masses().iter().all(|&m| m > 0.0));
    let flat = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(0.5, 0.05),
        DVec2::new(0.5, 1.0),
    ];
    let obtuse = TriangleMesh::new(flat.to_vec(), vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    let built = PlanarBodyBuilder::new(obtuse, material(MaterialModel::Linear, 0.3))
        .control_volumes(ControlVolumes::Circumcentric)
        .build();
    assert!(
        matches!(built, Err(Error::NonPositiveControlArea { .. })),
        "{built:?}"
    );
}

/// Internal forces are minus the gradient of the elastic energy: central differences of the
/// energy at a large deformation, to 1e-6 of the largest force (the differences' truncation
/// and round-off are below 1e-8), every model, plane and volumetric treatment.
#[test]
fn forces_are_the_gradient_of_the_energy() {
    let mesh = TriangleMesh::rectangle(DVec2::new(1.0, 0.5), [3, 2]).unwrap();
    for model in MODELS {
        for setup in SETUPS {
            let mut body = body_with(&mesh, material(model, 0.35), setup)
                .build()
                .unwrap();
            for (i, x) in body.positions_mut().iter_mut().enumerate() {
                let p = *x;
                *x = DVec2::new(1.2 * p.x + 0.3 * p.y * p.y, 0.8 * p.y + 0.1 * p.x)
                    + DVec2::new(jitter(i), jitter(i + 50)) * 0.02;
            }
            let forces = body.internal_forces();
            let scale = forces.iter().map(|f| f.length()).fold(0.0, f64::max);
            let h = 1e-6;
            for node in 0..forces.len() {
                for axis in 0..2 {
                    let mut x = body.positions().to_vec();
                    x[node][axis] += h;
                    let up = body.elastic_energy_at(&x);
                    x[node][axis] -= 2.0 * h;
                    let down = body.elastic_energy_at(&x);
                    let numeric = -(up - down) / (2.0 * h);
                    let error = (numeric - forces[node][axis]).abs();
                    assert!(
                        error < 1e-6 * scale,
                        "{model:?} {setup:?} node {node}: {error:e} N"
                    );
                }
            }
        }
    }
}

/// Bad meshes are refused with the offending triangle or node named, never a panic.
#[test]
fn bad_meshes_are_typed_errors() {
    let square = vec![DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
    let cases: Vec<(Vec<DVec2>, Vec<[u32; 3]>)> = vec![
        (vec![], vec![]),
        (square.clone(), vec![[0, 1, 4]]),
        (square.clone(), vec![[0, 1, 1], [0, 2, 3]]),
        (square.clone(), vec![[0, 2, 1], [0, 2, 3]]),
        (
            vec![DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0), DVec2::Y],
            vec![[0, 1, 2], [0, 1, 3]],
        ),
        (square.clone(), vec![[0, 1, 2]]),
        (
            vec![DVec2::ZERO, DVec2::X, DVec2::new(f64::NAN, 1.0)],
            vec![[0, 1, 2]],
        ),
    ];
    let mut messages = Vec::new();
    for (rest, triangles) in cases {
        let error = TriangleMesh::new(rest, triangles).expect_err("a bad mesh was accepted");
        messages.push(error.to_string());
    }
    assert!(matches!(
        TriangleMesh::rectangle(DVec2::new(1.0, -1.0), [2, 2]),
        Err(Error::InvalidGeneratorParameter { .. })
    ));
    assert!(
        messages[1].contains("triangle 0 refers to node 4"),
        "{}",
        messages[1]
    );
    assert!(
        messages[2].contains("triangle 0 uses node 1"),
        "{}",
        messages[2]
    );
    assert!(
        messages[3].contains("triangle 0 is inverted"),
        "{}",
        messages[3]
    );
    assert!(
        messages[4].contains("triangle 0 is degenerate"),
        "{}",
        messages[4]
    );
    assert!(
        messages[5].contains("node 3 belongs to no element"),
        "{}",
        messages[5]
    );
    assert!(messages[6].contains("node 2"), "{}", messages[6]);
}

/// At the extremes (crushed to 1 %, inverted, stretched fivefold, sheared by 3) every model
/// gives a finite stress, stretch, energy and forces in both planes: a bounded state, never NaN.
#[test]
fn extreme_deformations_give_finite_stresses() {
    let extremes = [
        DMat2::from_diagonal(DVec2::new(0.01, 1.0)),
        DMat2::from_diagonal(DVec2::new(-0.5, 1.0)),
        DMat2::from_diagonal(DVec2::new(5.0, 5.0)),
        DMat2::from_cols(DVec2::new(1.0, 0.0), DVec2::new(3.0, 1.0)),
    ];
    let corners = vec![DVec2::ZERO, DVec2::X, DVec2::Y];
    let triangle = TriangleMesh::new(corners.clone(), vec![[0, 1, 2]]).unwrap();
    for model in MODELS {
        for plane in PLANES {
            let mut body = PlanarBodyBuilder::new(triangle.clone(), material(model, 0.45))
                .plane(plane)
                .build()
                .unwrap();
            for f in extremes {
                for (x, p) in body.positions_mut().iter_mut().zip(&corners) {
                    *x = f * *p;
                }
                let stress = body.stress(0);
                let forces = body.internal_forces();
                let finite = stress.p.is_finite()
                    && stress.stretch.is_finite()
                    && body.elastic_energy().is_finite()
                    && forces.iter().all(|f| f.is_finite());
                assert!(
                    finite && stress.stretch > 0.0,
                    "{model:?} {plane:?} {f:?}: {stress:?}"
                );
            }
        }
    }
}

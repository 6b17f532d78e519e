//! Cook's membrane (Cook 1974): the tapered panel with corners (0,0), (48,44), (48,60), (0,44),
//! clamped at x = 0, a total vertical shear spread evenly on its right edge, unit thickness,
//! linear elasticity.
//!
//! 1. Plane stress, E = 1, ν = 1/3, total shear 1: the vertical displacement at the middle of
//!    the loaded edge, (48, 52), converges to 23.96 (Cook, Malkus and Plesha, "Concepts and
//!    Applications of Finite Element Analysis", 1989). Linear triangles are stiff in bending:
//!    the table shows the error shrinking with the mesh, with the order of convergence observed
//!    between successive meshes against the reference; the top corner's displacement, (48, 60),
//!    is printed beside it.
//! 2. Nearly incompressible plane strain, λ = 7500, μ = 0.375 (ν = 0.499975), total shear 1:
//!    `u_y(48, 52)` = 16.4326, the reference of Krysl's `FinEtools` for this case (quadratic NICE-T6
//!    elements with Richardson extrapolation), on meshes of alternating and of parallel
//!    diagonals, with the volumetric term per triangle and averaged on node patches; then on
//!    quadratic triangles, with the term per element and averaged over each (mean dilatation).
//!
//! Run with `cargo run --release --example cooks_membrane`. The last line is a JSON summary.

use rapier_fvm::fvm::VolumetricTreatment;
use rapier_fvm::glamx::DVec2;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{
    Diagonals, PlanarBodyBuilder, PlaneModel, TriangleMesh, edge_loads, solve_planar_equilibrium,
};
use rapier_fvm::statics::StaticSettings;
use std::time::Instant;

/// `u_y(48, 52)` of the plane stress case.
const REFERENCE: f64 = 23.96;
/// `u_y(48, 52)` of the nearly incompressible plane strain case.
const INCOMPRESSIBLE_REFERENCE: f64 = 16.4326;
const CORNERS: [DVec2; 4] = [
    DVec2::new(0.0, 0.0),
    DVec2::new(48.0, 44.0),
    DVec2::new(48.0, 60.0),
    DVec2::new(0.0, 44.0),
];

/// A material (Pa), plane model, volumetric treatment and mesh pattern.
#[derive(Clone, Copy)]
struct Setup {
    young: f64,
    poisson: f64,
    plane: PlaneModel,
    volumetric: VolumetricTreatment,
    diagonals: Diagonals,
    quadratic: bool,
}

/// The plane stress case.
const STRESS: Setup = Setup {
    young: 1.0,
    poisson: 1.0 / 3.0,
    plane: PlaneModel::PlaneStress,
    volumetric: VolumetricTreatment::PerElement,
    diagonals: Diagonals::Alternating,
    quadratic: false,
};

/// The nearly incompressible plane strain case, `λ = 7500`, `μ = 0.375`.
fn incompressible(volumetric: VolumetricTreatment, diagonals: Diagonals) -> Setup {
    let (lambda, mu) = (7500.0, 0.375);
    Setup {
        young: mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
        poisson: lambda / (2.0 * (lambda + mu)),
        plane: PlaneModel::PlaneStrain,
        volumetric,
        diagonals,
        quadratic: false,
    }
}

/// One solve on `cells` × `cells` quadrilaterals (two triangles each) under a total shear of
/// 1: the vertical displacements at (48, 52) and (48, 60), the triangle count and the
/// milliseconds taken.
fn solve(cells: usize, setup: Setup) -> Result<(f64, f64, usize, f64), rapier_fvm::Error> {
    let started = Instant::now();
    let mesh = TriangleMesh::quadrilateral_with(CORNERS, [cells, cells], setup.diagonals)?;
    let triangles = mesh.triangles().len();
    let material = Material::new(MaterialModel::Linear, setup.young, setup.poisson, 1.0)?;
    let mut builder = PlanarBodyBuilder::new(mesh, material)
        .plane(setup.plane)
        .volumetric(setup.volumetric);
    if setup.quadratic {
        builder = builder.quadratic();
    }
    let free = builder.build()?;
    let clamped = free.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9);
    let loaded = free.nodes_on_line(DVec2::new(48.0, 0.0), DVec2::Y, 1e-9);
    let find = |point: DVec2| {
        (free.rest_positions().iter())
            .position(|p| p.distance(point) < 1e-9)
            .expect("the generator puts a node there")
    };
    let (middle, corner) = (find(DVec2::new(48.0, 52.0)), find(DVec2::new(48.0, 60.0)));
    let mut body = free;
    for node in clamped {
        body.pin(node, [true, true])?;
    }
    let loads = edge_loads(&body, &loaded, DVec2::new(0.0, 1.0), true);
    solve_planar_equilibrium(&mut body, &loads, &StaticSettings::default())?;
    let rest = body.rest_positions();
    let uy = |node: usize| body.positions()[node].y - rest[node].y;
    let ms = started.elapsed().as_secs_f64() * 1e3;
    Ok((uy(middle), uy(corner), triangles, ms))
}

/// Prints the convergence of `setup` against `reference` over `meshes`; returns the finest
/// mesh's displacement at (48, 52) and its triangles.
fn table(
    setup: Setup,
    reference: f64,
    meshes: &[usize],
) -> Result<(f64, usize), rapier_fvm::Error> {
    println!("cells  triangles   u_y(48,52)   error    order   u_y(48,60)   ms");
    let mut last: Option<f64> = None;
    let mut finest = (0.0, 0);
    for &cells in meshes {
        let (middle, corner, triangles, ms) = solve(cells, setup)?;
        let error = middle / reference - 1.0;
        let order = last
            .map(|previous: f64| ((reference - previous) / (reference - middle)).log2())
            .filter(|order| order.is_finite())
            .map_or(String::from("    -"), |order| format!("{order:5.2}"));
        println!(
            "{cells:5} {triangles:10} {middle:12.4} {:+7.2}%  {order}  {corner:11.4} {ms:7.1}",
            100.0 * error
        );
        last = Some(middle);
        finest = (middle, triangles);
    }
    Ok(finest)
}

fn main() -> Result<(), rapier_fvm::Error> {
    println!("Cook's membrane, plane stress, E = 1, nu = 1/3; reference u_y(48, 52) = {REFERENCE}");
    let (displacement, triangles) = table(STRESS, REFERENCE, &[2, 4, 8, 16, 32, 64, 128])?;
    println!("\nthe same, quadratic (6-node) triangles");
    let quadratic = Setup {
        quadratic: true,
        ..STRESS
    };
    let (quadratic_displacement, quadratic_triangles) =
        table(quadratic, REFERENCE, &[2, 4, 8, 16, 32])?;
    let mut incompressible_errors = Vec::new();
    for diagonals in [Diagonals::Alternating, Diagonals::Parallel] {
        for volumetric in [
            VolumetricTreatment::PerElement,
            VolumetricTreatment::NodalAverage,
        ] {
            println!(
                "\nplane strain, lambda = 7500, mu = 0.375, {diagonals:?} diagonals, {volumetric:?}; reference {INCOMPRESSIBLE_REFERENCE}"
            );
            let setup = incompressible(volumetric, diagonals);
            let (finest, _) = table(setup, INCOMPRESSIBLE_REFERENCE, &[4, 8, 16, 32, 64])?;
            let error = finest / INCOMPRESSIBLE_REFERENCE - 1.0;
            incompressible_errors.push(format!("\"{diagonals:?} {volumetric:?}\": {error:.5}"));
        }
    }
    let mut quadratic_errors = Vec::new();
    for volumetric in [
        VolumetricTreatment::PerElement,
        VolumetricTreatment::ElementAverage,
    ] {
        println!(
            "\nplane strain, lambda = 7500, mu = 0.375, quadratic triangles on parallel diagonals, {volumetric:?}; reference {INCOMPRESSIBLE_REFERENCE}"
        );
        let setup = Setup {
            quadratic: true,
            ..incompressible(volumetric, Diagonals::Parallel)
        };
        let (finest, _) = table(setup, INCOMPRESSIBLE_REFERENCE, &[2, 4, 8, 16, 32])?;
        let error = finest / INCOMPRESSIBLE_REFERENCE - 1.0;
        quadratic_errors.push(format!("\"{volumetric:?}\": {error:.5}"));
    }
    let rel_error = displacement / REFERENCE - 1.0;
    println!(
        "{{\"displacement\": {displacement:.6}, \"reference\": {REFERENCE}, \"rel_error\": {rel_error:.6}, \"triangles\": {triangles}, \"plane\": \"stress\", \"point\": [48, 52], \"quadratic\": {{\"displacement\": {quadratic_displacement:.6}, \"triangles\": {quadratic_triangles}}}, \"incompressible_reference\": {INCOMPRESSIBLE_REFERENCE}, \"incompressible_rel_error_at_8192_triangles\": {{{}}}, \"incompressible_quadratic_rel_error_at_2048_elements\": {{{}}}}}",
        incompressible_errors.join(", "),
        quadratic_errors.join(", ")
    );
    Ok(())
}

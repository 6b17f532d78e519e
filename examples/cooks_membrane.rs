//! Cook's membrane (Cook 1974): the tapered panel with corners (0,0), (48,44), (48,60), (0,44),
//! clamped at x = 0, a total vertical shear of 1 spread evenly on its right edge, E = 1,
//! ν = 1/3, plane stress, linear elasticity, unit thickness. The vertical displacement at the
//! middle of the loaded edge, (48, 52), converges to 23.96 (Cook, Malkus and Plesha, "Concepts
//! and Applications of Finite Element Analysis", 1989); the top corner's, (48, 60), is printed
//! beside it.
//!
//! Linear triangles are stiff in bending: the table shows the error shrinking with the mesh,
//! with the order of convergence observed between successive meshes against the reference.
//!
//! Run with `cargo run --release --example cooks_membrane`. The last line is a JSON summary.

use rapier_fvm::glamx::DVec2;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{
    PlanarBodyBuilder, PlaneModel, TriangleMesh, edge_loads, solve_planar_equilibrium,
};
use rapier_fvm::statics::StaticSettings;
use std::time::Instant;

const REFERENCE: f64 = 23.96;
const CORNERS: [DVec2; 4] = [
    DVec2::new(0.0, 0.0),
    DVec2::new(48.0, 44.0),
    DVec2::new(48.0, 60.0),
    DVec2::new(0.0, 44.0),
];

/// One solve on `cells` × `cells` quadrilaterals (two triangles each): the vertical
/// displacements at (48, 52) and (48, 60), the triangle count and the milliseconds taken.
fn solve(cells: usize) -> Result<(f64, f64, usize, f64), rapier_fvm::Error> {
    let started = Instant::now();
    let mesh = TriangleMesh::quadrilateral(CORNERS, [cells, cells])?;
    let clamped = mesh.nodes_on_line(DVec2::ZERO, DVec2::Y, 1e-9);
    let loaded = mesh.nodes_on_line(DVec2::new(48.0, 0.0), DVec2::Y, 1e-9);
    let find = |point: DVec2| {
        (mesh.rest_positions().iter())
            .position(|p| p.distance(point) < 1e-9)
            .expect("the generator puts a node there")
    };
    let (middle, corner) = (find(DVec2::new(48.0, 52.0)), find(DVec2::new(48.0, 60.0)));
    let triangles = mesh.triangles().len();
    let material = Material::new(MaterialModel::Linear, 1.0, 1.0 / 3.0, 1.0)?;
    let mut body = PlanarBodyBuilder::new(mesh, material)
        .plane(PlaneModel::PlaneStress)
        .thickness(1.0)
        .pinned_nodes(clamped)
        .build()?;
    let loads = edge_loads(&body, &loaded, DVec2::new(0.0, 1.0), true);
    solve_planar_equilibrium(&mut body, &loads, &StaticSettings::default())?;
    let rest = body.mesh().rest_positions();
    let uy = |node: usize| body.positions()[node].y - rest[node].y;
    let ms = started.elapsed().as_secs_f64() * 1e3;
    Ok((uy(middle), uy(corner), triangles, ms))
}

fn main() -> Result<(), rapier_fvm::Error> {
    println!(
        "Cook's membrane, plane stress, linear triangles; reference u_y(48, 52) = {REFERENCE}"
    );
    println!("cells  triangles   u_y(48,52)   error    order   u_y(48,60)   ms");
    let mut last: Option<f64> = None;
    let mut finest = (0.0, 0);
    for cells in [2, 4, 8, 16, 32, 64, 128] {
        let (middle, corner, triangles, ms) = solve(cells)?;
        let error = middle / REFERENCE - 1.0;
        let order = last.map_or(String::from("    -"), |previous: f64| {
            format!(
                "{:5.2}",
                ((REFERENCE - previous) / (REFERENCE - middle)).log2()
            )
        });
        println!(
            "{cells:5} {triangles:10} {middle:12.4} {:+7.2}%  {order}  {corner:11.4} {ms:7.1}",
            100.0 * error
        );
        last = Some(middle);
        finest = (middle, triangles);
    }
    let (displacement, triangles) = finest;
    let rel_error = displacement / REFERENCE - 1.0;
    println!(
        "{{\"displacement\": {displacement:.6}, \"reference\": {REFERENCE}, \"rel_error\": {rel_error:.6}, \"triangles\": {triangles}, \"plane\": \"stress\", \"point\": [48, 52]}}"
    );
    Ok(())
}

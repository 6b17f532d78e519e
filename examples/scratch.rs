//! scratch
use rapier_fvm::prelude::*;
use rapier_fvm::fvm::{FvmMesh, TetRest};
use rapier_fvm::material::*;
#[derive(Clone, Copy)] struct Null;
impl HyperelasticModel for Null { fn energy_density(&self, _: &DMat3) -> f64 {0.0} fn first_piola(&self, f: &DMat3) -> DMat3 { *f } fn first_piola_differential(&self, _: &DMat3, d: &DMat3) -> DMat3 {*d} }
fn main() -> Result<(), Error> {
    let mesh = mesh::cuboid(DVec3::splat(0.2), [40,40,40])?;
    let mat = Material::new(MaterialModel::StVenantKirchhoff, 1e6, 0.3, 1000.0)?;
    let d = RayleighDamping::stiffness_proportional(1e-3, mat.lame())?;
    let mut fvm = FvmMesh::new(&mesh);
    let x: Vec<DVec3> = mesh.positions().iter().map(|p| *p * 1.01).collect();
    let v: Vec<DVec3> = mesh.positions().iter().map(|p| *p * 0.1).collect();
    let mut out = vec![DVec3::ZERO; x.len()];
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
    let n = mesh.tet_count() as f64;
    let t = std::time::Instant::now(); for _ in 0..20 { fvm.internal_forces(&Null, None, &x, &v, &mut out); } println!("null no damp {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let t = std::time::Instant::now(); for _ in 0..20 { fvm.internal_forces(&Null, Some(&d), &x, &v, &mut out); } println!("null + damp {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let m = StVenantKirchhoff(mat.lame());
    let t = std::time::Instant::now(); for _ in 0..20 { fvm.internal_forces(&m, None, &x, &v, &mut out); } println!("stvk no damp {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let t = std::time::Instant::now(); for _ in 0..20 { fvm.internal_forces(&m, Some(&d), &x, &v, &mut out); } println!("stvk + damp {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let tets = mesh.tets().to_vec();
    let t = std::time::Instant::now(); for _ in 0..20 { gather_scatter(&tets, &x, &mut out); } println!("gather scatter {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let rest: Vec<TetRest> = fvm.rest().to_vec();
    let t = std::time::Instant::now(); for _ in 0..20 { fvm.internal_forces(&Null, None, &x, &v, &mut out); } println!("null no damp again {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let t = std::time::Instant::now(); for _ in 0..20 { direct(&tets, &rest, &x, &mut out); } println!("direct {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let t = std::time::Instant::now(); for _ in 0..20 { direct_kernel(&tets, &rest, &x, &v, &mut out); } println!("direct kernel {:.1} ns", t.elapsed().as_nanos() as f64 / 20.0 / n);
    let t = std::time::Instant::now(); let mut acc = DMat3::ZERO; for _ in 0..20 { for r in &rest { acc += r.control_normals(); } } println!("stream rest {:.1} ns {}", t.elapsed().as_nanos() as f64 / 20.0 / n, acc.x_axis.x);
    });
    Ok(())
}
#[allow(dead_code)]
pub fn gather_scatter(tets: &[[u32;4]], x: &[DVec3], out: &mut [DVec3]) {
    out.fill(DVec3::ZERO);
    for tet in tets {
        let xs = tet.map(|n| x[n as usize]);
        for c in 0..4 { out[tet[c] as usize] += xs[c]; }
    }
}
#[allow(dead_code)]
pub fn direct(tets: &[[u32;4]], rest: &[TetRest], x: &[DVec3], out: &mut [DVec3]) {
    out.fill(DVec3::ZERO);
    for (tet, r) in tets.iter().zip(rest) {
        let xs = tet.map(|n| x[n as usize]);
        let f = r.gradient(&xs);
        let g = f * r.control_normals();
        let fs = [-(g.x_axis + g.y_axis + g.z_axis), g.x_axis, g.y_axis, g.z_axis];
        for c in 0..4 { out[tet[c] as usize] += fs[c]; }
    }
}
#[allow(dead_code)]
pub fn direct_kernel(tets: &[[u32;4]], rest: &[TetRest], x: &[DVec3], v: &[DVec3], out: &mut [DVec3]) {
    out.fill(DVec3::ZERO);
    for (tet, r) in tets.iter().zip(rest) {
        let xs = tet.map(|n| x[n as usize]);
        let vs = tet.map(|n| v[n as usize]);
        let fs = rapier_fvm::fvm::tet_forces(&Null, None, r, &xs, &vs);
        for c in 0..4 { out[tet[c] as usize] += fs[c]; }
    }
}

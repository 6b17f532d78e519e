//! scratch
use rapier_fvm::prelude::*;
fn main() -> Result<(), Error> {
    let mesh = mesh::cuboid(DVec3::splat(0.2), [40, 40, 40])?;
    let mat = Material::new(MaterialModel::StVenantKirchhoff, 1e6, 0.3, 1000.0)?;
    let d = RayleighDamping::stiffness_proportional(1e-3, mat.lame())?;
    let mut body = SoftBodyBuilder::new(mesh, mat).damping(d).build()?;
    for x in body.positions_mut() {
        *x *= 1.01;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        let n = body.mesh().tet_count() as f64;
        for _ in 0..3 {
            let t = std::time::Instant::now();
            for _ in 0..50 {
                std::hint::black_box(body.internal_forces()[0]);
            }
            println!("{:.1} ns/tet", t.elapsed().as_nanos() as f64 / 50.0 / n);
        }
    });
    Ok(())
}

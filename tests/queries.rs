//! Ray casts and point projections against deformable surfaces, compared with the closed-form
//! answers for a cube: the queries run in rapier's f32, so positions agree to 1e-5 m (f32's
//! resolution at 1 m is 6e-8 m; the margin covers the products of a few operations).

use rapier_fvm::prelude::*;

const TOLERANCE: f64 = 1e-5;

/// A 0.2 m cube centred at `centre` (m).
fn cube(centre: DVec3) -> Result<DeformableBody, Error> {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0)?;
    DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.1), [3, 3, 3])?, rubber)
        .translation(centre)
        .build()
}

#[test]
fn a_ray_hits_the_top_face_of_a_cube_with_its_outward_normal() -> Result<(), Error> {
    let body = cube(DVec3::ZERO)?;
    let origin = DVec3::new(0.03, 1.0, 0.02);
    let hit = body
        .cast_ray(origin, DVec3::NEG_Y, 10.0)
        .expect("the ray crosses the cube");
    assert!((hit.time_of_impact - 0.9).abs() < TOLERANCE, "{hit:?}");
    assert!(
        (hit.point - DVec3::new(0.03, 0.1, 0.02)).length() < TOLERANCE,
        "{hit:?}"
    );
    assert!((hit.normal - DVec3::Y).length() < TOLERANCE, "{hit:?}");
    let [a, b, c] = body.surface_triangles()[hit.triangle].map(|n| body.positions()[n as usize]);
    assert!(
        a.y.min(b.y).min(c.y) > 0.1 - TOLERANCE,
        "the triangle hit lies on the top face"
    );
    // Beyond its reach, or beside the cube, the ray misses.
    assert!(body.cast_ray(origin, DVec3::NEG_Y, 0.5).is_none());
    assert!(
        body.cast_ray(DVec3::new(0.5, 1.0, 0.0), DVec3::NEG_Y, 10.0)
            .is_none()
    );
    Ok(())
}

#[test]
fn queries_follow_the_nodes_where_they_are_now() -> Result<(), Error> {
    let mut body = cube(DVec3::ZERO)?;
    for x in body.positions_mut() {
        x.y += 0.2;
    }
    let hit = body
        .cast_ray(DVec3::new(0.0, 1.0, 0.0), DVec3::NEG_Y, 10.0)
        .expect("the ray crosses the moved cube");
    assert!((hit.time_of_impact - 0.7).abs() < TOLERANCE, "{hit:?}");
    let projection = body
        .project_point(DVec3::new(0.05, -0.5, -0.04))
        .expect("the cube has a surface");
    assert!((projection.point - DVec3::new(0.05, 0.1, -0.04)).length() < TOLERANCE);
    assert!((projection.distance - 0.6).abs() < TOLERANCE);
    Ok(())
}

#[test]
fn a_set_answers_with_the_nearest_body() -> Result<(), Error> {
    let mut set = DeformableBodySet::new();
    let near = set.insert(cube(DVec3::new(0.0, 0.5, 0.0))?);
    let far = set.insert(cube(DVec3::new(0.0, -0.5, 0.0))?);
    let (handle, hit) = set
        .cast_ray(DVec3::new(0.0, 2.0, 0.0), DVec3::NEG_Y, 10.0)
        .expect("the ray crosses both cubes");
    assert_eq!(handle, near);
    assert!((hit.time_of_impact - 1.4).abs() < TOLERANCE, "{hit:?}");
    // From below, the lower cube is hit first.
    let (handle, _) = set
        .cast_ray(DVec3::new(0.0, -2.0, 0.0), DVec3::Y, 10.0)
        .expect("the ray crosses both cubes");
    assert_eq!(handle, far);
    let (handle, projection) = set.project_point(DVec3::new(0.0, -1.0, 0.0)).unwrap();
    assert_eq!(handle, far);
    assert!((projection.distance - 0.4).abs() < TOLERANCE);
    Ok(())
}

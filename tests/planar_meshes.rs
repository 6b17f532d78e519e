//! The 2D mesh generators: the polygon outline meshed by a refined constrained Delaunay
//! triangulation (areas exact, element size and quality as asked, bad outlines refused with
//! typed errors), and a patch test on such a mesh, which nobody on the team laid out.

use rapier_fvm::Error;
use rapier_fvm::glamx::{DMat2, DVec2};
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::planar::{PlanarBodyBuilder, PlaneModel, TriangleMesh, solve_planar_equilibrium};
use rapier_fvm::statics::StaticSettings;

fn points(xy: &[(f64, f64)]) -> Vec<DVec2> {
    xy.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

/// The L-shaped bracket's outline, counterclockwise.
fn bracket() -> Vec<DVec2> {
    points(&[
        (0.0, 0.0),
        (1.0, 0.0),
        (1.0, 0.4),
        (0.4, 0.4),
        (0.4, 1.0),
        (0.0, 1.0),
    ])
}

/// The smallest angle (degrees) of the triangle `a b c`.
fn smallest_angle(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let angle = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs().to_degrees();
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// The mesh covers the outline exactly (area to 1e-12), in either orientation; no triangle is
/// larger than the equilateral one of the edge length asked for, and none has an angle below
/// 20° (the refinement aims at 25°; the bracket's corners are 90° and 270°).
#[test]
fn a_polygon_is_meshed_to_the_size_and_quality_asked() {
    for outline in [bracket(), bracket().into_iter().rev().collect()] {
        let mesh = TriangleMesh::polygon(&outline, 0.05).unwrap();
        assert!((mesh.area() - 0.64).abs() < 1e-12, "area {}", mesh.area());
        let target = 3f64.sqrt() / 4.0 * 0.05 * 0.05;
        let mut worst_angle = f64::MAX;
        for t in 0..mesh.triangles().len() {
            let [a, b, c] = mesh.corners(t);
            let area = 0.5 * (b - a).perp_dot(c - a);
            assert!(
                area > 0.0 && area <= target * (1.0 + 1e-9),
                "triangle {t}: area {area}"
            );
            worst_angle = worst_angle.min(smallest_angle(a, b, c));
        }
        println!(
            "{} triangles, smallest angle {worst_angle:.1}°",
            mesh.triangles().len()
        );
        assert!(worst_angle >= 20.0, "smallest angle {worst_angle}°");
    }
}

/// Bad outlines are typed errors naming what is wrong, never a panic of the triangulator: too
/// few vertices, crossing edges, a repeated vertex, edges folding back onto each other (a
/// degenerate spike, also the collinear triangle), a non-finite coordinate.
#[test]
fn bad_outlines_are_typed_errors() {
    let cases = [
        (points(&[(0.0, 0.0), (1.0, 0.0)]), "outline"),
        (
            points(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]),
            "outline edge",
        ),
        (
            points(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]),
            "outline edge",
        ),
        (
            points(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]),
            "outline vertex",
        ),
        (
            points(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (1.0, 0.5)]),
            "outline vertex",
        ),
        (
            points(&[(0.0, 0.0), (f64::NAN, 0.0), (0.0, 1.0)]),
            "outline vertex",
        ),
        (
            points(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)]),
            "outline vertex",
        ),
    ];
    for (outline, named) in cases {
        match TriangleMesh::polygon(&outline, 0.1) {
            Err(Error::InvalidGeneratorParameter { parameter, .. }) => {
                assert_eq!(parameter, named, "{outline:?}")
            }
            other => panic!("{outline:?}: {other:?}"),
        }
    }
    let bad_size = TriangleMesh::polygon(&bracket(), -1.0);
    assert!(matches!(
        bad_size,
        Err(Error::InvalidGeneratorParameter {
            parameter: "edge_length",
            ..
        })
    ));
    let too_fine = TriangleMesh::polygon(&bracket(), 1e-6);
    assert!(matches!(
        too_fine,
        Err(Error::InvalidGeneratorParameter {
            parameter: "edge_length",
            ..
        })
    ));
}

/// The patch test on the bracket's triangulation: its outline moved by an affine map, every
/// interior node follows it, to 1e-9 of the element size (every model, both planes).
#[test]
fn the_patch_test_holds_on_a_triangulated_polygon() {
    let mesh = TriangleMesh::polygon(&bracket(), 0.1).unwrap();
    let a = DMat2::from_cols(DVec2::new(1.05, -0.04), DVec2::new(0.02, 0.97));
    let c = DVec2::new(-0.3, 0.2);
    let outline = bracket();
    let on_outline = |p: DVec2| {
        (0..outline.len()).any(|i| {
            let (u, v) = (outline[i], outline[(i + 1) % outline.len()]);
            let t = ((p - u).dot(v - u) / (v - u).length_squared()).clamp(0.0, 1.0);
            p.distance(u + (v - u) * t) < 1e-12
        })
    };
    for model in [MaterialModel::Linear, MaterialModel::StableNeoHookean] {
        for plane in [PlaneModel::PlaneStress, PlaneModel::PlaneStrain] {
            let material = Material::new(model, 1e6, 0.3, 1000.0).unwrap();
            let mut body = PlanarBodyBuilder::new(mesh.clone(), material)
                .plane(plane)
                .build()
                .unwrap();
            let rest = body.rest_positions().to_vec();
            for (i, p) in rest.iter().enumerate() {
                // Interior nodes start a millimetre off the map, in a fixed pattern.
                let off = DVec2::new((i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()) * 1e-3;
                if on_outline(*p) {
                    body.pin(i, [true, true]).unwrap();
                    body.positions_mut()[i] = a * *p + c;
                } else {
                    body.positions_mut()[i] = a * *p + c + off;
                }
            }
            let loads = vec![DVec2::ZERO; rest.len()];
            let settings = StaticSettings {
                tolerance: 1e-12,
                max_iterations: 50,
            };
            solve_planar_equilibrium(&mut body, &loads, &settings).unwrap();
            let worst = (body.positions().iter().zip(&rest))
                .map(|(x, p)| x.distance(a * *p + c))
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-10,
                "{model:?} {plane:?}: {worst:e} m off the affine map"
            );
        }
    }
}

/// The area of the polygon `outline` (m², either orientation).
fn shoelace(outline: &[DVec2]) -> f64 {
    let n = outline.len();
    ((0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<f64>()
        / 2.0)
        .abs()
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]

    /// Random outlines, most of them crossing themselves, some repeating or lining up vertices
    /// (coordinates on a coarse grid; about a quarter are simple polygons): the generator never
    /// panics (the triangulator's constraint insertion would on crossing edges), and every mesh
    /// it returns covers the outline's area to 1e-9 and passes the mesh checks (it was built by
    /// `TriangleMesh::new`).
    #[test]
    fn random_outlines_give_a_mesh_or_a_typed_error(
        grid in proptest::collection::vec((0i32..6, 0i32..6), 3..9),
    ) {
        let outline: Vec<DVec2> = grid.iter().map(|&(x, y)| DVec2::new(f64::from(x), f64::from(y)) * 0.1).collect();
        match TriangleMesh::polygon(&outline, 0.1) {
            Ok(mesh) => {
                let area = shoelace(&outline);
                proptest::prop_assert!((mesh.area() - area).abs() < 1e-9 * area.max(1.0), "{} against {}", mesh.area(), area);
            }
            Err(Error::InvalidGeneratorParameter { .. }) => {}
            Err(other) => proptest::prop_assert!(false, "{other:?}"),
        }
    }
}

/// A generator asked for more than ten million triangles refuses with a typed error naming
/// what sets the count, before allocating anything (16 384 × 16 384 cells would be 537 million
/// triangles, about half a terabyte once built).
#[test]
fn generators_refuse_more_than_ten_million_triangles() {
    for mesh in [
        TriangleMesh::rectangle(DVec2::ONE, [16384, 16384]),
        TriangleMesh::disk(1.0, 16384),
    ] {
        match mesh {
            Err(Error::InvalidGeneratorParameter { reason, .. }) => {
                assert!(reason.contains("ten million"), "{reason}");
            }
            other => panic!(
                "expected a refusal, got {:?}",
                other.map(|m| m.triangles().len())
            ),
        }
    }
    // At the limit's scale but below it: 2 × 2 000 × 2 000 = 8 million triangles are made.
    assert!(TriangleMesh::rectangle(DVec2::ONE, [2000, 2000]).is_ok());
}

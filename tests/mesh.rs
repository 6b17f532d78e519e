//! Mesh validation, surface extraction, generators and mass lumping.

mod common;

use rapier_fvm::prelude::*;
use std::collections::HashSet;

fn unit_tet() -> Vec<DVec3> {
    vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
}

#[test]
fn empty_mesh_is_rejected() {
    assert_eq!(
        TetMesh::new(vec![], vec![]),
        Err(Error::EmptyMesh { nodes: 0, tets: 0 })
    );
    assert_eq!(
        TetMesh::new(unit_tet(), vec![]),
        Err(Error::EmptyMesh { nodes: 4, tets: 0 })
    );
}

#[test]
fn out_of_range_index_names_the_tet_and_node() {
    let err = TetMesh::new(unit_tet(), vec![[0, 1, 2, 3], [0, 1, 2, 9]]).unwrap_err();
    assert_eq!(
        err,
        Error::NodeIndexOutOfRange {
            tet: 1,
            node: 9,
            node_count: 4
        }
    );
    assert!(err.to_string().contains("tetrahedron 1"));
}

#[test]
fn repeated_node_is_rejected() {
    let err = TetMesh::new(unit_tet(), vec![[0, 1, 1, 3]]).unwrap_err();
    assert_eq!(err, Error::RepeatedNode { tet: 0, node: 1 });
}

#[test]
fn non_finite_coordinate_names_the_node() {
    let mut positions = unit_tet();
    positions[2].y = f64::NAN;
    let err = TetMesh::new(positions, vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(matches!(err, Error::NonFiniteCoordinate { node: 2, .. }));
    let mut positions = unit_tet();
    positions[3].z = f64::INFINITY;
    let err = TetMesh::new(positions, vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(matches!(err, Error::NonFiniteCoordinate { node: 3, .. }));
}

#[test]
fn flat_tet_is_degenerate() {
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
    let err = TetMesh::new(positions.clone(), vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(matches!(err, Error::DegenerateTet { tet: 0, .. }));
    // Reorientation cannot fix a flat element either.
    let err = TetMesh::new_reoriented(positions, vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(matches!(err, Error::DegenerateTet { tet: 0, .. }));
}

#[test]
fn inverted_tet_is_reported_and_can_be_reoriented() {
    let tets = vec![[0, 1, 2, 3], [0, 2, 1, 3]];
    let err = TetMesh::new(unit_tet(), tets.clone()).unwrap_err();
    match err {
        Error::InvertedTet { tet, volume } => {
            assert_eq!(tet, 1);
            assert!((volume + 1.0 / 6.0).abs() < 1e-15);
        }
        other => panic!("expected InvertedTet, got {other:?}"),
    }
    let (mesh, flipped) = TetMesh::new_reoriented(unit_tet(), tets).unwrap();
    assert_eq!(flipped, 1);
    assert!((mesh.tet_volume(1) - 1.0 / 6.0).abs() < 1e-15);
}

#[test]
fn surface_of_a_box_is_closed_outward_and_has_the_box_area() {
    let half = DVec3::new(0.3, 0.2, 0.1);
    let mesh = mesh::cuboid(half, [3, 4, 2]).unwrap();
    let surface = mesh.surface_triangles();
    // Two triangles per boundary cell face.
    assert_eq!(surface.len(), 2 * 2 * (3 * 4 + 4 * 2 + 3 * 2));
    let p = mesh.positions();
    let mut area = 0.0;
    let mut divergence_volume = 0.0;
    for tri in &surface {
        let [a, b, c] = tri.map(|i| p[i as usize]);
        let doubled_normal = (b - a).cross(c - a);
        area += 0.5 * doubled_normal.length();
        // Outward: the face normal points away from the box centre.
        assert!(doubled_normal.dot((a + b + c) / 3.0) > 0.0);
        divergence_volume += doubled_normal.dot(a) / 6.0;
    }
    let expected_area = 8.0 * (half.x * half.y + half.y * half.z + half.x * half.z);
    assert!((area - expected_area).abs() < 1e-12 * expected_area);
    // Divergence theorem: the closed, outward surface encloses the mesh volume.
    assert!((divergence_volume - mesh.volume()).abs() < 1e-12 * mesh.volume());
}

#[test]
fn box_split_has_no_directional_bias() {
    // With an even number of cells, mirroring the box in any axis maps the mesh onto itself.
    let mesh = mesh::cuboid(DVec3::ONE, [4, 4, 4]).unwrap();
    let p = mesh.positions();
    let as_set = |tets: Vec<[u32; 4]>| -> HashSet<[u32; 4]> {
        tets.into_iter()
            .map(|mut t| {
                t.sort_unstable();
                t
            })
            .collect()
    };
    let original = as_set(mesh.tets().to_vec());
    for axis in 0..3 {
        let mirrored = mesh
            .tets()
            .iter()
            .map(|t| {
                t.map(|n| {
                    let mut q = p[n as usize];
                    q[axis] = -q[axis];
                    mesh.nearest_node(q)
                })
            })
            .collect();
        assert_eq!(as_set(mirrored), original, "mirror in axis {axis}");
    }
}

#[test]
fn cylinder_volume_converges_and_elements_are_well_shaped() {
    let (radius, half_height) = (0.1, 0.25);
    let exact = std::f64::consts::PI * radius * radius * 2.0 * half_height;
    let mut previous_error = f64::INFINITY;
    for cells in [4, 8, 16] {
        // Axial cells as long as the cross-section's, so the elements stay near-cubic.
        let mesh = mesh::cylinder(radius, half_height, cells, cells * 5 / 2).unwrap();
        let error = (mesh.volume() - exact).abs() / exact;
        let shape = mesh.worst_tet().1;
        println!(
            "cylinder {cells} cells across: volume error {error:.2e}, worst altitude/edge {shape:.3}"
        );
        // The inscribed boundary polygon's deficit falls as (cells)^-2: at least 3x per doubling.
        assert!(error < previous_error / 3.0);
        assert!(shape > 0.1, "elements must stay well shaped");
        previous_error = error;
    }
    assert!(previous_error < 0.01);
}

#[test]
fn sphere_volume_converges_and_elements_are_well_shaped() {
    let radius: f64 = 0.2;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let mut previous_error = f64::INFINITY;
    for cells in [5, 10, 20] {
        let mesh = mesh::sphere(radius, cells).unwrap();
        let error = (mesh.volume() - exact).abs() / exact;
        let shape = mesh.worst_tet().1;
        println!(
            "sphere {cells} cells across: volume error {error:.2e}, worst altitude/edge {shape:.3}"
        );
        // The inscribed faceted boundary's deficit falls as (cells)^-2: at least 3x per doubling.
        assert!(error < previous_error / 3.0);
        assert!(shape > 0.1, "elements must stay well shaped");
        previous_error = error;
    }
    assert!(previous_error < 0.04);
}

#[test]
fn generators_reject_bad_parameters() {
    assert!(matches!(
        mesh::cuboid(DVec3::ONE, [2, 0, 2]),
        Err(Error::InvalidGeneratorParameter {
            parameter: "cells",
            ..
        })
    ));
    assert!(matches!(
        mesh::cuboid(DVec3::new(1.0, -1.0, 1.0), [2, 2, 2]),
        Err(Error::InvalidGeneratorParameter {
            parameter: "half_extents.y",
            ..
        })
    ));
    assert!(matches!(
        mesh::cylinder(f64::NAN, 1.0, 4, 4),
        Err(Error::InvalidGeneratorParameter {
            parameter: "radius",
            ..
        })
    ));
    assert!(matches!(
        mesh::sphere(1.0, 1),
        Err(Error::InvalidGeneratorParameter {
            parameter: "cells_across",
            ..
        })
    ));
}

#[test]
fn lumped_masses_sum_to_density_times_volume() {
    let density = 1234.5;
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, density).unwrap();
    for mesh in [
        mesh::cuboid(DVec3::new(0.5, 0.05, 0.07), [10, 2, 3]).unwrap(),
        mesh::cylinder(0.1, 0.3, 6, 4).unwrap(),
        mesh::sphere(0.25, 6).unwrap(),
    ] {
        let volume = mesh.volume();
        let body = DeformableBodyBuilder::new(mesh, material).build().unwrap();
        let total = body.total_mass();
        assert!(
            (total - density * volume).abs() <= 1e-12 * total,
            "total {total} vs {}",
            density * volume
        );
        assert!(body.masses().iter().all(|&m| m > 0.0));
    }
}

#[test]
fn each_node_of_a_single_tet_gets_a_quarter_of_its_mass() {
    let mesh = TetMesh::new(unit_tet(), vec![[0, 1, 2, 3]]).unwrap();
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 600.0).unwrap();
    let body = DeformableBodyBuilder::new(mesh, material).build().unwrap();
    for &m in body.masses() {
        assert!((m - 600.0 / 6.0 / 4.0).abs() < 1e-12);
    }
}

#[test]
fn builder_rejects_missing_pinned_node_and_non_finite_placement() {
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    let mesh = mesh::cuboid(DVec3::ONE, [1, 1, 1]).unwrap();
    let err = DeformableBodyBuilder::new(mesh.clone(), material)
        .pinned_nodes([3, 8])
        .build()
        .unwrap_err();
    assert_eq!(
        err,
        Error::NodeOutOfRange {
            node: 8,
            node_count: 8
        }
    );
    let err = DeformableBodyBuilder::new(mesh, material)
        .translation(DVec3::new(0.0, f64::NAN, 0.0))
        .build()
        .unwrap_err();
    assert_eq!(
        err,
        Error::NonFiniteInput {
            parameter: "translation"
        }
    );
}

#[test]
fn unreferenced_node_is_rejected() {
    let mut positions = unit_tet();
    positions.push(DVec3::ONE);
    assert_eq!(
        TetMesh::new(positions, vec![[0, 1, 2, 3]]),
        Err(Error::UnreferencedNode { node: 4 })
    );
}

/// Checks that the boundary of `mesh` is closed (every edge shared by exactly two boundary
/// triangles, in opposite directions) and encloses the mesh volume (divergence theorem, 1e-12).
fn assert_closed_outward_surface(mesh: &TetMesh) {
    let surface = mesh.surface_triangles();
    let mut directed_edges = std::collections::HashMap::new();
    for tri in &surface {
        for k in 0..3 {
            *directed_edges
                .entry((tri[k], tri[(k + 1) % 3]))
                .or_insert(0) += 1;
        }
    }
    for (&(a, b), &count) in &directed_edges {
        assert_eq!(count, 1, "edge {a}-{b} used twice in the same direction");
        assert_eq!(
            directed_edges.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} is on a crack"
        );
    }
    let p = mesh.positions();
    let enclosed: f64 = surface
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            (b - a).cross(c - a).dot(a) / 6.0
        })
        .sum();
    assert!((enclosed - mesh.volume()).abs() < 1e-12 * mesh.volume());
}

#[test]
fn round_shapes_have_closed_outward_surfaces() {
    // A missed merge of the blocks' shared nodes would open a crack inside the body, which the
    // volume checks cannot see.
    for cells in [2, 3, 8] {
        assert_closed_outward_surface(&mesh::cylinder(0.1, 0.2, cells, 3).unwrap());
        assert_closed_outward_surface(&mesh::sphere(0.1, cells).unwrap());
    }
    assert_closed_outward_surface(&mesh::cuboid(DVec3::new(0.3, 0.2, 0.1), [3, 4, 2]).unwrap());
}

#[test]
fn slivers_are_refused_before_stepping() {
    // A tetrahedron 1e-5 high on a unit base: valid, but 1e-5 thin.
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 1e-5)];
    let mesh = TetMesh::new(positions, vec![[0, 1, 2, 3]]).unwrap();
    let (tet, quality) = mesh.worst_tet();
    assert!(tet == 0 && quality < 1e-4);
    let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
    match DeformableBodyBuilder::new(mesh.clone(), material).build() {
        Err(Error::SliverTet {
            tet: 0, threshold, ..
        }) => {
            assert_eq!(threshold, rapier_fvm::body::DEFAULT_MIN_ELEMENT_QUALITY)
        }
        other => panic!("expected a sliver error, got {other:?}"),
    }
    // The threshold is the user's to lower.
    assert!(
        DeformableBodyBuilder::new(mesh, material)
            .min_element_quality(0.0)
            .build()
            .is_ok()
    );
    // A regular tetrahedron has quality sqrt(2/3).
    let s = 1.0 / 2f64.sqrt();
    let regular = TetMesh::new_reoriented(
        vec![
            DVec3::new(s, 0.0, -0.5),
            DVec3::new(-s, 0.0, -0.5),
            DVec3::new(0.0, s, 0.5),
            DVec3::new(0.0, -s, 0.5),
        ],
        vec![[0, 1, 2, 3]],
    )
    .unwrap()
    .0;
    assert!((regular.tet_quality(0) - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
}

//! Each writer on a small scene, its output read back: the ParaView series through vtkio, the OBJ
//! by counting its records, the pictures by decoding the PNG.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm_runner::output::{
    Camera, Coloring, ParaViewSeries, RigidBodySnapshot, Snapshot, SoftBodySnapshot, TimeSeries,
    plot_series, render_png, write_obj,
};
use rapier3d::pipeline::PhysicsWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};
use std::path::PathBuf;
use vtkio::model::{Attribute, DataSet, Vtk};

/// A fresh folder for one test's files.
fn folder(test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 2 x 2 x 2-cell soft cube (27 nodes, 40 tets: five per cell) squashed and moving at time `time`, above a
/// ground half-space, beside a rigid ball.
fn scene(time: f64) -> Snapshot {
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    let mut body =
        DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [2, 2, 2]).unwrap(), rubber)
            .translation(DVec3::new(0.0, 0.1, 0.0))
            .build()
            .unwrap();
    let rest = body.positions().to_vec();
    let squash = 1.0 - 0.1 * time;
    for (x, p) in body.positions_mut().iter_mut().zip(&rest) {
        *x = DVec3::new(p.x * (1.0 + 0.03 * time), p.y * squash, p.z);
    }
    for (v, p) in body.velocities_mut().iter_mut().zip(&rest) {
        *v = DVec3::new(0.0, -1.0, 0.0) + *p;
    }
    let mut physics = PhysicsWorld::default();
    physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).build(),
        None,
    );
    physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(-0.12, 0.05, 0.0)),
        ColliderBuilder::ball(0.04),
    );
    Snapshot {
        time,
        soft_bodies: vec![SoftBodySnapshot::capture(
            "soft cube",
            "rubber",
            &body,
            &rest,
        )],
        rigid_bodies: RigidBodySnapshot::all_of(&physics, 0.2),
    }
}

/// The values of the data array `name` among `attributes`.
fn array(attributes: &[Attribute], name: &str) -> Vec<f64> {
    attributes
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == name => d.data.cast_into::<f64>(),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no array {name}"))
}

#[test]
fn paraview_series_reads_back_with_the_snapshot_values() {
    let dir = folder("paraview");
    let mut series = ParaViewSeries::new(&dir, "drop").unwrap();
    let frames = [scene(0.0), scene(0.5)];
    for frame in &frames {
        series.write_frame(frame).unwrap();
    }
    let pvd = std::fs::read_to_string(series.pvd_path()).unwrap();
    assert_eq!(pvd.matches("<DataSet ").count(), 2);
    assert!(pvd.contains("timestep=\"0.5\" part=\"0\" file=\"soft_cube_00001.vtu\""));

    let snapshot = &frames[1].soft_bodies[0];
    let vtk = Vtk::import(dir.join("soft_cube_00001.vtu")).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    let piece = pieces[0].load_piece_data(None).unwrap();
    assert_eq!(piece.num_points(), 27);
    assert_eq!(piece.cells.num_cells(), 40);
    let flat = |v: &[DVec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>();
    assert_eq!(
        piece.points.cast_into::<f64>().unwrap(),
        flat(&snapshot.positions)
    );
    // Binary data: the values come back bit for bit.
    assert_eq!(
        array(&piece.data.point, "displacement"),
        flat(&snapshot.displacements())
    );
    assert_eq!(
        array(&piece.data.point, "velocity"),
        flat(&snapshot.velocities)
    );
    assert_eq!(array(&piece.data.cell, "von_mises"), snapshot.von_mises());
    let stress = array(&piece.data.cell, "cauchy_stress");
    assert_eq!(stress.len(), 9 * 40);
    let sigma = snapshot.cauchy_stress[7];
    assert_eq!(stress[9 * 7 + 1], sigma.y_axis.x); // σ_xy, row-major
    assert!(snapshot.von_mises().iter().all(|s| *s > 0.0));
}

#[test]
fn obj_has_one_object_per_body_and_the_surface_counts() {
    let dir = folder("obj");
    let snapshot = scene(0.5);
    let path = dir.join("surface.obj");
    write_obj(&path, &snapshot).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("o "), 3, "soft cube, ball, ground");
    // A 2 x 2 x 2-cell cube: 26 nodes on its surface, 6 faces x 4 squares x 2 triangles.
    let rigid_vertices: usize = snapshot.rigid_bodies.iter().map(|b| b.vertices.len()).sum();
    let rigid_faces: usize = snapshot
        .rigid_bodies
        .iter()
        .map(|b| b.triangles.len())
        .sum();
    assert_eq!(count("v "), 26 + rigid_vertices);
    assert_eq!(count("f "), 48 + rigid_faces);
    assert_eq!(
        snapshot.rigid_bodies[1].triangles.len(),
        2,
        "the ground is one square patch"
    );
    let largest_index = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .flat_map(|l| l[2..].split(' ').map(|i| i.parse::<usize>().unwrap()))
        .max();
    assert_eq!(largest_index, Some(count("v ")));
}

/// Decodes a PNG into its size and RGB(A) bytes.
fn decode(path: &std::path::Path) -> (u32, u32, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    pixels.truncate(info.buffer_size());
    (info.width, info.height, info.color_type.samples(), pixels)
}

#[test]
fn rendered_view_shows_the_bodies_on_the_background() {
    let dir = folder("render");
    let snapshot = scene(0.5);
    let (min, max) = snapshot.bounds().unwrap();
    let camera = Camera::oblique(min, max, 320, 240);
    for (file, coloring) in [
        ("material.png", Coloring::Material),
        ("stress.png", Coloring::VonMises { max: 1e4 }),
    ] {
        let path = dir.join(file);
        render_png(&path, &snapshot, &camera, coloring).unwrap();
        let (width, height, samples, pixels) = decode(&path);
        assert_eq!((width, height), (320, 240));
        // The pixel at the projected centre of the soft cube is not the background.
        let centre = snapshot.soft_bodies[0].positions.iter().sum::<DVec3>() / 27.0;
        let p = camera.project(centre);
        let i = samples * (p.y as usize * width as usize + p.x as usize);
        assert_ne!(&pixels[i..i + 3], &[250, 250, 250], "{file}");
        let background = pixels
            .chunks(samples)
            .filter(|c| c[..3] == [250, 250, 250])
            .count();
        let share = background as f64 / f64::from(width * height);
        assert!((0.2..0.95).contains(&share), "{file}: background {share}");
    }
}

#[test]
fn plot_is_a_png_of_the_requested_size_with_a_drawn_line() {
    let dir = folder("plot");
    let series = TimeSeries {
        name: String::from("tip displacement"),
        unit: String::from("m"),
        samples: (0..100)
            .map(|i| (f64::from(i) * 0.01, (f64::from(i) * 0.1).sin()))
            .collect(),
    };
    let path = dir.join("plot.png");
    plot_series(&path, &series, (640, 400)).unwrap();
    let (width, height, samples, pixels) = decode(&path);
    assert_eq!((width, height), (640, 400));
    // The line is pure blue; the background white.
    let blue = pixels
        .chunks(samples)
        .filter(|c| c[..3] == [0, 0, 255])
        .count();
    assert!(blue > 500, "{blue} blue pixels");
}

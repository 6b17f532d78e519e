//! A soft rubber cube (10 cm, E = 1e5 Pa, ν = 0.3, damped) and a rigid box dropped onto a ground
//! in an [`FvmWorld`], stepped for 1 s at 60 frames per second, with every writer of the runner's
//! output: a ParaView series, OBJ surfaces, rendered pictures and a plot, in `out/render_drop/`.
//!
//! Run with `cargo run --release -p rapier_fvm_runner --example render_drop`.

use rapier_fvm::glamx::Vec3;
use rapier_fvm::prelude::*;
use rapier_fvm::world::FvmWorld;
use rapier_fvm_runner::output::{
    Camera, Coloring, ParaViewSeries, RigidBodySnapshot, Snapshot, SoftBodySnapshot, TimeSeries,
    plot_series, render_png, write_obj,
};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};
use std::error::Error;
use std::path::Path;

const FRAMES: usize = 60;
/// Every how many frames the series and surfaces are saved.
const SAVE_EVERY: usize = 3;
/// Half size of the drawn ground patch (m).
const GROUND_PATCH: f64 = 0.25;

fn main() -> Result<(), Box<dyn Error>> {
    let out = Path::new("out/render_drop");
    let mut world = FvmWorld::default();
    world.physics.insert_collider(
        ColliderBuilder::new(SharedShape::halfspace(Vec3::Y)).friction(0.5),
        None,
    );
    world.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vec3::new(-0.15, 0.2, 0.05)),
        ColliderBuilder::cuboid(0.03, 0.03, 0.03).density(500.0),
    );
    let rubber = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
    let cube = DeformableBodyBuilder::new(mesh::cuboid(DVec3::splat(0.05), [6, 6, 6])?, rubber)
        .damping(RayleighDamping::stiffness_proportional(
            2e-3,
            rubber.lame(),
        )?)
        .translation(DVec3::new(0.0, 0.3, 0.0))
        .rotation(DVec3::new(0.3, 0.0, 0.2))
        .build()?;
    let rest = cube.positions().to_vec();
    let handle = world.soft_bodies.insert(cube);

    let capture = |world: &FvmWorld, time: f64| Snapshot {
        time,
        soft_bodies: vec![SoftBodySnapshot::capture(
            "cube",
            "rubber",
            &world.soft_bodies[handle],
            &rest,
        )],
        rigid_bodies: RigidBodySnapshot::all_of(&world.physics, GROUND_PATCH),
    };
    let mut saved = vec![capture(&world, 0.0)];
    let mut height = TimeSeries {
        name: String::from("cube centre height"),
        unit: String::from("m"),
        samples: vec![(0.0, world.soft_bodies[handle].center_of_mass().y)],
    };
    for frame in 1..=FRAMES {
        for (_, outcome) in world.step() {
            outcome?;
        }
        let time = frame as f64 / 60.0;
        height
            .samples
            .push((time, world.soft_bodies[handle].center_of_mass().y));
        if frame % SAVE_EVERY == 0 {
            saved.push(capture(&world, time));
        }
    }

    write_series(out, &saved)?;
    let max_stress = write_pictures(out, &saved)?;
    plot_series(&out.join("cube_centre_height.png"), &height, (800, 500))?;
    println!(
        "{} frames saved to {} (colour scale to {:.0} Pa)",
        saved.len(),
        out.display(),
        max_stress
    );
    Ok(())
}

/// Writes the ParaView series and the OBJ surfaces of every saved frame, printing a table.
fn write_series(out: &Path, saved: &[Snapshot]) -> Result<(), Box<dyn Error>> {
    let mut series = ParaViewSeries::new(out, "render_drop")?;
    println!(
        "{:>6} {:>12} {:>16}",
        "t (s)", "centre (mm)", "von Mises (kPa)"
    );
    for (i, snapshot) in saved.iter().enumerate() {
        let body = &snapshot.soft_bodies[0];
        let centre = body.positions.iter().map(|x| x.y).sum::<f64>() / body.positions.len() as f64;
        let peak = peak_stress(snapshot);
        println!(
            "{:>6.2} {:>12.1} {:>16.2}",
            snapshot.time,
            centre * 1e3,
            peak * 1e-3
        );
        series.write_frame(snapshot)?;
        write_obj(&out.join(format!("surface_{i:05}.obj")), snapshot)?;
    }
    Ok(())
}

/// Renders a few saved frames coloured by material and by stress from one camera framing them
/// all; returns the top of the stress colour scale (Pa).
fn write_pictures(out: &Path, saved: &[Snapshot]) -> Result<f64, Box<dyn Error>> {
    let bounds = saved
        .iter()
        .filter_map(Snapshot::bounds)
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
    let (min, max) = bounds.ok_or("nothing to frame")?;
    let camera = Camera::oblique(min, max, 800, 600);
    // The colour scale ends at the largest 95th percentile of any frame, so that a few peak
    // nodes at a contact corner do not leave the rest of the body in the bottom colour.
    let max_stress = saved.iter().map(upper_stress).fold(1.0, f64::max);
    // The start, the most stressed frame, and a few instants between.
    let peak = (0..saved.len())
        .max_by(|&a, &b| peak_stress(&saved[a]).total_cmp(&peak_stress(&saved[b])))
        .unwrap_or(0);
    let mut instants = vec![0, saved.len() / 4, saved.len() / 2, peak, saved.len() - 1];
    instants.sort_unstable();
    instants.dedup();
    for i in instants {
        let snapshot = &saved[i];
        render_png(
            &out.join(format!("view_{i:05}.png")),
            snapshot,
            &camera,
            Coloring::Material,
        )?;
        let stress = Coloring::VonMises { max: max_stress };
        render_png(
            &out.join(format!("stress_{i:05}.png")),
            snapshot,
            &camera,
            stress,
        )?;
    }
    Ok(max_stress)
}

/// The largest nodal von Mises stress (Pa) of a snapshot's soft bodies.
fn peak_stress(snapshot: &Snapshot) -> f64 {
    snapshot
        .soft_bodies
        .iter()
        .flat_map(|b| b.nodal_von_mises())
        .fold(0.0, f64::max)
}

/// The 95th percentile of the nodal von Mises stresses (Pa) of a snapshot's soft bodies.
fn upper_stress(snapshot: &Snapshot) -> f64 {
    let mut values: Vec<f64> = snapshot
        .soft_bodies
        .iter()
        .flat_map(|b| b.nodal_von_mises())
        .collect();
    values.sort_by(f64::total_cmp);
    values.get(values.len() * 95 / 100).copied().unwrap_or(0.0)
}

//! What a body's motion asked of its model, in the report (`needs`): the peak rotation of a
//! spinning block against its spin, and the linear model's spurious stress at that rotation
//! against its closed form.

mod scenes;

use scenes::{run_scene, scene_path};

#[test]
fn a_spinning_blocks_peak_rotation_is_its_spin_angle() {
    // spinning_block.toml for 1 s: spun at ω = 3 rad/s about z, free, the block turns by
    // ω t = 171.9° (below 180°, so the angle grows to the last frame). The spin stretches it
    // (peak Green strain 0.56 %), which raises its moment of inertia by up to twice that and
    // slows the spin by as much as its angular momentum is kept: 1.2 % allowed. It touches
    // nothing.
    let text = std::fs::read_to_string(scene_path("spinning_block.toml")).unwrap();
    let (report, _) = run_scene("needs_spinning_block", &text, Some(1.0));
    let needs = &report.soft_bodies[0].needs;
    let spin = 3.0_f64.to_degrees();
    assert!(
        needs.peak_rotation_deg <= spin && needs.peak_rotation_deg > spin * (1.0 - 0.012),
        "{needs:?}"
    );
    assert!(
        needs.peak_green_strain > 1e-3 && needs.peak_green_strain < 6e-3,
        "{needs:?}"
    );
    assert_eq!(needs.contact_frames, 0);
    // The linear model's spurious von Mises stress over E at that rotation, (1 − cos θ)/(1 + ν)
    // with ν = 0.3, to round-off.
    let theta = needs.peak_rotation_deg.to_radians();
    let expected = (1.0 - theta.cos()) / 1.3;
    assert!((needs.linear_spurious_stress_over_e - expected).abs() < 1e-12 * expected);
}

#[test]
fn a_dropped_cube_touches_the_ground_from_its_landing_on() {
    // drop.toml: a 10 cm rubber cube whose bottom starts 0.5 m above the ground falls for
    // √(2h/g) = 0.319 s, landing in frame 20 of 90 at 60 Hz, and stays (its damping takes the
    // bounce): so the ground pushes it in the 71 frames from the 20th, or 72 when the last
    // substep of frame 19 (ending 2.6 mm above the ground at 3.1 m/s) already stops the nodes'
    // approach (a contact within reach stops a node at the surface in the substep it would
    // cross it), two fewer if it bounced off. Dropped flat and symmetric, it does not turn: its
    // elements rotate by the bulge of the impact alone, below 5°.
    let text = std::fs::read_to_string(scene_path("drop.toml")).unwrap();
    let (report, _) = run_scene("needs_drop", &text, None);
    let needs = &report.soft_bodies[0].needs;
    let landing = ((2.0 * 0.5 / 9.81_f64).sqrt() * 60.0).ceil() as usize;
    assert_eq!(landing, 20);
    let after = report.frames + 1 - landing;
    assert!(
        needs.contact_frames <= after + 1 && needs.contact_frames + 2 >= after,
        "{needs:?}"
    );
    assert!(needs.peak_rotation_deg < 5.0, "{needs:?}");
}

#[test]
fn a_beam_sagging_onto_a_rounded_support_is_pushed_from_its_landing_on() {
    // cage_beam.toml for 0.5 s (30 frames): the free end of a clamped beam sags onto a fixed
    // capsule 5 mm below it within its first frames and rests there; a capsule meets the beam's
    // faces by its closest points (rigid-corner contacts, not the surface points' own), which
    // count as much as the ground's contacts with a dropped cube's points. The frames before the
    // landing, at most two (5 mm of free fall take 32 ms), are the only ones not counted.
    let text = std::fs::read_to_string(scene_path("cage_beam.toml")).unwrap();
    let (report, _) = run_scene("needs_cage_beam", &text, Some(0.5));
    let needs = &report.soft_bodies[0].needs;
    assert_eq!(report.frames, 30);
    assert!(
        needs.contact_frames + 2 >= report.frames && needs.contact_frames <= report.frames,
        "{needs:?}"
    );
}

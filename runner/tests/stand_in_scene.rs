//! A scene's `rigid_stand_in`: a stiff brick tossed onto the ground stands in as a rigid body in
//! flight, turns elastic as it lands, and rests where the elastic brick rests.

mod scenes;

use scenes::{run_scene, scene_path};

/// `tossed_bricks.toml` with `rigid_stand_in = 1e-3` on every brick, or as written.
fn tossed(stand_in: bool) -> String {
    let text = std::fs::read_to_string(scene_path("tossed_bricks.toml")).unwrap();
    let label = "label = \"stiff plastic\" }\n";
    assert_eq!(text.matches(label).count(), 4);
    if stand_in {
        text.replace(label, &format!("{label}rigid_stand_in = 1e-3\n"))
    } else {
        text
    }
}

#[test]
fn tossed_bricks_stand_in_in_flight_and_rest_where_elastic_ones_do() {
    // 1.5 s: the bricks fly (the first frame elastic, then rigid), land (turning elastic just
    // before: the strike of the ground predicts v / c ≈ 3 / 367 ≈ 8e-3, above 1e-3) and come to
    // rest. Brick 3 rests flat, its centre at its half thickness, 3 cm: its height change is
    // −0.47 m as written; standing in it rests on rapier's contact, whose depth (below 0.1 mm,
    // rapier's allowed error 1 mm) is the tolerance. Both runs are clean in the audit.
    let (elastic, _) = run_scene("tossed_bricks", &tossed(false), Some(1.5));
    let (standing, _) = run_scene("tossed_bricks", &tossed(true), Some(1.5));
    for report in [&elastic, &standing] {
        assert!(report.stability.stable, "{:?}", report.stability);
    }
    for body in &standing.soft_bodies {
        assert!(body.rigid_frames > 0, "{} never stood in", body.name);
        assert!(
            body.rigid_frames < standing.frames,
            "{} never turned elastic",
            body.name
        );
    }
    assert!(elastic.soft_bodies.iter().all(|b| b.rigid_frames == 0));
    let height = |report: &rapier_fvm_runner::sim::Report| {
        let probe = report
            .probes
            .iter()
            .find(|p| p.name == "brick 3 height change")
            .unwrap();
        probe.final_value
    };
    assert!(
        (height(&elastic) + 0.47).abs() < 1e-4,
        "{}",
        height(&elastic)
    );
    assert!(
        (height(&standing) - height(&elastic)).abs() < 1e-4,
        "{}",
        height(&standing)
    );
}

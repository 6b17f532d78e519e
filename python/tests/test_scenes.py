"""Scene files from Python: the same trajectory as the runner's, overrides, a run's report."""

import numpy as np
import pytest

import rapier_fvm as rf


@pytest.mark.parametrize("name, duration", [("rigid_on_soft", 0.5), ("grasp", 0.4)])
def test_a_scene_stepped_from_python_follows_the_runners_run_to_the_bit(scenes, tmp_path,
                                                                        name, duration):
    path = scenes / f"{name}.toml"
    report = rf.run_scene(path, tmp_path / "out", duration=duration)
    world = rf.World.from_scene(path)
    world.step(report["frames"])
    probes = world.probes()
    assert len(report["probes"]) == len(probes) > 0
    for probe in report["probes"]:
        samples = probes[probe["name"]]
        np.testing.assert_array_equal(samples[:, 0], probe["times"])
        np.testing.assert_array_equal(samples[:, 1], probe["values"])
    assert (tmp_path / "out" / "report.json").is_file()


def test_overrides_change_the_scene_as_if_written_in_it(scenes, tmp_path):
    path = scenes / "rigid_on_soft.toml"
    text = path.read_text()
    stiffer = text.replace("young = 1e6", "young = 2e6")
    assert stiffer != text, "the scene's modulus moved: update the test"
    edited = tmp_path / "rigid_on_soft.toml"
    edited.write_text(stiffer)
    by_file = rf.World.from_scene(edited)
    by_override = rf.World.from_scene(path, {"soft_body[0].material.young": 2e6})
    by_file.step(20)
    by_override.step(20)
    block = by_file.soft_body("block")
    np.testing.assert_array_equal(by_file.positions(block), by_override.positions(block))
    with pytest.raises(ValueError, match="no element"):
        rf.World.from_scene(path, {"soft_body[7].material.young": 1.0})
    with pytest.raises(rf.SceneError, match="young"):
        rf.World.from_scene(path, {"soft_body[0].material.young": -1.0})


def test_a_2d_scene_runs_and_reports(scenes, tmp_path):
    report = rf.run_scene(scenes / "planar_drop.toml", tmp_path / "planar", duration=0.1)
    assert report["frames"] == 6 and report["final_state_finite"]


def test_a_pickled_scene_world_keeps_its_keyframes_and_probes(scenes):
    import pickle

    world = rf.World.from_scene(scenes / "grasp.toml")
    world.step(10)
    copy = pickle.loads(pickle.dumps(world))
    world.step(10)
    copy.step(10)
    for name, samples in world.probes().items():
        np.testing.assert_array_equal(copy.probes()[name], samples)
    assert copy.probes()["cube centre rise"].shape == (21, 2)  # frames 0 to 20


def test_a_state_of_another_scene_is_refused_and_a_later_one_brings_its_probes(scenes):
    drop = rf.World.from_scene(scenes / "drop.toml")
    beam = rf.World.from_scene(scenes / "cage_beam.toml")
    with pytest.raises(ValueError, match="other bodies"):
        beam.restore(drop.save())
    start = drop.save()
    drop.step(5)
    later, probes = drop.save(), drop.probes()
    drop.restore(start)
    assert drop.frame == 0 and all(p.shape[0] == 1 for p in drop.probes().values())
    drop.restore(later)
    assert drop.frame == 5
    for name, samples in probes.items():
        np.testing.assert_array_equal(drop.probes()[name], samples)


def test_override_paths_are_strict_and_create_missing_tables(scenes):
    path = scenes / "rigid_on_soft.toml"
    for bad in ["soft_body[[0].material.young", "soft_body[", "a..b", "soft_body[x]"]:
        with pytest.raises(ValueError, match="a key path is keys"):
            rf.World.from_scene(path, {bad: 1.0})
    # [contact] is not in the scene: the override makes it, and its value is checked.
    rf.World.from_scene(path, {"contact.margin": 2e-3})
    with pytest.raises(rf.SceneError, match="margin"):
        rf.World.from_scene(path, {"contact.margin": -1.0})
    # numpy scalars and tuples are values too.
    rf.World.from_scene(path, {"soft_body[0].material.young": np.float64(2e6),
                               "world.gravity": (0.0, np.float32(-9.0), 0.0)})


def test_an_error_elsewhere_in_an_overridden_scene_names_the_files_own_line(scenes, tmp_path):
    text = (scenes / "rigid_on_soft.toml").read_text().replace("poisson = 0.3", "poisson = 0.7")
    bad = tmp_path / "rigid_on_soft.toml"
    bad.write_text(text)
    line = next(i + 1 for i, l in enumerate(text.splitlines()) if "poisson = 0.7" in l)
    with pytest.raises(rf.SceneError, match=f"rigid_on_soft.toml:{line}:"):
        rf.World.from_scene(bad, {"rigid_body[1].density": 500.0})


def test_handles_materials_meshes_and_shapes_pickle():
    import pickle

    material = rf.Material("corotated", 2e6, 0.25, 900.0)
    mesh = rf.Mesh.cuboid((0.1, 0.2, 0.3), (1, 2, 3))
    for value in [rf.SoftBody(1, 2), rf.RigidBody(3, 0), rf.Collider(0, 4)]:
        assert pickle.loads(pickle.dumps(value)) == value
    for shape in [rf.Shape.cuboid((0.1, 0.2, 0.3)), rf.Shape.ball(0.1),
                  rf.Shape.capsule(0.2, 0.05), rf.Shape.cylinder(0.2, 0.05)]:
        assert repr(pickle.loads(pickle.dumps(shape))) == repr(shape)
    assert repr(pickle.loads(pickle.dumps(material))) == repr(material)
    copy = pickle.loads(pickle.dumps(mesh))
    np.testing.assert_array_equal(copy.nodes, mesh.nodes)
    np.testing.assert_array_equal(copy.tets, mesh.tets)


def test_advise_returns_the_advice_and_writes_a_scene_that_runs(scenes, tmp_path):
    # The cantilever over 0.2 s: the same advice as `rapier-fvm advise`; the recommendation's
    # measured error is within the target and its file runs.
    advice = rf.advise(scenes / "cantilever.toml", tmp_path / "advice", target=0.05, duration=0.2)
    recommendation = advice["recommendation"]
    assert recommendation["within_target"] and recommendation["measured_error"] <= 0.05
    assert [a["label"] for a in advice["soft_bodies"][0]["alternatives"]][0] == "beam: model linear"
    report = rf.run_scene(recommendation["file"], tmp_path / "run", duration=0.05)
    assert report["frames"] == 3
    with pytest.raises(ValueError, match="target"):
        rf.advise(scenes / "cantilever.toml", tmp_path / "no", target=2.0)
    # Overrides edit the scene before it is the reference: a linear beam has no linear
    # alternative left.
    linear = rf.advise(scenes / "cantilever.toml", tmp_path / "linear", duration=0.2,
                       overrides={"soft_body[0].material.model": "linear"})
    labels = [a["label"] for a in linear["soft_bodies"][0]["alternatives"]]
    assert "beam: model linear" not in labels and "beam: model st_venant_kirchhoff" in labels
    bad = tmp_path / "bad.toml"
    bad.write_text((scenes / "cantilever.toml").read_text().replace("poisson = 0.3", "poisson = 0.5"))
    with pytest.raises(rf.SceneError, match="poisson"):
        rf.advise(bad, tmp_path / "bad")

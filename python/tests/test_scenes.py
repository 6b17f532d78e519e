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

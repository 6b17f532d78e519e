"""Sweeps: the same runs, the same numbers, whichever backend runs them."""

import csv
import json

import pytest

from rapier_fvm.sweep import grid, main, sweep

VALUES = {"soft_body[0].material.young": [5e5, 1e6], "rigid_body[1].density": [1000.0, 2000.0]}


def finals(rows):
    return [{k: v for k, v in row.items() if k not in ("wall_time_s", "ms_per_frame")}
            for row in rows]


def test_the_grid_is_every_combination_first_key_slowest():
    assert grid(VALUES) == [
        {"soft_body[0].material.young": 5e5, "rigid_body[1].density": 1000.0},
        {"soft_body[0].material.young": 5e5, "rigid_body[1].density": 2000.0},
        {"soft_body[0].material.young": 1e6, "rigid_body[1].density": 1000.0},
        {"soft_body[0].material.young": 1e6, "rigid_body[1].density": 2000.0},
    ]


@pytest.mark.parametrize("backend", ["pool", "ray"])
def test_backends_give_the_serial_loops_rows_to_the_bit(scenes, tmp_path, backend):
    scene = scenes / "rigid_on_soft.toml"
    serial = sweep(scene, VALUES, tmp_path / "serial", backend="serial", duration=0.1)
    other = sweep(scene, VALUES, tmp_path / backend, backend=backend, workers=2, duration=0.1)
    assert finals(other) == finals(serial)
    # The runs differ: a stiffer block or a heavier box changes the probes.
    assert len({json.dumps(r["ground reaction (N)"]) for r in serial}) > 1
    with open(tmp_path / backend / "sweep.csv") as f:
        assert len(list(csv.DictReader(f))) == 4
    assert (tmp_path / backend / "sweep.png").stat().st_size > 0
    assert len(list((tmp_path / backend / "runs").glob("*/report.json"))) == 4


def test_a_job_array_runs_one_job_each_then_gathers(scenes, tmp_path):
    scene = str(scenes / "rigid_on_soft.toml")
    sets = ["--set", "soft_body[0].material.young=5e5,1e6"]
    for index in range(2):
        main([scene, *sets, "--out", str(tmp_path), "--duration", "0.1", "--only", str(index)])
    main([scene, "--out", str(tmp_path), "--gather"])
    rows = json.loads((tmp_path / "sweep.json").read_text())
    alone = sweep(scene, {"soft_body[0].material.young": [5e5, 1e6]}, tmp_path / "loop",
                  backend="serial", duration=0.1)
    assert [r["ground reaction (N)"] for r in rows] == [r["ground reaction (N)"] for r in alone]


def test_a_bad_key_fails_the_sweep_with_the_scenes_error(scenes, tmp_path):
    import rapier_fvm as rf

    with pytest.raises(rf.SceneError, match="unknown field `nothing`"):
        sweep(scenes / "rigid_on_soft.toml", {"soft_body[0].nothing.young": [1.0]},
              tmp_path, backend="serial", duration=0.1)


def test_a_failed_run_is_a_row_with_its_error_and_the_others_go_on(scenes, tmp_path):
    rows = sweep(scenes / "rigid_on_soft.toml", {"soft_body[0].material.young": [1e6, -1.0]},
                 tmp_path, backend="pool", workers=2, duration=0.1)
    assert "error" not in rows[0] and "young" in rows[1]["error"]
    with open(tmp_path / "sweep.csv") as f:
        assert [r["error"] for r in csv.DictReader(f)] == ["", rows[1]["error"]]

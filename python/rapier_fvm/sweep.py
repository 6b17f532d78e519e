"""Batches of scene runs: a scene over a grid (or list) of values, each run an independent,
deterministic job writing its own report, gathered into one table and one plot.

    from rapier_fvm.sweep import sweep
    rows = sweep("assets/scenes/drop.toml",
                 {"soft_body[0].material.young": [1e5, 3e5, 1e6]},
                 out="out/sweep", backend="pool", workers=2)

Backends: ``"serial"`` (a plain loop), ``"pool"`` (a local process pool) and ``"ray"`` (tasks
on a Ray cluster: a local instance unless ``address`` names one, e.g. ``"auto"`` inside a
cluster). Each job runs ``run_scene`` into ``out/runs/<index>``; ``out/sweep.csv`` and
``out/sweep.json`` hold one row per run (its values, time per frame, stability and every
probe's final value) and ``out/sweep.png`` plots each probe's final value against the first
swept key (with matplotlib, if installed). The command line does the same, and runs one job of
a Slurm job array (``--only $SLURM_ARRAY_TASK_ID``) or gathers the table of finished runs
(``--gather``)::

    python -m rapier_fvm.sweep SCENE --set soft_body[0].material.young=1e5,1e6 --out DIR \\
        [--backend serial|pool|ray] [--workers N] [--address ADDR] [--duration S]
"""

from __future__ import annotations

import argparse
import csv
import itertools
import json
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

BACKENDS = ("serial", "pool", "ray")


def grid(parameters: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """Every combination of the values of `parameters` (key path -> values), first key slowest."""
    keys = list(parameters)
    return [dict(zip(keys, values)) for values in itertools.product(*parameters.values())]


def run_job(scene: str, out: str, index: int, overrides: Mapping[str, Any],
            duration: Optional[float]) -> dict[str, Any]:
    """Runs job `index` (the scene with `overrides`) into `out/runs/<index>`; its table row."""
    from . import run_scene

    folder = Path(out) / "runs" / f"{index:04d}"
    started = time.perf_counter()
    try:
        report = run_scene(scene, folder, duration=duration, overrides=dict(overrides))
    except ValueError as error:  # rapier_fvm.Error and SceneError, a malformed override
        return {"run": index, **overrides, "error": str(error), "exception": error}
    (folder / "overrides.json").write_text(json.dumps(overrides))
    return row_of(index, overrides, report, time.perf_counter() - started)


def row_of(index: int, overrides: Mapping[str, Any], report: Mapping[str, Any],
           seconds: float) -> dict[str, Any]:
    """A run's table row: index, values, cost, stability and each probe's final value."""
    stability = report.get("stability", {})
    row: dict[str, Any] = {"run": index, **overrides,
                           "wall_time_s": seconds,
                           "ms_per_frame": report["ms_per_frame"],
                           "stable": stability.get("stable", report.get("final_state_finite"))}
    for probe in report["probes"]:
        row[f"{probe['name']} ({probe['unit']})"] = probe["final_value"]
    return row


def sweep(scene: Union[str, os.PathLike], parameters: Union[Mapping[str, Sequence[Any]],
          Sequence[Mapping[str, Any]]], out: Union[str, os.PathLike], *,
          backend: str = "pool", workers: int = 2, duration: Optional[float] = None,
          address: Optional[str] = None) -> list[dict[str, Any]]:
    """Runs `scene` once per combination of `parameters` (a dict of key paths to value lists,
    or a list of override dicts) and writes the table and plot into `out`; returns the rows in
    run order. A pool's or Ray's job runs its solver on one thread (``RAYON_NUM_THREADS=1``),
    so `workers` jobs use `workers` cores; the serial loop runs in this process, on its threads.
    A run that fails is a row with its ``error``; if every run fails, the first error is
    raised."""
    if backend not in BACKENDS:
        raise ValueError(f"backend: {backend!r} is not one of {BACKENDS}")
    if workers < 1:
        raise ValueError(f"workers: must be at least 1, got {workers}")
    jobs = grid(parameters) if isinstance(parameters, Mapping) else [dict(p) for p in parameters]
    if not jobs:
        raise ValueError("parameters: no run to make")
    # Absolute, so that jobs on other machines' workers (whose working folder differs) find
    # them on a shared file system.
    scene, out = str(Path(scene).resolve()), str(Path(out).resolve())
    Path(out).mkdir(parents=True, exist_ok=True)
    args = [(scene, out, i, job, duration) for i, job in enumerate(jobs)]
    if backend == "serial":
        rows = [run_job(*a) for a in args]
    elif backend == "pool":
        rows = run_pool(args, workers)
    else:
        rows = run_ray(args, workers, address)
    errors = [row.pop("exception") for row in rows if "exception" in row]
    write_table(rows, Path(out))
    if len(errors) == len(rows):
        raise errors[0]
    return rows


def one_thread() -> None:
    """Keeps a job's solver on one thread (read when its thread pool starts)."""
    os.environ["RAYON_NUM_THREADS"] = "1"


def run_pool(args: list[tuple], workers: int) -> list[dict[str, Any]]:
    """The jobs on a local process pool (spawned: the solver's threads do not survive fork)."""
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(workers, mp_context=context, initializer=one_thread) as pool:
        return list(pool.map(run_job, *zip(*args)))


def run_ray(args: list[tuple], workers: int, address: Optional[str]) -> list[dict[str, Any]]:
    """The jobs as Ray tasks of one CPU each, at most `workers` at a time on a local instance
    (or on the cluster at `address`)."""
    import ray

    started_here = not ray.is_initialized()
    if started_here:
        options: dict[str, Any] = {"address": address, "include_dashboard": False}
        if address is None:
            options["num_cpus"] = workers
        ray.init(**options)
    try:
        one_thread_env = {"env_vars": {"RAYON_NUM_THREADS": "1"}}
        task = ray.remote(num_cpus=1, runtime_env=one_thread_env)(run_job)
        return ray.get([task.remote(*a) for a in args])
    finally:
        if started_here:
            ray.shutdown()


def write_table(rows: list[dict[str, Any]], out: Path) -> None:
    """`out/sweep.csv`, `out/sweep.json` and, with matplotlib, `out/sweep.png`."""
    columns = list(dict.fromkeys(k for row in rows for k in row))
    with open(out / "sweep.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
    (out / "sweep.json").write_text(json.dumps(rows, indent=1))
    plot(rows, out / "sweep.png")


def plot(rows: list[dict[str, Any]], path: Path) -> bool:
    """Each probe's final value against the first swept key, a line for each combination of the
    others; False without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    rows = [row for row in rows if "error" not in row]
    if not rows:
        return False
    fixed = {"run", "wall_time_s", "ms_per_frame", "stable"}
    keys = [k for k in rows[0] if k not in fixed and " (" not in k]
    probes = [k for k in rows[0] if " (" in k]
    if not keys or not probes:
        return False
    figure, axes = plt.subplots(len(probes), 1, figsize=(6, 2.5 * len(probes)), squeeze=False)
    # One line per combination of the other keys' values.
    lines: dict[tuple, list[dict[str, Any]]] = {}
    for row in rows:
        lines.setdefault(tuple(row[k] for k in keys[1:]), []).append(row)
    for axis, probe in zip(axes[:, 0], probes):
        for others, line in lines.items():
            label = ", ".join(f"{k} = {v}" for k, v in zip(keys[1:], others)) or None
            axis.plot([r[keys[0]] for r in line], [r[probe] for r in line], "o-", label=label)
        axis.set_xlabel(keys[0])
        axis.set_ylabel(probe)
        if len(lines) > 1:
            axis.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return True


def gather(out: Path) -> list[dict[str, Any]]:
    """The rows of the finished runs under `out/runs` (a Slurm job array's), and the table;
    a folder without a finished run is named on stderr and left out."""
    rows = []
    for folder in sorted((out / "runs").iterdir()):
        if not ((folder / "report.json").is_file() and (folder / "overrides.json").is_file()):
            print(f"{folder}: no finished run, left out", file=sys.stderr)
            continue
        report = json.loads((folder / "report.json").read_text())
        overrides = json.loads((folder / "overrides.json").read_text())
        rows.append(row_of(int(folder.name), overrides, report, report["wall_time_s"]))
    write_table(rows, out)
    return rows


def parse_set(text: str) -> tuple[str, list[Any]]:
    """`key=v1,v2,...` with values read as JSON (numbers, true/false, "strings")."""
    key, _, values = text.partition("=")
    if not key or not values:
        raise argparse.ArgumentTypeError(f"expected KEY=V1,V2,..., got {text!r}")
    return key, [json.loads(v) for v in values.split(",")]


def main(argv: Optional[Sequence[str]] = None) -> int:
    """The command line (see the module's documentation)."""
    parser = argparse.ArgumentParser(prog="python -m rapier_fvm.sweep",
                                     description="Runs a scene over a grid of values.")
    parser.add_argument("scene")
    parser.add_argument("--set", dest="sets", type=parse_set, action="append", default=[],
                        metavar="KEY=V1,V2", help="a key path and its values (repeatable)")
    parser.add_argument("--out", required=True)
    parser.add_argument("--backend", choices=BACKENDS, default="pool")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--address", default=None, help="a Ray cluster's address")
    parser.add_argument("--duration", type=float, default=None)
    one = parser.add_mutually_exclusive_group()
    one.add_argument("--only", type=int, default=None,
                     help="runs only this job index (one task of a Slurm job array)")
    one.add_argument("--gather", action="store_true",
                     help="gathers the table of the runs already under --out")
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.gather:
        rows = gather(out)
    elif args.only is not None:
        jobs = grid(dict(args.sets))
        if not 0 <= args.only < len(jobs):
            parser.error(f"--only {args.only}: the grid has jobs 0..{len(jobs) - 1}")
        one_thread()
        rows = [run_job(str(Path(args.scene).resolve()), str(out.resolve()), args.only,
                        jobs[args.only], args.duration)]
        rows[0].pop("exception", None)
    else:
        rows = sweep(args.scene, dict(args.sets), out, backend=args.backend,
                     workers=args.workers, duration=args.duration, address=args.address)
    failed = [row for row in rows if "error" in row]
    for row in failed:
        print(f"run {row['run']} failed: {row['error']}", file=sys.stderr)
    if args.only is None:
        print(f"{len(rows)} runs ({len(failed)} failed); table in {out / 'sweep.csv'}")
    else:
        print(f"run {args.only} in {out / 'runs'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""Sweep throughput: runs per minute of the same eight runs (the rigid_on_soft scene, 2 s,
four moduli by two box densities) as a plain loop, a process pool and Ray, with one and two
workers, in one sitting; Ray's start-up, and its overhead per job against the loop.

    python python/benches/sweep_throughput.py   (needs the `ray` extra)
"""

import os
import tempfile
import time
from pathlib import Path

from rapier_fvm.sweep import sweep

SCENE = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "rigid_on_soft.toml"
VALUES = {"soft_body[0].material.young": [5e5, 1e6, 2e6, 4e6], "rigid_body[1].density": [1e3, 2e3]}
RUNS = 8
DURATION = 2.0


def main():
    """Runs the five ways in turn and prints runs per minute."""
    import ray

    os.environ["RAYON_NUM_THREADS"] = "1"
    results = {}
    with tempfile.TemporaryDirectory() as out:
        for backend, workers in [("serial", 1), ("pool", 1), ("pool", 2), ("ray", 1), ("ray", 2)]:
            if backend == "ray":
                started = time.perf_counter()
                ray.init(num_cpus=workers, include_dashboard=False,
                         runtime_env={"env_vars": {"RAYON_NUM_THREADS": "1"}})
                print(f"Ray started with {workers} CPU(s) in {time.perf_counter() - started:.2f} s")
            started = time.perf_counter()
            sweep(SCENE, VALUES, Path(out) / f"{backend}{workers}", backend=backend,
                  workers=workers, duration=DURATION)
            seconds = time.perf_counter() - started
            if backend == "ray":
                ray.shutdown()
            results[(backend, workers)] = seconds
            print(f"{backend:6} {workers} worker(s): {seconds:6.2f} s, "
                  f"{RUNS / seconds * 60:6.1f} runs/min")
    loop = results[("serial", 1)]
    for workers in (1, 2):
        overhead = (results[("ray", workers)] - loop / workers) / RUNS
        print(f"Ray's overhead per job with {workers} worker(s), start-up apart: {overhead:.3f} s")
    print("load average", os.getloadavg())


# The pool spawns processes that import this file: the runs go under the guard.
if __name__ == "__main__":
    main()

"""The cost of the Python boundary per step: a body stepped frame by frame from Python (one
`step()` call and one `positions()` read per frame) against the same world stepped by Rust's
loop (`step(frames)` in one call), alternating, for a 100-tet and a 10k-tet body.

    python python/benches/boundary.py        (prints one line per size, then the load average)
"""

import os
import time

import numpy as np

import rapier_fvm as rf

FRAMES = 120


def beam(cells):
    """A rubber beam clamped at one end, swinging under gravity (never at rest)."""
    world = rf.World(dt=1 / 60)
    mesh = rf.Mesh.cuboid((0.5, 0.05, 0.05), cells)
    clamped = np.flatnonzero(mesh.nodes[:, 0] < -0.5 + 1e-9)
    rubber = rf.Material("stable_neo_hookean", young=1e6, poisson=0.3, density=1000.0)
    body = world.add_soft_body(mesh, rubber, stiffness_time=0.01, pinned=clamped)
    return world, body, mesh.tet_count


def by_python(cells):
    world, body, _ = beam(cells)
    started = time.perf_counter()
    for _ in range(FRAMES):
        world.step()
        world.positions(body)
    return (time.perf_counter() - started) / FRAMES, world.positions(body)


def by_rust(cells):
    world, body, _ = beam(cells)
    started = time.perf_counter()
    world.step(FRAMES)
    return (time.perf_counter() - started) / FRAMES, world.positions(body)


for cells in [(20, 1, 1), (50, 5, 8)]:
    tets = beam(cells)[2]
    python_s, rust_s = [], []
    for _ in range(5):
        t, x_python = by_python(cells)
        python_s.append(t)
        t, x_rust = by_rust(cells)
        rust_s.append(t)
    same = np.array_equal(x_python, x_rust)
    p, r = min(python_s), min(rust_s)
    # The boundary alone, timed over many calls: a step call that steps nothing and a read.
    world, body, _ = beam(cells)
    calls = 2000
    started = time.perf_counter()
    for _ in range(calls):
        world.step(0)
    call = (time.perf_counter() - started) / calls
    started = time.perf_counter()
    for _ in range(calls):
        world.positions(body)
    read = (time.perf_counter() - started) / calls
    print(f"{tets} tets: Python-driven {p * 1e3:.4f} ms per frame, Rust-driven {r * 1e3:.4f} ms "
          f"(best of 5, ratio {p / r:.3f}); same positions to the bit: {same}; the boundary "
          f"alone: a step call {call * 1e6:.2f} us, a positions() read {read * 1e6:.2f} us "
          f"({x_rust.shape[0]} nodes), {(call + read) / r * 100:.3f} % of a frame")
print("load average", os.getloadavg())

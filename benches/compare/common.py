"""Shared pieces of the peer comparison: scene constants, closed-form references,
timing, signal analysis, tet meshes and JSON-lines output.

Every case script prints one JSON object per line to the real stdout; the engines'
own chatter (pybullet prints every tet it loads) is sent to /dev/null at the file
descriptor level, so the stdout stream stays machine-readable.
"""
import argparse
import json
import math
import os
import platform
import sys
import time

import numpy as np

G = 9.81

# Cantilever (issue 6, scenes 1-3): L = 1 m, 0.1 x 0.1 m section, clamped at x = 0.
BEAM_L, BEAM_B, BEAM_H, BEAM_RHO, BEAM_E, BEAM_NU = 1.0, 0.1, 0.1, 1000.0, 1e8, 0.3
POISSON_SWEEP = (0.0, 0.3, 0.45, 0.49, 0.499)

# Contact scenes (issue 6, scenes 4-5).
SOFT_E, SOFT_NU, SOFT_RHO = 1e5, 0.3, 1000.0
DROP_SIZE, DROP_HEIGHT = 0.2, 0.5  # cube edge; height of its bottom face at release
BLOCK_SIZE = (0.3, 0.3, 0.1)  # soft block, bottom face pinned at z = 0
BOX_SIZE, BOX_MASS = 0.1, 1.0  # rigid box resting on the block

SCALING_CASE_BUDGET_S = 30.0


# ----------------------------------------------------------------------------
# References
# ----------------------------------------------------------------------------
def lame(E, nu):
    mu = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    return mu, lam


def cowper_kappa(nu):
    """Shear correction of a rectangular section (Cowper 1966): 10(1+nu)/(12+11nu)."""
    return 10 * (1 + nu) / (12 + 11 * nu)


def beam_eb_tip(E=BEAM_E, L=BEAM_L, b=BEAM_B, h=BEAM_H, rho=BEAM_RHO):
    """Euler-Bernoulli tip deflection of a cantilever under its own weight: q L^4 / (8 E I)."""
    q = rho * G * b * h
    I = b * h**3 / 12
    return q * L**4 / (8 * E * I)


def beam_timoshenko_tip(E=BEAM_E, nu=BEAM_NU, L=BEAM_L, b=BEAM_B, h=BEAM_H, rho=BEAM_RHO):
    """Timoshenko: q L^4/(8 E I) + q L^2/(2 kappa G A), kappa from Cowper."""
    q = rho * G * b * h
    Gs = E / (2 * (1 + nu))
    return beam_eb_tip(E, L, b, h, rho) + q * L**2 / (2 * cowper_kappa(nu) * Gs * b * h)


def beam_eb_frequency(E=BEAM_E, L=BEAM_L, b=BEAM_B, h=BEAM_H, rho=BEAM_RHO):
    """First clamped-free bending frequency: f = (1.87510)^2 / (2 pi L^2) sqrt(E I / (rho A))."""
    I, A = b * h**3 / 12, b * h
    return 1.8751040687**2 / (2 * math.pi * L**2) * math.sqrt(E * I / (rho * A))


def beam_timoshenko_frequency(E=BEAM_E, nu=BEAM_NU, L=BEAM_L, b=BEAM_B, h=BEAM_H, rho=BEAM_RHO,
                              n=400):
    """First clamped-free frequency of the Timoshenko beam (shear kappa G A, rotary inertia
    rho I), solved with n two-node elements (one-point shear integration, lumped mass);
    converged to ~1e-5 at n = 400. Also returns the static tip deflection of the same model
    as a check against the closed form."""
    I, A = b * h**3 / 12, b * h
    Gs = E / (2 * (1 + nu))
    kGA = cowper_kappa(nu) * Gs * A
    le = L / n
    ndof = 2 * (n + 1)
    K = np.zeros((ndof, ndof))
    kb = E * I / le * np.array([[0, 0, 0, 0], [0, 1, 0, -1], [0, 0, 0, 0], [0, -1, 0, 1]])
    B = np.array([-1 / le, -0.5, 1 / le, -0.5])
    ke = kb + kGA * le * np.outer(B, B)
    for e in range(n):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += ke
    m = np.zeros(ndof)
    f = np.zeros(ndof)
    for e in range(n):
        for node in (e, e + 1):
            m[2 * node] += rho * A * le / 2
            m[2 * node + 1] += rho * I * le / 2
            f[2 * node] += rho * G * A * le / 2
    free = np.arange(2, ndof)
    Kf, mf = K[np.ix_(free, free)], m[free]
    tip_static = np.linalg.solve(Kf, f[free])[-2]
    d = 1 / np.sqrt(mf)
    w2 = np.linalg.eigvalsh(Kf * d[:, None] * d[None, :])
    return math.sqrt(w2[0]) / (2 * math.pi), tip_static


def drop_rest_centroid(E=SOFT_E, rho=SOFT_RHO, H=DROP_SIZE):
    """Centroid height of a cube resting under its own weight on frictionless ground
    (uniaxial stress): H/2 - rho g H^2 / (3 E)."""
    return H / 2 - rho * G * H**2 / (3 * E)


# ----------------------------------------------------------------------------
# Timing and output
# ----------------------------------------------------------------------------
class Timer:
    """Per-step CPU (time.process_time) and wall times."""

    def __init__(self):
        self.cpu, self.wall = [], []

    def step(self, fn):
        c0, w0 = time.process_time(), time.perf_counter()
        fn()
        self.cpu.append(time.process_time() - c0)
        self.wall.append(time.perf_counter() - w0)

    def fields(self):
        cpu = np.array(self.cpu) if self.cpu else np.array([float("nan")])
        wall = np.array(self.wall) if self.wall else np.array([float("nan")])
        return {
            "ms_per_step": float(np.median(cpu) * 1e3),
            "wall_ms_per_step": float(np.median(wall) * 1e3),
            "steps_timed": len(self.cpu),
            "cpu_s_total": float(cpu.sum()),
        }


_OUT = None


def quiet_stdout():
    """Send fd 1 to /dev/null (engines print from C); JSON goes to a dup of the old fd 1."""
    global _OUT
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.close(devnull)
    _OUT = os.fdopen(saved, "w", buffering=1)
    sys.stdout = sys.stderr  # Python-level prints become diagnostics


def clean(x):
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def machine():
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = None
    return {"host_cpus": os.cpu_count(), "load1": load, "python": platform.python_version(),
            "platform": platform.platform()}


def emit(record):
    record.setdefault("machine", machine())
    line = json.dumps(clean(record), allow_nan=False)
    (_OUT or sys.stdout).write(line + "\n")
    (_OUT or sys.stdout).flush()
    print(f"[{record.get('scene')}] {record.get('case')}: error={record.get('error')} "
          f"ms/step={record.get('ms_per_step'):.3g} stable={record.get('stable')}", file=sys.stderr)


def rel_error(value, reference):
    if value is None or reference is None or not math.isfinite(value):
        return None
    return (value - reference) / reference


def parse_args(scenes, description):
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--quick", action="store_true",
                    help="smallest resolution of each scene only (smoke test)")
    ap.add_argument("--scene", action="append", choices=scenes,
                    help="run only this scene (repeatable); default: all")
    args = ap.parse_args()
    args.scenes = args.scene or list(scenes)
    return args


# ----------------------------------------------------------------------------
# Signal analysis
# ----------------------------------------------------------------------------
def _fit_fixed(t, u, w, s):
    X = np.stack([np.ones_like(t), np.exp(-s * t) * np.cos(w * t), np.exp(-s * t) * np.sin(w * t)], 1)
    coef, *_ = np.linalg.lstsq(X, u, rcond=None)
    r = u - X @ coef
    return float(r @ r), coef


def fit_damped_oscillation(t, u):
    """Least-squares fit u(t) = c + exp(-s t)(a cos wt + b sin wt).
    Returns natural frequency (Hz) sqrt(w^2+s^2)/2pi, damping ratio s/sqrt(w^2+s^2), the
    equilibrium c and the fit residual relative to the signal's spread."""
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    if len(u) < 8 or not np.all(np.isfinite(u)) or np.ptp(u) == 0:
        return None
    dt = t[1] - t[0]
    wmin, wmax = 2 * math.pi / (t[-1] - t[0]), 0.9 * math.pi / dt
    best = None
    # coarse: log-spaced frequencies up to Nyquist, damping ratios 0..0.95
    for w in np.geomspace(wmin, wmax, 120):
        for z in np.linspace(0.0, 0.95, 20):
            s = z * w / math.sqrt(1 - z * z)
            r, coef = _fit_fixed(t, u, w, s)
            if best is None or r < best[0]:
                best = (r, w, s, coef)
    _, w, s, _ = best
    wlo, whi = w / 1.1, w * 1.1
    slo, shi = max(s - 0.2 * w, 0.0), s + 0.2 * w
    for _ in range(4):
        for w in np.linspace(wlo, whi, 31):
            for s in np.linspace(slo, shi, 31):
                r, coef = _fit_fixed(t, u, w, s)
                if r < best[0]:
                    best = (r, w, s, coef)
        _, w, s, _ = best
        dw, ds = (whi - wlo) / 10, (shi - slo) / 10
        wlo, whi, slo, shi = max(w - dw, 1e-6), w + dw, max(s - ds, 0.0), s + ds
    r, w, s, coef = best
    wn = math.hypot(w, s)
    return {"frequency_hz": wn / (2 * math.pi), "damped_frequency_hz": w / (2 * math.pi),
            "damping_ratio": s / wn, "equilibrium": float(coef[0]),
            "fit_residual_rel": math.sqrt(r / len(u)) / (np.std(u) + 1e-300)}


# ----------------------------------------------------------------------------
# Tet meshes (pybullet reads them; MuJoCo builds its own grid)
# ----------------------------------------------------------------------------
def box_tet_mesh(n, size, origin=(0.0, 0.0, 0.0)):
    """Grid of n[0] x n[1] x n[2] cubes, 5 tets each with alternating orientation so faces
    conform; every tet positively oriented. Returns (points (N,3), tets (M,4))."""
    nx, ny, nz = n
    sx, sy, sz = (size[i] / n[i] for i in range(3))
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k
    pts = np.array([(origin[0] + i * sx, origin[1] + j * sy, origin[2] + k * sz)
                    for i in range(nx + 1) for j in range(ny + 1) for k in range(nz + 1)])
    tets = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                c = [idx(i + a, j + b, k + d) for a in (0, 1) for b in (0, 1) for d in (0, 1)]
                # corners c[abd] with a,b,d bits (x,y,z)
                if (i + j + k) % 2 == 0:
                    cs = [(0, 3, 5, 6), (1, 0, 5, 3), (2, 0, 3, 6), (4, 0, 6, 5), (7, 3, 6, 5)]
                else:
                    cs = [(1, 2, 4, 7), (0, 1, 2, 4), (3, 1, 7, 2), (5, 1, 4, 7), (6, 2, 7, 4)]
                tets += [[c[q] for q in t] for t in cs]
    tets = np.array(tets)
    d = pts[tets[:, 1:]] - pts[tets[:, :1]]
    vol = np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))
    neg = vol < 0
    tets[neg] = tets[neg][:, [0, 2, 1, 3]]
    return pts, tets


def tet_volumes(pts, tets):
    d = pts[tets[:, 1:]] - pts[tets[:, :1]]
    return np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2])) / 6


def write_vtk(path, pts, tets):
    """Legacy ASCII VTK unstructured grid, one point and one cell per line (pybullet's reader)."""
    with open(path, "w") as f:
        f.write("# vtk DataFile Version 2.0\nrapier_fvm compare\nASCII\nDATASET UNSTRUCTURED_GRID\n")
        f.write(f"POINTS {len(pts)} double\n")
        f.writelines(f"{p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n" for p in pts)
        f.write(f"\nCELLS {len(tets)} {5 * len(tets)}\n")
        f.writelines(f"4 {t[0]} {t[1]} {t[2]} {t[3]}\n" for t in tets)
        f.write(f"\nCELL_TYPES {len(tets)}\n")
        f.writelines("10\n" for _ in tets)


if __name__ == "__main__":
    f, tip = beam_timoshenko_frequency()
    print("EB tip", beam_eb_tip(), "Timoshenko tip", beam_timoshenko_tip(), "FE check", tip)
    print("EB f1", beam_eb_frequency(), "Timoshenko f1", f)
    p, t = box_tet_mesh((2, 2, 2), (1, 1, 1))
    print("mesh vol", tet_volumes(p, t).sum(), "min", tet_volumes(p, t).min())
    tt = np.linspace(0, 2, 481)
    sig = 0.3 + np.exp(-0.5 * tt) * np.cos(2 * np.pi * 5 * tt)
    print(fit_damped_oscillation(tt, sig), 0.5 / math.hypot(0.5, 2 * math.pi * 5))
    print("drop rest centroid", drop_rest_centroid())

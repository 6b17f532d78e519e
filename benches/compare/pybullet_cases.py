"""pybullet 3.2.7 deformables (FEM, stable Neo-Hookean, implicit damping) on the scenes of
issue 6. One JSON line per case on stdout; progress on stderr.

    benches/compare/.venv/bin/python benches/compare/pybullet_cases.py [--quick] [--scene NAME]

Setup pitfalls handled here (see shared notes/peers.md):
  * deformable world (RESET_USE_DEFORMABLE_WORLD), tets from legacy ASCII VTK, positively
    oriented tets (common.box_tet_mesh), numpy installed;
  * pybullet's Neo-Hookean takes NeoHookeanMu = 4/3 mu, NeoHookeanLambda = lambda + 5/6 mu for a
    material with textbook (E, nu);
  * a GEOM_PLANE ground does not collide with deformables: the ground is a static box;
  * the `mass` argument is spread uniformly over the nodes (no per-node masses in the API);
  * elasticity is explicit, only the damping (NeoHookeanDamping, a stiffness-proportional
    time beta) is implicit: it needs beta >= dt/2 to be stable.
"""
import hashlib
import math
import os
import sys
import tempfile
import time
from importlib import metadata

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common as c  # noqa: E402

SCENES = ("cantilever", "poisson", "vibration", "drop", "box_on_block", "scaling")
ENGINE = "pybullet"
VERSION = metadata.version("pybullet")
TMP = tempfile.mkdtemp(prefix="pb_compare_")
DEFAULT_MARGIN = 0.02  # what peers.md measured as pybullet's rest gap

import pybullet as p  # noqa: E402  (after common: its import banner goes to stderr)


def new_world(dt):
    p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD)
    p.setGravity(0, 0, -c.G)
    p.setTimeStep(dt)
    p.setPhysicsEngineParameter(sparseSdfVoxelSize=0.25)


def add_ground():
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[5, 5, 0.5])
    body = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=shape, basePosition=[0, 0, -0.5])
    p.changeDynamics(body, -1, lateralFriction=0.5)
    return body


def add_soft(pts, tets, E, nu, rho, beta, margin=DEFAULT_MARGIN, friction=0.5):
    key = hashlib.sha1(np.ascontiguousarray(pts).tobytes() + np.ascontiguousarray(tets).tobytes())
    path = os.path.join(TMP, f"mesh_{key.hexdigest()[:16]}.vtk")
    if not os.path.exists(path):
        c.write_vtk(path, pts, tets)
    mu, lam = c.lame(E, nu)
    mass = rho * c.tet_volumes(pts, tets).sum()
    body = p.loadSoftBody(path, basePosition=[0, 0, 0], scale=1, mass=mass, useNeoHookean=1,
                          NeoHookeanMu=4 / 3 * mu, NeoHookeanLambda=lam + 5 / 6 * mu,
                          NeoHookeanDamping=beta, collisionMargin=margin, frictionCoeff=friction,
                          useSelfCollision=0, useFaceContact=1)
    if body < 0:
        raise RuntimeError("pybullet failed to load the soft body")
    return body


def nodes(body):
    return np.array(p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1])


def pin(body, mask):
    for i in np.where(mask)[0]:
        p.createSoftBodyAnchor(body, int(i), -1, -1)


def base_record(scene, case, settings, elements):
    s = {"engine": ENGINE, "engine_version": VERSION, "scene": scene, "case": case,
         "elements": int(elements), "settings": dict(settings, elements=int(elements))}
    s["settings"].setdefault("model", "stable Neo-Hookean (mu'=4/3 mu, lambda'=lambda+5/6 mu)")
    s["settings"].setdefault("mass_lumping", "uniform per node (pybullet API)")
    return s


def finite(x, limit):
    return bool(np.all(np.isfinite(x)) and np.max(np.abs(x)) < limit)


# ----------------------------------------------------------------------------
# Cantilever: static tip deflection (scenes 1 and 2)
# ----------------------------------------------------------------------------
BEAM_ORIGIN = (0.0, -c.BEAM_B / 2, 1.0)
SETTLE_BETA = 2 / (2 * math.pi * c.beam_eb_frequency())  # first mode critically damped


def run_beam(res, dt, nu, beta, t_end, record_every=1):
    new_world(dt)
    pts, tets = c.box_tet_mesh(res, (c.BEAM_L, c.BEAM_B, c.BEAM_H), BEAM_ORIGIN)
    body = add_soft(pts, tets, c.BEAM_E, nu, c.BEAM_RHO, beta)
    pin(body, pts[:, 0] < 1e-9)
    tip = pts[:, 0] > c.BEAM_L - 1e-9
    timer, ts, us = c.Timer(), [], []
    stable = True
    for k in range(int(round(t_end / dt))):
        timer.step(p.stepSimulation)
        if k % record_every == 0 or k == int(round(t_end / dt)) - 1:
            x = nodes(body)
            if not finite(x, 100.0):
                stable = False
                break
            ts.append((k + 1) * dt)
            us.append(float((x[tip, 2] - pts[tip, 2]).mean()))
    return len(tets), np.array(ts), np.array(us), timer, stable


def static_case(scene, res, dt, nu, settle=1.5):
    n_el, ts, us, timer, stable = run_beam(res, dt, nu, SETTLE_BETA, settle)
    ref = c.beam_timoshenko_tip(nu=nu)
    tail = us[ts > settle - 0.25] if len(us) else us
    tip = -float(tail.mean()) if stable and len(tail) else None
    drift = float(abs(tail[-1] - tail[0])) if stable and len(tail) > 1 else None
    if tip is not None and not (0.0 < tip < 10 * ref):
        stable = False  # moved against gravity or ran away: not a physical equilibrium
    r = base_record(scene, f"{res[0]}x{res[1]}x{res[2]} cubes dt=1/{round(1 / dt)} nu={nu}", {
        "resolution": list(res), "tets_per_cube": 5, "dt": dt, "nu": nu, "E": c.BEAM_E,
        "damping_beta": SETTLE_BETA, "settle_s": settle,
        "settling": "stiffness-proportional damping beta = 2/omega_1 (first mode critically "
                    "damped), tip averaged over the last 0.25 s"}, n_el)
    r.update({"reference": ref, "reference_name": "Timoshenko q L^4/(8EI) + q L^2/(2 kappa G A), "
              "kappa = 10(1+nu)/(12+11nu)", "reference_euler_bernoulli": c.beam_eb_tip(),
              "tip_deflection": tip, "error": c.rel_error(tip, ref) if stable else None,
              "error_vs_euler_bernoulli": c.rel_error(tip, c.beam_eb_tip()) if stable else None,
              "tip_drift_last_0_25s": drift,
              "settled": bool(drift is not None and drift < 0.01 * ref),
              "stable": stable})
    r.update(timer.fields())
    c.emit(r)


def scene_cantilever(quick):
    resolutions = [(10, 1, 1)] if quick else [(10, 1, 1), (20, 2, 2), (40, 4, 4)]
    for dt in (1 / 240, 1 / 60):
        for res in resolutions:
            static_case("cantilever", res, dt, c.BEAM_NU)


def scene_poisson(quick):
    res = (10, 1, 1) if quick else (20, 2, 2)
    for nu in c.POISSON_SWEEP:
        static_case("poisson", res, 1 / 240, nu)


# ----------------------------------------------------------------------------
# Free vibration (scene 3)
# ----------------------------------------------------------------------------
def scene_vibration(quick):
    res = (10, 1, 1) if quick else (20, 2, 2)
    f_t, _ = c.beam_timoshenko_frequency()
    dts = [1 / 240] if quick else [1 / 1000, 1 / 240, 1 / 60]
    for dt in dts:
        for beta_factor in (0.5, 1.0):
            beta = beta_factor * dt
            n_el, ts, us, timer, stable = run_beam(res, dt, c.BEAM_NU, beta, 2.0)
            fit = c.fit_damped_oscillation(ts, us) if stable else None
            freq = fit["frequency_hz"] if fit else None
            zeta = fit["damping_ratio"] if fit else None
            # damping beta gives the mode it measures beta*omega/2 (omega of the model, not of theory)
            zeta_phys = beta * 2 * math.pi * freq / 2 if freq else None
            r = base_record("vibration", f"{res[0]}x{res[1]}x{res[2]} dt=1/{round(1 / dt)} "
                            f"beta={beta_factor}dt", {
                                "resolution": list(res), "tets_per_cube": 5, "dt": dt,
                                "damping_beta": beta, "duration_s": 2.0,
                                "excitation": "released straight under gravity (oscillates "
                                              "about the static deflection)",
                                "note": "pybullet needs beta >= dt/2 to be stable, so the "
                                        "beam is never undamped"}, n_el)
            r.update({"reference": f_t,
                      "reference_name": "Timoshenko first bending frequency (shear + rotary "
                                        "inertia, 400-element solve); Euler-Bernoulli "
                                        "(1.8751^2/(2 pi L^2)) sqrt(EI/(rho A))",
                      "reference_euler_bernoulli": c.beam_eb_frequency(),
                      "first_frequency_hz": freq, "error": c.rel_error(freq, f_t),
                      "damping_ratio": zeta,
                      "damping_ratio_from_beta": zeta_phys,
                      "numerical_damping_ratio": (zeta - zeta_phys) if zeta_phys is not None else None,
                      "fit": fit, "stable": stable and fit is not None})
            r.update(timer.fields())
            c.emit(r)
            if stable:
                break  # smallest stable beta found for this dt


# ----------------------------------------------------------------------------
# Drop (scene 4)
# ----------------------------------------------------------------------------
def scene_drop(quick):
    cases = [(4, DEFAULT_MARGIN)] if quick else [(4, DEFAULT_MARGIN), (4, 0.002), (8, DEFAULT_MARGIN)]
    dt, beta, t_end = 1 / 240, 0.01, 2.5
    ref = c.drop_rest_centroid()
    for n, margin in cases:
        new_world(dt)
        add_ground()
        s = c.DROP_SIZE
        pts, tets = c.box_tet_mesh((n, n, n), (s, s, s), (-s / 2, -s / 2, c.DROP_HEIGHT))
        body = add_soft(pts, tets, c.SOFT_E, c.SOFT_NU, c.SOFT_RHO, beta, margin=margin)
        timer, minz, cz = c.Timer(), [], []
        stable = True
        for k in range(int(t_end / dt)):
            timer.step(p.stepSimulation)
            x = nodes(body)
            if not finite(x, 100.0):
                stable = False
                break
            minz.append(x[:, 2].min())
            cz.append(x[:, 2].mean())
        minz, cz = np.array(minz), np.array(cz)
        rest = slice(-int(0.5 / dt), None)
        h = float(cz[rest].mean()) if stable else None
        r = base_record("drop", f"{n}^3 cubes margin={margin}", {
            "resolution": [n, n, n], "tets_per_cube": 5, "dt": dt, "damping_beta": beta,
            "collision_margin": margin, "friction": 0.5, "E": c.SOFT_E, "nu": c.SOFT_NU,
            "drop_height_bottom": c.DROP_HEIGHT, "duration_s": t_end,
            "ground": "static box (GEOM_PLANE does not collide with deformables)"}, len(tets))
        r.update({"reference": ref,
                  "reference_name": "resting centroid height H/2 - rho g H^2/(3E) (uniaxial, "
                                    "frictionless ground)",
                  "resting_centroid_height": h, "error": c.rel_error(h, ref),
                  "centroid_rest_std": float(cz[rest].std()) if stable else None,
                  "peak_penetration": float(max(0.0, -minz.min())) if stable else None,
                  "resting_penetration": float(-minz[rest].mean()) if stable else None,
                  "peak_penetration_into_margin": float(max(0.0, margin - minz.min())) if stable else None,
                  "stable": stable})
        r.update(timer.fields())
        c.emit(r)


# ----------------------------------------------------------------------------
# Rigid box on a soft block (scene 5)
# ----------------------------------------------------------------------------
def scene_box_on_block(quick):
    resolutions = [(6, 6, 2)] if quick else [(6, 6, 2), (12, 12, 4)]
    dt, beta, t_end = 1 / 240, 0.01, 2.0
    bx, by, bz = c.BLOCK_SIZE
    hb = c.BOX_SIZE / 2
    for res in resolutions:
        new_world(dt)
        pts, tets = c.box_tet_mesh(res, c.BLOCK_SIZE, (-bx / 2, -by / 2, 0.0))
        body = add_soft(pts, tets, c.SOFT_E, c.SOFT_NU, c.SOFT_RHO, beta)
        pin(body, pts[:, 2] < 1e-9)
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[hb] * 3)
        box = p.createMultiBody(baseMass=c.BOX_MASS, baseCollisionShapeIndex=shape,
                                basePosition=[0, 0, bz + hb + 0.001])
        p.changeDynamics(box, -1, lateralFriction=0.5)
        top = (pts[:, 2] > bz - 1e-9) & (np.abs(pts[:, 0]) <= hb + 1e-9) & (np.abs(pts[:, 1]) <= hb + 1e-9)
        timer, zs, vz, pen, dent = c.Timer(), [], [], [], []
        stable = True
        for k in range(int(t_end / dt)):
            timer.step(p.stepSimulation)
            z = p.getBasePositionAndOrientation(box)[0][2]
            v = p.getBaseVelocity(box)[0][2]
            x = nodes(body)
            if not (finite(x, 100.0) and math.isfinite(z) and abs(z) < 100):
                stable = False
                break
            zs.append(z)
            vz.append(v)
            pen.append(float((x[top, 2] - (z - hb)).max()))
            dent.append(float((pts[top, 2] - x[top, 2]).mean()))
        rest = slice(-int(0.5 / dt), None)
        zs, vz, pen, dent = np.array(zs), np.array(vz), np.array(pen), np.array(dent)
        r = base_record("box_on_block", f"{res[0]}x{res[1]}x{res[2]} cubes", {
            "resolution": list(res), "tets_per_cube": 5, "dt": dt, "damping_beta": beta,
            "collision_margin": DEFAULT_MARGIN, "friction": 0.5, "E": c.SOFT_E, "nu": c.SOFT_NU,
            "block": list(c.BLOCK_SIZE), "block_support": "bottom face pinned",
            "box_size": c.BOX_SIZE, "box_mass": c.BOX_MASS, "duration_s": t_end}, len(tets))
        r.update({"reference": None, "error": None,
                  "sink": float(bz - (zs[rest].mean() - hb)) if stable else None,
                  "penetration": float(pen[rest].mean()) if stable else None,
                  "surface_sink": float(dent[rest].mean()) if stable else None,
                  "vertical_velocity_std": float(vz[rest].std()) if stable else None,
                  "stable": stable})
        r.update(timer.fields())
        c.emit(r)


# ----------------------------------------------------------------------------
# Scaling (scene 6)
# ----------------------------------------------------------------------------
def scene_scaling(quick):
    sizes = [6] if quick else [6, 8, 11, 14, 19, 24, 30]
    dt, beta = 1 / 240, 0.01
    predicted = 0.0
    for n in sizes:
        if predicted > c.SCALING_CASE_BUDGET_S:
            print(f"[scaling] stop before n={n}: predicted {predicted:.0f} s", file=sys.stderr)
            break
        w0 = time.perf_counter()
        new_world(dt)
        add_ground()
        s = c.DROP_SIZE
        pts, tets = c.box_tet_mesh((n, n, n), (s, s, s), (-s / 2, -s / 2, 0.001))
        body = add_soft(pts, tets, c.SOFT_E, c.SOFT_NU, c.SOFT_RHO, beta)
        setup = time.perf_counter() - w0
        timer = c.Timer()
        for _ in range(3):
            p.stepSimulation()
        t0 = time.perf_counter()
        while len(timer.cpu) < 20 and time.perf_counter() - t0 < 10.0:
            timer.step(p.stepSimulation)
        x = nodes(body)
        case_s = time.perf_counter() - w0
        r = base_record("scaling", f"{n}^3 cubes", {
            "resolution": [n, n, n], "tets_per_cube": 5, "dt": dt, "damping_beta": beta,
            "scene": "0.2 m cube E=1e5 resting on a box ground", "threads": 1}, len(tets))
        r.update({"reference": None, "error": None, "nodes": len(pts), "setup_s": setup,
                  "case_wall_s": case_s, "stable": finite(x, 100.0)})
        r.update(timer.fields())
        c.emit(r)
        growth = ((n + 5) / n) ** 3 if n == sizes[-1] else (sizes[min(sizes.index(n) + 1, len(sizes) - 1)] / n) ** 3
        predicted = case_s * growth


def main():
    args = c.parse_args(SCENES, __doc__.splitlines()[0])
    c.quiet_stdout()
    p.connect(p.DIRECT)
    for scene in SCENES:
        if scene in args.scenes:
            t0 = time.perf_counter()
            globals()[f"scene_{scene}"](args.quick)
            print(f"[{scene}] done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    p.disconnect()


if __name__ == "__main__":
    main()

"""MuJoCo 4.0 flex (flexcomp grid; dof full / trilinear / quadratic; integrator discrete)
on the scenes of issue 6. One JSON line per case on stdout; progress on stderr.

    benches/compare/.venv/bin/python benches/compare/mujoco_cases.py [--quick] [--scene NAME]

Setup pitfalls handled here (see shared notes/peers.md):
  * only the `discrete` (implicit) integrator accepts flex elasticity; Newton solver with
    1000 iterations (the default 100 warns every step);
  * flexcomp `mass` is split equally over the points and pinned points' share is dropped:
    for dof=full the vertex bodies get their dual-cell (lumped) masses rho * V_i instead;
    for trilinear/quadratic the node bodies keep MuJoCo's split, scaled so that the free
    nodes carry the body's whole mass rho * V;
  * `damping` in <elasticity> is a stiffness-proportional (Rayleigh) time.
"""
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common as c  # noqa: E402

import mujoco  # noqa: E402

SCENES = ("cantilever", "poisson", "vibration", "drop", "box_on_block", "scaling")
ENGINE = "mujoco"
VERSION = mujoco.__version__
SOLVER = {"integrator": "discrete", "solver": "Newton", "iterations": 1000}
SETTLE_BETA = 2 / (2 * math.pi * c.beam_eb_frequency())
FLEX_RADIUS = 0.002


def flexcomp_xml(name, cells, size, center, dof, E, nu, rho, beta, pin_axis=None, contact=True,
                 cellcount=None):
    """A flexcomp grid of cells[0] x cells[1] x cells[2] cells (6 tets each) of `size`,
    centred at `center`. pin_axis = (axis, 0) pins the points/nodes with coordinate 0 along
    that axis (the minimum face)."""
    count = [n + 1 for n in cells]
    spacing = [size[i] / cells[i] for i in range(3)]
    mass = rho * size[0] * size[1] * size[2]
    extra = ""
    pin = ""
    if dof in ("trilinear", "quadratic"):
        extra = f' cellcount="{cellcount[0]} {cellcount[1]} {cellcount[2]}"'
        order = 1 if dof == "trilinear" else 2
        top = [order * k for k in cellcount]
    else:
        top = cells
    if pin_axis is not None:
        hi = list(top)
        hi[pin_axis] = 0
        pin = f'<pin gridrange="0 0 0 {hi[0]} {hi[1]} {hi[2]}"/>'
    con = ('<contact condim="3" selfcollide="none" solref="0.002 1"/>' if contact
           else '<contact contype="0" conaffinity="0"/>')
    return f"""
    <flexcomp name="{name}" type="grid" dim="3" dof="{dof}"{extra} count="{count[0]} {count[1]} {count[2]}"
              spacing="{spacing[0]:.9g} {spacing[1]:.9g} {spacing[2]:.9g}"
              pos="{center[0]} {center[1]} {center[2]}" mass="{mass}" radius="{FLEX_RADIUS}">
      <elasticity young="{E}" poisson="{nu}" damping="{beta}"/>
      {con}
      {pin}
    </flexcomp>"""


def build(dt, body_xml, memory_mb, ground=False):
    g = '<geom name="ground" type="plane" size="5 5 0.1" friction="0.5"/>' if ground else ""
    xml = f"""
<mujoco>
  <option timestep="{dt}" integrator="{SOLVER['integrator']}" solver="{SOLVER['solver']}"
          iterations="{SOLVER['iterations']}" gravity="0 0 {-c.G}"/>
  <size memory="{memory_mb}M"/>
  <worldbody>
    {g}
    {body_xml}
  </worldbody>
</mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return m, d


def fix_masses(m, d, cells, size, rho, dof):
    """dof=full: vertex bodies get their lumped (dual-cell) mass; interpolated: node bodies
    scaled to a total of rho*V. Returns a description for the settings."""
    total = rho * size[0] * size[1] * size[2]
    if dof == "full":
        x0 = d.flexvert_xpos.copy()
        lo = x0.min(0)
        h = np.array([size[i] / cells[i] for i in range(3)])
        g = np.rint((x0 - lo) / h).astype(int)
        w = np.ones(len(x0))
        for a in range(3):
            w *= np.where((g[:, a] == 0) | (g[:, a] == cells[a]), 0.5, 1.0) * h[a]
        bodies = m.flex_vertbodyid[m.flex_vertadr[0]:m.flex_vertadr[0] + m.flex_vertnum[0]]
        for b, wi in zip(bodies, w):
            if b != 0:
                scale = rho * wi / m.body_mass[b]
                m.body_mass[b] *= scale
                m.body_inertia[b] *= scale
        how = "lumped: each vertex body gets rho times its dual-cell volume"
    else:
        bodies = m.flex_nodebodyid[m.flex_nodeadr[0]:m.flex_nodeadr[0] + m.flex_nodenum[0]]
        free = [b for b in bodies if b != 0]
        scale = total / m.body_mass[free].sum()
        m.body_mass[free] *= scale
        m.body_inertia[free] *= scale
        how = "MuJoCo's equal split over the nodes, scaled to rho*V on the free nodes"
    mujoco.mj_setConst(m, d)
    mujoco.mj_forward(m, d)
    return how


def memory_for(n_tets):
    return int(max(64, n_tets * 0.06))


def base_record(scene, case, settings, elements):
    s = {"engine": ENGINE, "engine_version": VERSION, "scene": scene, "case": case,
         "elements": int(elements), "settings": dict(settings, elements=int(elements), **SOLVER)}
    s["settings"].setdefault("model", "flex 3D elasticity (StVK-type, linear tets / interpolated cage)")
    return s


def discretization(dof, cells, cellcount):
    if dof == "full":
        return f"full {cells[0] + 1}x{cells[1] + 1}x{cells[2] + 1} vertices"
    return f"{dof} cage {cellcount[0]}x{cellcount[1]}x{cellcount[2]} cells"


def timed_step(m, d):
    return lambda: mujoco.mj_step(m, d)


def warnings(d):
    """MuJoCo's warning counters that fired during the case (e.g. an unconverged M+K solve)."""
    out = {}
    for name in dir(mujoco.mjtWarning):
        if name.startswith("mjWARN_"):
            n = int(d.warning[int(getattr(mujoco.mjtWarning, name))].number)
            if n > 0:
                out[name] = n
    return out


def finite(x, limit):
    return bool(np.all(np.isfinite(x)) and np.max(np.abs(x)) < limit)


# ----------------------------------------------------------------------------
# Cantilever (scenes 1-3)
# ----------------------------------------------------------------------------
BEAM_SIZE = (c.BEAM_L, c.BEAM_B, c.BEAM_H)
BEAM_CENTER = (c.BEAM_L / 2, 0.0, 1.05)


def run_beam(dof, cells, cellcount, dt, nu, beta, t_end):
    xml = flexcomp_xml("beam", cells, BEAM_SIZE, BEAM_CENTER, dof, c.BEAM_E, nu, c.BEAM_RHO, beta,
                       pin_axis=0, contact=False, cellcount=cellcount)
    n_est = 6 * cells[0] * cells[1] * cells[2]
    m, d = build(dt, xml, memory_for(n_est))
    how = fix_masses(m, d, cells, BEAM_SIZE, c.BEAM_RHO, dof)
    x0 = d.flexvert_xpos.copy()
    tip = x0[:, 0] > x0[:, 0].max() - 1e-9
    timer, ts, us = c.Timer(), [], []
    stable = True
    step = timed_step(m, d)
    for k in range(int(round(t_end / dt))):
        timer.step(step)
        x = d.flexvert_xpos
        if not finite(x, 100.0):
            stable = False
            break
        ts.append((k + 1) * dt)
        us.append(float((x[tip, 2] - x0[tip, 2]).mean()))
    info = {"dofs": int(m.nv), "mass_lumping": how, "flex_radius": FLEX_RADIUS,
            "engine_warnings": warnings(d)}
    return int(m.flex_elemnum[0]), np.array(ts), np.array(us), timer, stable, info


BEAM_CASES_FULL = [("full", (10, 1, 1), None), ("full", (20, 2, 2), None), ("full", (40, 4, 4), None)]
BEAM_CASES_INTERP = [("trilinear", (20, 2, 2), (10, 1, 1)), ("trilinear", (20, 2, 2), (20, 2, 2)),
                     ("quadratic", (20, 2, 2), (5, 1, 1)), ("quadratic", (20, 2, 2), (10, 1, 1))]


def static_case(scene, dof, cells, cellcount, dt, nu, settle=1.5):
    n_el, ts, us, timer, stable, info = run_beam(dof, cells, cellcount, dt, nu, SETTLE_BETA, settle)
    ref = c.beam_timoshenko_tip(nu=nu)
    tail = us[ts > settle - 0.25] if stable else us
    tip = -float(tail.mean()) if stable and len(tail) else None
    drift = float(abs(tail[-1] - tail[0])) if stable and len(tail) > 1 else None
    if tip is not None and not (0.0 < tip < 10 * ref):
        stable = False  # moved against gravity or ran away: not a physical equilibrium
    disc = discretization(dof, cells, cellcount)
    r = base_record(scene, f"{disc} dt=1/{round(1 / dt)} nu={nu}", dict({
        "dof": dof, "resolution": [k + 1 for k in cells], "resolution_is": "vertices per axis",
        "cellcount": list(cellcount) if cellcount else None, "dt": dt, "nu": nu, "E": c.BEAM_E,
        "damping_beta": SETTLE_BETA, "settle_s": settle,
        "settling": "stiffness-proportional damping beta = 2/omega_1 (first mode critically "
                    "damped), tip averaged over the last 0.25 s"}, **info), n_el)
    r.update({"reference": ref, "reference_name": "Timoshenko q L^4/(8EI) + q L^2/(2 kappa G A), "
              "kappa = 10(1+nu)/(12+11nu)", "reference_euler_bernoulli": c.beam_eb_tip(),
              "tip_deflection": tip, "error": c.rel_error(tip, ref) if stable else None,
              "error_vs_euler_bernoulli": c.rel_error(tip, c.beam_eb_tip()) if stable else None,
              "tip_drift_last_0_25s": drift, "engine_warnings": info["engine_warnings"],
              "settled": bool(drift is not None and drift < 0.01 * ref),
              "stable": stable})
    r.update(timer.fields())
    c.emit(r)


def scene_cantilever(quick):
    cases = [BEAM_CASES_FULL[0], BEAM_CASES_INTERP[2]] if quick else BEAM_CASES_FULL + BEAM_CASES_INTERP
    for dt in (1 / 240, 1 / 60):
        for dof, cells, cellcount in cases:
            static_case("cantilever", dof, cells, cellcount, dt, c.BEAM_NU)


def scene_poisson(quick):
    cases = [BEAM_CASES_FULL[0]] if quick else [BEAM_CASES_FULL[1], BEAM_CASES_INTERP[2]]
    for dof, cells, cellcount in cases:
        for nu in c.POISSON_SWEEP:
            static_case("poisson", dof, cells, cellcount, 1 / 240, nu)


def scene_vibration(quick):
    f_t, _ = c.beam_timoshenko_frequency()
    cases = [BEAM_CASES_INTERP[2]] if quick else [BEAM_CASES_FULL[1], BEAM_CASES_INTERP[2]]
    dts = [1 / 240] if quick else [1 / 1000, 1 / 240, 1 / 60]
    for dof, cells, cellcount in cases:
        for dt in dts:
            n_el, ts, us, timer, stable, info = run_beam(dof, cells, cellcount, dt, c.BEAM_NU, 0.0, 2.0)
            fit = c.fit_damped_oscillation(ts, us) if stable else None
            freq = fit["frequency_hz"] if fit else None
            disc = discretization(dof, cells, cellcount)
            r = base_record("vibration", f"{disc} dt=1/{round(1 / dt)}", dict({
                "dof": dof, "resolution": [k + 1 for k in cells], "cellcount": list(cellcount) if cellcount else None,
                "dt": dt, "damping_beta": 0.0, "duration_s": 2.0,
                "excitation": "released straight under gravity (oscillates about the static "
                              "deflection)"}, **info), n_el)
            r.update({"reference": f_t,
                      "reference_name": "Timoshenko first bending frequency (shear + rotary "
                                        "inertia, 400-element solve); Euler-Bernoulli "
                                        "(1.8751^2/(2 pi L^2)) sqrt(EI/(rho A))",
                      "reference_euler_bernoulli": c.beam_eb_frequency(),
                      "first_frequency_hz": freq, "error": c.rel_error(freq, f_t),
                      "damping_ratio": fit["damping_ratio"] if fit else None,
                      "numerical_damping_ratio": fit["damping_ratio"] if fit else None,
                      "damping_ratio_omega_dt_over_2": 2 * math.pi * f_t * dt / 2,
                      "fit": fit, "stable": stable and fit is not None})
            r.update(timer.fields())
            c.emit(r)


# ----------------------------------------------------------------------------
# Drop (scene 4)
# ----------------------------------------------------------------------------
def scene_drop(quick):
    cases = [("full", (4, 4, 4), None)] if quick else [
        ("full", (4, 4, 4), None), ("full", (8, 8, 8), None),
        ("trilinear", (8, 8, 8), (1, 1, 1)), ("quadratic", (8, 8, 8), (1, 1, 1))]
    dt, beta, t_end = 1 / 240, 0.01, 2.5
    s = c.DROP_SIZE
    ref = c.drop_rest_centroid()
    for dof, cells, cellcount in cases:
        xml = flexcomp_xml("cube", cells, (s, s, s), (0, 0, c.DROP_HEIGHT + s / 2), dof, c.SOFT_E,
                           c.SOFT_NU, c.SOFT_RHO, beta, cellcount=cellcount)
        m, d = build(dt, xml, memory_for(6 * np.prod(cells)), ground=True)
        how = fix_masses(m, d, cells, (s, s, s), c.SOFT_RHO, dof)
        timer, minz, cz = c.Timer(), [], []
        stable = True
        step = timed_step(m, d)
        for k in range(int(t_end / dt)):
            timer.step(step)
            x = d.flexvert_xpos
            if not finite(x, 100.0):
                stable = False
                break
            minz.append(x[:, 2].min())
            cz.append(x[:, 2].mean())
        minz, cz = np.array(minz), np.array(cz)
        rest = slice(-int(0.5 / dt), None)
        h = float(cz[rest].mean()) if stable else None
        r = base_record("drop", f"{discretization(dof, cells, cellcount)}", {
            "dof": dof, "resolution": [k + 1 for k in cells], "cellcount": list(cellcount) if cellcount else None,
            "dt": dt, "damping_beta": beta, "flex_radius": FLEX_RADIUS, "contact_solref": [0.002, 1],
            "friction": 0.5, "E": c.SOFT_E, "nu": c.SOFT_NU, "drop_height_bottom": c.DROP_HEIGHT,
            "duration_s": t_end, "ground": "plane", "dofs": int(m.nv), "mass_lumping": how},
            m.flex_elemnum[0])
        r.update({"reference": ref,
                  "reference_name": "resting centroid height H/2 - rho g H^2/(3E) (uniaxial, "
                                    "frictionless ground)",
                  "resting_centroid_height": h, "error": c.rel_error(h, ref),
                  "centroid_rest_std": float(cz[rest].std()) if stable else None,
                  "peak_penetration": float(max(0.0, -minz.min())) if stable else None,
                  "resting_penetration": float(-minz[rest].mean()) if stable else None,
                  "stable": stable})
        r.update(timer.fields())
        c.emit(r)


# ----------------------------------------------------------------------------
# Rigid box on a soft block (scene 5)
# ----------------------------------------------------------------------------
def scene_box_on_block(quick):
    cases = [(6, 6, 2)] if quick else [(6, 6, 2), (12, 12, 4)]
    dt, beta, t_end = 1 / 240, 0.01, 2.0
    bx, by, bz = c.BLOCK_SIZE
    hb = c.BOX_SIZE / 2
    for cells in cases:
        box = (f'<body name="box" pos="0 0 {bz + hb + 0.001}"><freejoint/>'
               f'<geom type="box" size="{hb} {hb} {hb}" mass="{c.BOX_MASS}" friction="0.5"/></body>')
        xml = flexcomp_xml("block", cells, c.BLOCK_SIZE, (0, 0, bz / 2), "full", c.SOFT_E, c.SOFT_NU,
                           c.SOFT_RHO, beta, pin_axis=2) + box
        m, d = build(dt, xml, memory_for(6 * np.prod(cells)))
        how = fix_masses(m, d, cells, c.BLOCK_SIZE, c.SOFT_RHO, "full")
        bid = m.body("box").id
        jadr = m.jnt_dofadr[m.body_jntadr[bid]]
        x0 = d.flexvert_xpos.copy()
        top = (x0[:, 2] > x0[:, 2].max() - 1e-9) & (np.abs(x0[:, 0]) <= hb + 1e-9) & (np.abs(x0[:, 1]) <= hb + 1e-9)
        timer, zs, vz, pen, dent = c.Timer(), [], [], [], []
        stable = True
        step = timed_step(m, d)
        for k in range(int(t_end / dt)):
            timer.step(step)
            z = float(d.xpos[bid, 2])
            x = d.flexvert_xpos
            if not (finite(x, 100.0) and math.isfinite(z) and abs(z) < 100):
                stable = False
                break
            zs.append(z)
            vz.append(float(d.qvel[jadr + 2]))
            pen.append(float((x[top, 2] - (z - hb)).max()))
            dent.append(float((x0[top, 2] - x[top, 2]).mean()))
        rest = slice(-int(0.5 / dt), None)
        zs, vz, pen, dent = np.array(zs), np.array(vz), np.array(pen), np.array(dent)
        r = base_record("box_on_block", f"full {cells[0] + 1}x{cells[1] + 1}x{cells[2] + 1} vertices", {
            "dof": "full", "resolution": [k + 1 for k in cells], "dt": dt, "damping_beta": beta,
            "flex_radius": FLEX_RADIUS, "contact_solref": [0.002, 1], "friction": 0.5,
            "E": c.SOFT_E, "nu": c.SOFT_NU, "block": list(c.BLOCK_SIZE),
            "block_support": "bottom face pinned", "box_size": c.BOX_SIZE, "box_mass": c.BOX_MASS,
            "duration_s": t_end, "dofs": int(m.nv), "mass_lumping": how}, m.flex_elemnum[0])
        r.update({"reference": None, "error": None,
                  "sink": float(bz - (zs[rest].mean() - hb)) if stable else None,
                  "penetration": float(pen[rest].mean()) if stable else None,
                  "surface_sink": float(dent[rest].mean()) if stable else None,
                  "vertical_velocity_std": float(vz[rest].std()) if stable else None,
                  "engine_warnings": warnings(d), "stable": stable})
        r.update(timer.fields())
        c.emit(r)


# ----------------------------------------------------------------------------
# Scaling (scene 6)
# ----------------------------------------------------------------------------
def scene_scaling(quick):
    sizes = [6] if quick else [6, 8, 11, 14, 19, 24, 28]
    dt, beta = 1 / 240, 0.01
    s = c.DROP_SIZE
    predicted = 0.0
    for i, n in enumerate(sizes):
        if predicted > c.SCALING_CASE_BUDGET_S:
            print(f"[scaling] stop before n={n}: predicted {predicted:.0f} s", file=sys.stderr)
            break
        w0 = time.perf_counter()
        xml = flexcomp_xml("cube", (n, n, n), (s, s, s), (0, 0, s / 2 + 0.001), "full", c.SOFT_E,
                           c.SOFT_NU, c.SOFT_RHO, beta)
        m, d = build(dt, xml, memory_for(6 * n**3), ground=True)
        fix_masses(m, d, (n, n, n), (s, s, s), c.SOFT_RHO, "full")
        setup = time.perf_counter() - w0
        for _ in range(3):
            mujoco.mj_step(m, d)
        timer = c.Timer()
        step = timed_step(m, d)
        t0 = time.perf_counter()
        while len(timer.cpu) < 20 and time.perf_counter() - t0 < 10.0:
            timer.step(step)
        case_s = time.perf_counter() - w0
        r = base_record("scaling", f"full {n + 1}^3 vertices", {
            "dof": "full", "resolution": [n + 1] * 3, "dt": dt, "damping_beta": beta,
            "scene": "0.2 m cube E=1e5 resting on a plane", "threads": 1, "dofs": int(m.nv)},
            m.flex_elemnum[0])
        r.update({"reference": None, "error": None, "nodes": int(m.flex_vertnum[0]),
                  "setup_s": setup, "case_wall_s": case_s, "stable": finite(d.flexvert_xpos, 100.0)})
        r.update(timer.fields())
        c.emit(r)
        nxt = sizes[i + 1] if i + 1 < len(sizes) else n
        predicted = case_s * (nxt / n) ** 3


def main():
    args = c.parse_args(SCENES, __doc__.splitlines()[0])
    c.quiet_stdout()
    for scene in SCENES:
        if scene in args.scenes:
            t0 = time.perf_counter()
            globals()[f"scene_{scene}"](args.quick)
            print(f"[{scene}] done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()

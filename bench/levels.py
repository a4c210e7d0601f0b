"""The hierarchy measured (docs/hierarchy.md): each level's cost per set, its error against
the next exact level over the issue's spreads (error maps), the selector's speed goals,
and the figure of the level the selector picks along a sweep.

`python -m bench.levels` (one core): writes bench/results/levels.json, one error-map
figure per approximate level (levels_error_<level>.png: measured error against its bound)
and one scene figure per model with a hierarchy (scene_<model>.png, its data in
scenes.json). `--quick` for a smaller run; `--scenes [MODEL ...]` for the scene figures alone;
`--torsion-motion` for the torsion gyrocompass's motion map alone (levels.json
'torsion_motion_map', levels_error_linear_motion.png).
`--ghc-motion` for the gyrohorizoncompass's motion levels alone (their costs, the linear
level's error map and the points toward its cap, levels_error_gyrohorizoncompass_linear.png),
into levels.json.

Spreads (torsion gyrocompass, each about the paper example): spin H, the bearing
stiffnesses K0, Kp, K_gamma one at a time 0.1x..10x, latitude 0..89 deg, delta_b from 0
(l1 = l2, l_c kept) to 4x the example's, and a joint random spread of all of them.
"""
from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"  # one core: set before NumPy loads its BLAS

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from gyro import ladder  # noqa: E402
from gyro import levels as hierarchy  # noqa: E402
from gyro import questions  # noqa: E402
from gyro.analyses.scene import level_error, select  # noqa: E402
from gyro.analyses.scene import rungs as scene_rungs  # noqa: E402
from gyro.models import load  # noqa: E402
from gyro.questions import frequencies as F  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
TG = load("torsion_gyrocompass")
APPROXIMATE = ("formulas", "quartic", "decoupled", "linear_paper", "linear_exact:companion", "linear_exact:polyroots")
GOALS = {"modes_1e-3_speedup": 100.0, "all_1e-3_speedup": 3.0, "tol_1e-9_slowdown": 1.2,
         "million_sets_1e-3_s": 60.0, "selector_overhead": 0.10}
TOLS = (1e-2, 1e-5, 1e-9)
TM_HORIZON = 0.05  # s: the torsion gyrocompass's motion map (some 30 periods of its fastest nutation)


def _ix(name):
    return TG.param_names.index(name)


def with_delta_b(P: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """l1, l2 moved so that l2 - l1 is `factor` times the example's, l_c kept (delta_b ~ factor^2)."""
    P = P.copy()
    m, M, l1, l2 = (P[:, _ix(k)] for k in ("m", "M", "l1", "l2"))
    lc = (m * l2 + M * l1) / (m + M)
    d = factor * (l2 - l1)
    P[:, _ix("l1")], P[:, _ix("l2")] = lc - m * d / (m + M), lc + M * d / (m + M)
    return P


def spreads(points: int) -> dict:
    p0 = TG.vector()
    s = np.geomspace(0.1, 10.0, points)
    out = {}
    for name, label in (("H", "spin"), ("K0", "K0"), ("Kp", "Kp"), ("Kgamma", "K_gamma")):
        P = np.tile(p0, (points, 1))
        P[:, _ix(name)] *= s
        out[f"{label} 0.1x..10x"] = (P, s)
    P = np.tile(p0, (points, 1))
    P[:, _ix("phi")] = np.linspace(0.0, 89.0, points)
    out["latitude 0..89 deg"] = (P, P[:, _ix("phi")])
    f = np.linspace(0.0, 4.0, points)
    out["delta_b 0..16x (l2 - l1 0..4x)"] = (with_delta_b(np.tile(p0, (points, 1)), f), f)
    return out


def joint(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    P = np.tile(TG.vector(), (n, 1))
    for name in ("H", "K0", "Kp", "Kgamma"):
        P[:, _ix(name)] *= np.exp(rng.uniform(np.log(0.1), np.log(10.0), n))
    P[:, _ix("phi")] = rng.uniform(0.0, 89.0, n)
    return with_delta_b(P, rng.uniform(0.0, 4.0, n))


def per_set(fn, n: int, repeats: int = 3) -> float:
    """Median seconds per set of fn() over a batch of n sets."""
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts)) / n


# ------------------------------------------------------------------ costs


def costs(quick: bool) -> dict:
    p0 = TG.vector()
    batch = {"formulas": 200_000, "quartic": 20_000, "decoupled": 20_000, "linear_paper": 20_000, "linear_exact:companion": 5000,
             "linear_exact:default": 20_000, "linear_exact:polyroots": 100, "linear_exact:reference": 2}
    if quick:
        batch = {k: max(1, v // 10) for k, v in batch.items()}
    out = {}
    for name, n in batch.items():
        lv = hierarchy.get(TG, name)
        P = np.tile(p0, (n, 1))
        F.answer(TG, lv, P[:2], {})  # warm: the compiled code loaded
        out[name] = {"s_per_set": per_set(lambda: F.answer(TG, lv, P, {}), n, 1 if n < 10 else 3),
                     "declared": lv.cost, "batch": n}
    gm = load("gimbal_gyroscope")
    from gyro.questions import motion

    opts = {"horizon": 1.0}
    for lv in hierarchy.levels(gm):
        if quick and lv.name.endswith("Radau"):
            continue
        P = gm.vector()[None, :]
        motion.answer(gm, lv, P, opts)
        out[f"gimbal_gyroscope {lv.name}"] = {"s_per_set": per_set(lambda: motion.answer(gm, lv, P, opts), 1, 1),
                                              "declared": lv.cost, "batch": 1, "horizon_s": 1.0}
    return out


# ------------------------------------------------------------------ error maps


def error_maps(quick: bool) -> tuple[dict, dict]:
    points = 13 if quick else 41
    sp = spreads(points)
    P_joint = joint(1000 if quick else 5000, seed=7)
    stats, samples = {}, {}
    cases = [*sp.items(), ("joint random", (P_joint, None))]
    refs = {label: F.answer(TG, hierarchy.get(TG, "linear_exact:default"), P, {}) for label, (P, _) in cases}
    for name in APPROXIMATE:
        lv = hierarchy.get(TG, name)
        rows, errs, bounds = {}, [], []
        for label, (P, _) in cases:
            ref = refs[label]
            if name.endswith("polyroots") and label == "joint random":
                P, ref = P[:200], ref.take(slice(0, 200))
            ans = F.answer(TG, lv, P, {})
            err = F.error(ans, ref)
            err[(ans.failed != "") | (ref.failed != "")] = np.nan
            B = hierarchy.bounds(TG, lv, "frequencies", P, err.shape[1])
            bound = B.total(ans.estimate)
            trusted = np.isfinite(bound) & (F.edges(TG, ans, bound, range(bound.shape[1]), B.answered) == "")[:, None]
            with np.errstate(all="ignore"):
                ratio = np.where(trusted, err / bound, np.nan)
                loose = np.where(trusted & (err > 0), bound / err, np.nan)
                med = np.array([np.median(c[np.isfinite(c)]) if np.isfinite(c).any() else np.nan for c in loose.T])
            rows[label] = {
                "max_error_per_mode": [None if not (np.isfinite(x) and x >= 0) else float(x)
                                       for x in np.nanmax(np.where(np.isfinite(err), err, -1.0), axis=0)],
                "max_error_over_bound": float(np.nanmax(ratio)) if np.isfinite(ratio).any() else None,
                "median_bound_over_error_per_mode": [None if not np.isfinite(x) else float(x) for x in med],
                "trusted_fraction": float(trusted.mean()),
                "beaten": int(np.sum(err[trusted] > bound[trusted] + 1e-10)),
            }
            errs.append(np.where(trusted, err, np.nan))
            bounds.append(np.where(trusted, bound, np.nan))
        stats[name] = rows
        samples[name] = (np.concatenate(errs), np.concatenate(bounds))
    # the exact operator's default method against the 40-digit reference (a few sets per spread)
    rows = {}
    for label, (P, _) in sp.items():
        Pk = P[:: max(1, len(P) // (3 if quick else 5))]
        err, bound = level_error(TG, "frequencies", "linear_exact:default", "linear_exact:reference", Pk)
        rows[label] = {"max_error": float(np.nanmax(err)), "max_error_over_bound": float(np.nanmax(err / bound)),
                       "beaten": int(np.sum(err > bound))}
    stats["linear_exact:default"] = rows
    return stats, samples


def gimbal_map(quick: bool) -> dict:
    """The closed form against DOP853 (rtol 1e-10 and 1e-12) over horizons and spins."""
    gm = load("gimbal_gyroscope")
    out = []
    for horizon in ((0.5,) if quick else (0.5, 2.0)):
        for dphi0 in ((200.0,) if quick else (50.0, 200.0, 800.0)):
            opts = {"horizon": horizon, "points": 101, "initial": {"dphi0": dphi0, "dtheta0": 3.0}}
            err, bound = level_error(gm, "motion", "closed_form", "integrated:DOP853", gm.vector()[None, :], opts)
            _, ref_bound = level_error(gm, "motion", "integrated:DOP853", "closed_form", gm.vector()[None, :], opts)
            out.append({"horizon": horizon, "dphi0": dphi0, "error": [float(x) for x in err[0]],
                        "closed_form_bound": [float(x) for x in bound[0]],
                        "integrator_bound": [float(x) for x in ref_bound[0]],
                        "held": bool(np.all(err <= bound + ref_bound))})
    return {"closed_form vs integrated:DOP853": out}


def torsion_motion_map(quick: bool) -> dict:
    """The torsion gyrocompass's linear motion against the integrated full equations over a
    horizon of TM_HORIZON s: the perturbation's amplitude (the casing's tilt gamma, its tilt
    rate beta' about the other axis, the rotor's shift x1) from tiny to where the
    linearisation fails (and points toward the linear bound's cap), and at the
    rotor tilted by 1 mrad (gamma1) spin, K0, Kp, K_gamma 0.1x..10x and latitude 0..89 deg.
    Per point each coordinate's error, the linear level's bound and the integrator's own,
    and each level's seconds."""
    from gyro.systems import torsion_gyrocompass as tm
    from gyro.questions import motion

    lin, full = hierarchy.get(TG, "linear_motion"), hierarchy.get(TG, "nonlinear_motion")
    n = 3 if quick else 7
    cases = []
    for key, lo, hi in (("gamma_0", 1e-8, 1.0), ("beta_d0", 1e-6, 100.0), ("x1_0", 1e-10, 0.03)):
        for a in np.geomspace(lo, hi, n + 2):
            cases.append((f"amplitude {key}", key, float(a), {}, float(a)))
    for key, amps in (("gamma_0", (0.2, 0.3, 0.45, 0.6)), ("beta_d0", (3.0, 10.0, 30.0))):
        for a in amps:  # toward the cap of the linear bound (gyro.systems.torsion_gyrocompass.CAP)
            cases.append((f"near the cap {key}", key, a, {}, a))
    base = ("gamma1_0", 1e-3)
    for name in ("H", "K0", "Kp", "Kgamma"):
        for f in np.geomspace(0.1, 10.0, n if name == "H" else max(3, n // 2)):
            cases.append((f"{name} 0.1x..10x", *base, {name: float(f * TG.defaults[name])}, float(f)))
    for phi in np.linspace(0.0, 89.0, max(3, n // 2)):
        cases.append(("latitude 0..89 deg", *base, {"phi": float(phi)}, float(phi)))
    points = []
    for spread, key, a, values, x in cases:
        opts = {"horizon": TM_HORIZON, "initial": {"gamma1_0": 0.0, key: a}}
        P = TG.vector(values)[None, :]
        t0 = time.perf_counter()
        al = motion.answer(TG, lin, P, opts)
        t1 = time.perf_counter()
        an = motion.answer(TG, full, P, opts)
        t2 = time.perf_counter()
        err = motion.error(al, an)[0]
        # the linear estimate without its cap, over its own scale as the selector takes it (the
        # cap's evidence)
        mo = tm.Motion(dict(zip(TG.param_names, map(float, P[0]))), **opts["initial"])
        uncapped = tm.linear_answer(mo, motion.times(opts), cap=np.inf)[1] / al.extra["scale"][0]
        points.append({"spread": spread, "x": x, "initial": {key: a}, "values": values,
                       "error": [float(v) for v in err], "bound": [float(v) for v in al.estimate[0]],
                       "uncapped_bound": [float(v) for v in uncapped],
                       "integrator_bound": [float(v) for v in an.estimate[0]],
                       "seconds": {"linear_motion": t1 - t0, "nonlinear_motion": t2 - t1}})
        print(f"torsion motion {spread} {x:.3g}: error {np.max(err):.2e}, bound {np.max(al.estimate):.2e}, "
              f"integrator {np.max(an.estimate):.2e}; {t1 - t0:.2f} s, {t2 - t1:.1f} s", flush=True)
    e = np.array([p["error"] for p in points])
    b = np.array([p["bound"] for p in points])
    bn = np.array([p["integrator_bound"] for p in points])
    # where the integrator's own estimate is a tenth of the error or less, and the bound finite
    resolved = (e > 10 * bn) & np.isfinite(b)
    with np.errstate(all="ignore"):
        ratio = np.where(resolved, e / b, np.nan)
        loose = np.where(resolved, b / e, np.nan)
    sec = {k: [p["seconds"][k] for p in points] for k in ("linear_motion", "nonlinear_motion")}
    bu = np.array([p["uncapped_bound"] for p in points])
    order = np.argsort(bu.max(axis=1))
    cap = [{"uncapped_bound": float(bu[k].max()), "error_over_uncapped_bound": float(np.max(e[k] / bu[k]))}
           for k in order if bu[k].max() > 0.01 and np.isfinite(bu[k].max())]
    return {"horizon_s": TM_HORIZON, "points": points,
            "held": bool(np.all(e <= b + bn)),  # every point: the error within both levels' bounds
            "max_error_over_bound_resolved": float(np.nanmax(ratio)),
            "min_error_over_bound_resolved_worst_coordinate": float(np.nanmin(np.nanmax(ratio[resolved.any(axis=1)],
                                                                                        axis=1))),
            "bound_infinite_points": int(np.sum(~np.isfinite(b).all(axis=1))),
            "median_bound_over_error_per_coordinate": [float(np.nanmedian(c)) for c in loose.T],
            "error_range": [float(np.min(e.max(axis=1))), float(np.max(e.max(axis=1)))],
            "cap": tm.CAP, "toward_the_cap": cap,
            "seconds_median": {k: float(np.median(v)) for k, v in sec.items()},
            "seconds_range": {k: [float(min(v)), float(max(v))] for k, v in sec.items()},
            "declared": {k: hierarchy.get(TG, k).cost for k in sec}}


def torsion_motion_figure(data: dict) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.8))
    spreads_ = sorted({p["spread"] for p in data["points"]})
    for i, name in enumerate(spreads_):
        pts = [p for p in data["points"] if p["spread"] == name]
        e, b, bn = (np.array([p[k] for p in pts]).ravel() for k in ("error", "bound", "integrator_bound"))
        shown = (e > 0) & (b > 0) & np.isfinite(b)
        ok = shown & (e > 10 * bn)  # resolved: the integrator's estimate a tenth of the error or less
        ax.loglog(b[ok], e[ok], "o", ms=3, alpha=0.6, color=f"C{i}", label=name)
        ax.loglog(b[shown & ~ok], e[shown & ~ok], "x", ms=3, alpha=0.4, color=f"C{i}")
    ax.plot([], [], "kx", ms=3, label="not resolved (integrator's estimate > error/10)")
    allb = np.array([p["bound"] for p in data["points"]]).ravel()
    allb = allb[np.isfinite(allb) & (allb > 0)]
    lo, hi = allb.min(), allb.max()
    ax.loglog([lo, hi], [lo, hi], "k-", lw=1, label="error = bound")
    ax.loglog([lo, hi], [lo / 100, hi / 100], "k:", lw=1, label="bound 100x loose")
    ax.set_xlabel("linear_motion's bound (relative, per coordinate)")
    ax.set_ylabel("its error against nonlinear_motion")
    ax.set_title(f"torsion_gyrocompass, motion over {data['horizon_s']} s: linear_motion\n"
                 "(the ten reduced coordinates of each point)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = RESULTS / "levels_error_linear_motion.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.name


# ------------------------------------------------------------------ the gyrohorizoncompass's motions

GHC = "gyrohorizoncompass"
GHC_LAB = {"A": 1.0, "B": 1.05, "C": 1.1, "J": 1.0, "L": 0.5, "I": 1.0, "nu": 1.0, "zeta": 0.5, "eta": 0.2,
           "lam": 1.05}  # docs/gyrohorizoncompass.md's laboratory set (modes 0.35..1.0 rad/s)
GHC_ANGLES = ("alpha0", "beta0", "gamma0", "delta_epsilon0")
GHC_RATES = ("dalpha0", "dbeta0", "dgamma0", "depsilon0")


def ghc_motion_cases(quick: bool) -> list:
    """(spread, base, x, P (1, parameters), options) per point of the linear motion level's
    error map: the perturbation's amplitude a (the four angles at a, at rest) from 1e-6
    rad to where the linearisation fails, on the Earth set over 2 s (the nutation modes,
    104 and 220 rad/s; the Schuler-like ones hardly move) and on the laboratory set over
    20 s (about one period of its slowest mode); and at a = 1e-2 rad the laboratory set's
    spin L, Schuler frequency nu, speed zeta = v/R each 0.1x..10x, the latitude of the
    Darboux rate (zeta, eta) = w (cos phi, sin phi) 0..89 deg, and the Earth set's L and
    zeta 0.1x..10x (where the equilibrium (3.1) exists: I lambda zeta/2L < 1); and a joint
    random spread of the laboratory set's parameters and the perturbation's direction."""
    m = load(GHC)
    names = m.param_names
    earth = dict(zip(names, m.vector()))
    na = 6 if quick else 13
    npar = 5 if quick else 9
    out = []

    def add(spread, base_name, base, x, horizon, a=1e-2, init=None, **change):
        v = dict(base)
        v.update(change)
        init = {k: a for k in GHC_ANGLES} if init is None else init
        out.append((spread, base_name, float(x), m.vector(v)[None, :], {"horizon": horizon, "initial": init}))

    for base_name, base, horizon in (("Earth", earth, 2.0), ("laboratory", GHC_LAB, 20.0)):
        for a in np.geomspace(1e-6, 0.5, na):
            add("amplitude a (rad)", base_name, base, a, horizon, a=a)
    f = np.geomspace(0.1, 10.0, npar)
    for k in f:
        for name in ("L", "nu", "zeta"):
            add(f"{name} 0.1x..10x", "laboratory", GHC_LAB, k, 20.0, **{name: GHC_LAB[name] * k})
    w = np.hypot(GHC_LAB["zeta"], GHC_LAB["eta"])
    for phi in np.linspace(0.0, 89.0, npar):
        add("latitude 0..89 deg", "laboratory", GHC_LAB, phi, 20.0,
            zeta=w * np.cos(np.radians(phi)), eta=w * np.sin(np.radians(phi)))
    for k in f:
        for name in ("L", "zeta"):
            add(f"{name} 0.1x..10x", "Earth", earth, k, 2.0, **{name: earth[name] * k})
    # jointly: L, nu, zeta 0.3x..3x, the latitude, and a perturbation of angles and rates in
    # a random direction, amplitude 1e-5..0.1 (rad, rad/s)
    rng = np.random.default_rng(5)
    for _ in range(8 if quick else 24):
        fL, fn, fz = np.exp(rng.uniform(np.log(0.3), np.log(3.0), 3))
        phi = np.radians(rng.uniform(0.0, 89.0))
        u = rng.normal(size=8)
        a = float(np.exp(rng.uniform(np.log(1e-5), np.log(0.1))))
        add("joint random", "laboratory", GHC_LAB, a, 20.0,
            init=dict(zip(GHC_ANGLES + GHC_RATES, (a * u / np.max(np.abs(u))).tolist())),
            L=GHC_LAB["L"] * fL, nu=GHC_LAB["nu"] * fn, zeta=w * fz * np.cos(phi), eta=w * fz * np.sin(phi))
    return out


def ghc_motion_map(quick: bool) -> tuple[dict, dict]:
    """The linear motion level against integrated:DOP853 over `ghc_motion_cases`: per point
    and coordinate the measured relative error, the linear bound and the reference's own
    bound (an error counts as beaten where it exceeds the sum of both: at tiny amplitudes
    the reference's truncation is of the size of the linear error)."""
    from gyro.questions import motion

    m = load(GHC)
    lin, ref = hierarchy.get(m, "linear"), hierarchy.get(m, "integrated:DOP853")
    rows, samples = [], {}
    for spread, base, x, P, opts in ghc_motion_cases(quick):
        t0 = time.perf_counter()
        a = motion.answer(m, lin, P, opts)
        t1 = time.perf_counter()
        r = motion.answer(m, ref, P, opts)
        t2 = time.perf_counter()
        err = motion.error(a, r)[0]
        bound = hierarchy.bounds(m, lin, "motion", P, err.size).total(a.estimate)[0]
        rbound = hierarchy.bounds(m, ref, "motion", P, err.size).total(r.estimate)[0]
        why = a.failed[0] or r.failed[0]
        rows.append({"spread": spread, "base": base, "x": x, "failed": why or None,
                     "error": [float(e) for e in err], "bound": [float(b) for b in bound],
                     "reference_bound": [float(b) for b in rbound],
                     "linear_s": t1 - t0, "reference_s": t2 - t1})
        if not why:
            rows[-1].update(_ghc_uncapped(m, P, opts, a.extra["scale"][0]))
        if not why:
            samples.setdefault(f"{spread}, {base}", []).append((err, bound))
    fin = [(np.array(r["error"]), np.array(r["bound"]), np.array(r["reference_bound"])) for r in rows
           if not r["failed"]]
    trusted = [(e, b, rb) for e, b, rb in fin if np.all(np.isfinite(b))]
    ratio = np.concatenate([e / b for e, b, _ in trusted])
    loose = np.concatenate([b / e for e, b, _ in trusted if np.all(e > 0)])
    summary = {
        "points": len(rows), "failed": sum(1 for r in rows if r["failed"]),
        "edge (infinite bound: the estimate over a quarter of the displacement)": len(fin) - len(trusted),
        "max_error_trusted": float(max(np.max(e) for e, _, _ in trusted)),
        "min_error_trusted": float(min(np.min(e) for e, _, _ in trusted)),
        "max_error_over_bound": float(np.max(ratio)), "min_error_over_bound": float(np.min(ratio)),
        "max_bound_over_error": float(np.max(loose)), "median_bound_over_error": float(np.median(loose)),
        "beaten": int(sum(np.sum(e > b + rb) for e, b, rb in trusted)),
        "beaten_without_reference_bound": int(sum(np.sum(e > b) for e, b, _ in trusted)),
        "linear_s_median": float(np.median([r["linear_s"] for r in rows])),
        "reference_s_median": float(np.median([r["reference_s"] for r in rows])),
    }
    return {"summary": summary, "points": rows}, samples


def _ghc_uncapped(m, P, opts, scale) -> dict:
    """The linear level's estimate at one point without its cap (relative, per angle), and
    the linear motion's displacement from (3.1) and excursion from its start (rad): the
    cap's evidence."""
    import gyro.systems.gyrohorizoncompass as ghc
    from gyro.analyses import motion as generic
    from gyro.questions import motion

    params = dict(zip(m.param_names, map(float, P[0])))
    init = {k: v[1] for k, v in ghc.INITIAL.items()}
    init.update(opts.get("initial", {}))
    red = generic.ReducedState(m, params)
    z0 = ghc.Motion(params, **init).perturbation
    t = motion.times(opts)
    with np.errstate(all="ignore"):
        q, est = generic.linear_answer(red, z0, t, ["rad"] * 4, cap=np.inf)
    x = q - red.q_ref[red.ri]
    return {"uncapped_bound": [float(v) for v in est / scale],
            "displacement": float(np.max(np.sqrt(np.sum(x ** 2, axis=1)))),
            "excursion": generic.linear_size(x, "excursion")}


def ghc_motion_toward_the_cap(quick: bool) -> list:
    """The evidence for the linear level's cap: its estimate without the cap against the
    error (integrated:DOP853) where the linearisation fails: the Earth set over 10 s and the
    laboratory set over 400 s at growing amplitudes of the four angles, and the map's joint
    draws (`ghc_motion_cases`, where the equilibrium exists) scaled so that the linear
    motion's displacement from (3.1) is 0.1 .. 3 rad. Per point the uncapped estimate over
    the displacement (at most 1 rad, the cap's measure) and over the excursion, and the
    largest error over the estimate (beyond 1 the estimate is beaten)."""
    import gyro.systems.gyrohorizoncompass as ghc
    from gyro.analyses import motion as generic
    from gyro.questions import motion

    m = load(GHC)
    earth = dict(zip(m.param_names, m.vector()))
    runs = []  # (label, x, params, z0, opts)
    for base_name, base, horizon, amps in (("Earth", earth, 10.0, (0.02, 0.05, 0.1) if quick else (0.02, 0.05, 0.1, 0.2)),
                                           ("laboratory", GHC_LAB, 400.0, (0.01, 0.03) if quick else (0.005, 0.01, 0.03, 0.05))):
        for a in amps:
            opts = {"horizon": horizon, "initial": {k: a for k in GHC_ANGLES}}
            runs.append((f"{base_name} over {horizon:g} s, the angles at a", a, base, opts))
    joint = [c for c in ghc_motion_cases(quick) if c[0] == "joint random"]
    for k, (_, _, _, P, opts) in enumerate(joint[: 6 if quick else len(joint)]):
        params = dict(zip(m.param_names, map(float, P[0])))
        try:
            ghc.check_equilibrium(params)
        except Exception:
            continue
        red = generic.ReducedState(m, params)
        init = {kk: v[1] for kk, v in ghc.INITIAL.items()}
        init.update(opts["initial"])
        z1 = ghc.Motion(params, **init).perturbation
        zL = generic.linear_motion(red, z1, motion.times(opts), 0)[0]
        d1 = float(np.max(np.sqrt(np.sum(zL[:, :4] ** 2, axis=1))))
        for target in ((0.3, 1.0, 2.0) if quick else (0.1, 0.3, 0.6, 1.0, 1.5, 2.0, 3.0)):
            runs.append((f"joint draw {k}, the displacement in rad", target, params,
                         dict(opts, initial=dict(zip(ghc.INITIAL, (z1 * target / d1).tolist())))))
    out = []
    for label, x, params, opts in runs:
        t = motion.times(opts)
        init = {k: v[1] for k, v in ghc.INITIAL.items()}
        init.update(opts["initial"])
        mo = ghc.Motion(params, **init)
        red = generic.ReducedState(m, params)
        with np.errstate(all="ignore"):
            q, est = generic.linear_answer(red, mo.perturbation, t, ["rad"] * 4, cap=np.inf)
        ref, _ = ghc.motion_answer(mo, t, "DOP853", 1e-10)
        err = np.max(np.abs(q - ref), axis=0)
        xl = q - red.q_ref[red.ri]
        size, exc = generic.linear_size(xl, "displacement"), generic.linear_size(xl, "excursion")
        out.append({"run": label, "x": float(x), "estimate": float(np.max(est)),
                    "estimate_over_displacement": float(np.max(est)) / size,
                    "estimate_over_excursion": float(np.max(est)) / exc,
                    "error_over_estimate": float(np.max(err / est)), "error": float(np.max(err)),
                    "capped": not float(np.max(est)) <= generic.CAP * size})
    return out


def ghc_motion_figure(samples: dict) -> str:
    """The linear motion level's measured error against its bound, one colour per spread."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5))
    lo, hi = np.inf, 0.0
    for i, (label, pts) in enumerate(sorted(samples.items())):
        e = np.concatenate([p[0] for p in pts])
        b = np.concatenate([p[1] for p in pts])
        good = np.isfinite(b) & (e > 0)
        if good.any():
            ax.loglog(b[good], e[good], "o^sv<>Dph"[i % 9], ms=3.5, alpha=0.7, color=f"C{i % 10}", label=label)
            lo, hi = min(lo, b[good].min()), max(hi, b[good].max())
    ax.loglog([lo, hi], [lo, hi], "k-", lw=1, label="error = bound")
    ax.loglog([lo, hi], [lo / 100, hi / 100], "k:", lw=1, label="bound 100x loose")
    ax.set_xlabel("declared bound of level linear (relative, per coordinate)")
    ax.set_ylabel("measured error against integrated:DOP853")
    ax.set_title("gyrohorizoncompass: the linearised motion about (3.1) against (1.5)-(1.6)\n"
                 "(amplitude, spin L, nu, zeta, latitude spreads; a coordinate of a motion each)", fontsize=9)
    ax.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    name = "levels_error_gyrohorizoncompass_linear.png"
    fig.savefig(RESULTS / name, dpi=110)
    plt.close(fig)
    return name


def ghc_motion_costs(quick: bool) -> dict:
    """The motion levels' cost per set: the default motion of the Earth set over 1 s."""
    from gyro.questions import motion

    m = load(GHC)
    P, opts, out = m.vector()[None, :], {"horizon": 1.0}, {}
    for lv in hierarchy.levels(m):
        if not lv.answers_question("motion") or (quick and lv.name.endswith("Radau")):
            continue
        motion.answer(m, lv, P, opts)
        out[f"{GHC} {lv.name}"] = {"s_per_set": per_set(lambda: motion.answer(m, lv, P, opts), 1, 3),
                                   "declared": lv.cost, "batch": 1, "horizon_s": 1.0}
    return out


def ghc_motion(quick: bool, out: dict) -> dict:
    """The gyrohorizoncompass's motion levels measured into `out` (levels.json's document):
    their costs beside the others and the linear level's error map with its figure."""
    out.setdefault("costs", {}).update(ghc_motion_costs(quick))
    out["ghc_motion_error_map"], samples = ghc_motion_map(quick)
    out["ghc_motion_error_map"]["quick"] = quick
    cap = ghc_motion_toward_the_cap(quick)
    held = [c["error_over_estimate"] for c in cap if not c["capped"]]
    beaten = [c["estimate_over_displacement"] for c in cap if c["error_over_estimate"] > 1]
    out["ghc_motion_error_map"]["toward_the_cap"] = {
        "points": cap, "within_the_cap": len(held), "max_error_over_estimate_within_the_cap": max(held),
        "beaten_uncapped": len(beaten), "beaten_with_estimate_over_displacement_from": min(beaten, default=None)}
    out["ghc_motion_error_map"]["figure"] = ghc_motion_figure(samples)
    return out


# ------------------------------------------------------------------ speed goals


def speed(quick: bool) -> dict:
    n = 2000 if quick else 20000
    P = np.tile(TG.vector(), (n, 1))
    for lv in hierarchy.levels(TG):  # warm every compiled path
        if (lv.answers_question("frequencies") and lv.name != "linear_exact:reference"
                and not lv.name.endswith("polyroots")):
            F.answer(TG, lv, P[:2], {})
    t_exact = per_set(lambda: ladder.spectrum(TG, P, "default"), n)
    t_modes = per_set(lambda: select(TG, "frequencies", P, 1e-3, {"modes": [1, 2, 4]}), n)
    t_all = per_set(lambda: select(TG, "frequencies", P, 1e-3), n)
    t_9 = per_set(lambda: select(TG, "frequencies", P, 1e-9), n)
    picked = {key: str(select(TG, "frequencies", P[:1], tol, o).level[0])
              for key, tol, o in (("modes", 1e-3, {"modes": [1, 2, 4]}), ("all", 1e-3, {}), ("1e-9", 1e-9, {}))}
    # the selector's own overhead: select with the formulas alone, against the formulas alone
    nf = 20 * n
    Pf = np.tile(TG.vector(), (nf, 1))
    t_f = per_set(lambda: ladder.spectrum(TG, Pf, "formulas"), nf)
    t_fsel = per_set(lambda: select(TG, "frequencies", Pf, 1e-3, {"modes": [1, 2, 4]}, among=["formulas"]), nf)
    # a million sets of the joint spread at 1e-3, all ten frequencies
    m = 100_000 if quick else 1_000_000
    Pm = joint(m, seed=11)
    t0 = time.perf_counter()
    chunk = 100_000
    levels_used = {}
    for s in range(0, m, chunk):
        sc = select(TG, "frequencies", Pm[s:s + chunk], 1e-3)
        for name, c in zip(*np.unique(sc.level, return_counts=True)):
            levels_used[str(name)] = levels_used.get(str(name), 0) + int(c)
    t_m = time.perf_counter() - t0
    return {
        "sets": n, "exact_default_s_per_set": t_exact,
        "modes_1e-3": {"s_per_set": t_modes, "speedup": t_exact / t_modes, "level": picked["modes"], "modes": [1, 2, 4]},
        "all_1e-3": {"s_per_set": t_all, "speedup": t_exact / t_all, "level": picked["all"]},
        "tol_1e-9": {"s_per_set": t_9, "slowdown": t_9 / t_exact, "level": picked["1e-9"]},
        "selector_overhead": {"formulas_s_per_set": t_f, "select_formulas_s_per_set": t_fsel,
                              "overhead_over_cheapest": (t_fsel - t_f) / t_f},
        "million_sets_1e-3": {"sets": m, "seconds": t_m * (1_000_000 / m), "measured_s": t_m, "levels": levels_used},
        "goals": GOALS,
    }


REQUESTS = (("all_1e-3", 1e-3, {}), ("modes_1_2_4_1e-3", 1e-3, {"modes": [1, 2, 4]}),
            ("modes_4_1e-3", 1e-3, {"modes": [4]}), ("all_1e-9", 1e-9, {}))


def random_speed(n: int, seed: int = 36) -> dict:
    """The speed where it is used (issue 36): n random sets of the project's joint spread
    (`joint`), one core, each request against the exact operator by the default method on
    the same sets in the same run, with the levels picked. The runs are interleaved chunk by
    chunk (10,000 sets), so that the load of a shared machine falls on all of them alike.

    Beside the requests (REQUESTS), what the selector's order rests on: for k = 1..10
    requested modes (1..k) at 1e-3, the selector with the certified levels tried first (the
    certificate's declared costs set to 0 and no retirement, for the run) against the exact
    operator alone (`among` it), per set, and the most modes up to which the first was the
    faster (gyro.questions.frequencies CERTIFIED_MODES); the same for mode k alone, and the
    modes for which the first was not the faster there (none may be, for a rule by the number
    of modes to hold); and the certificate's parts alone (`certificate_costs`: COUNT_COST,
    OPERATOR_COST)."""
    P = joint(n, seed)
    chunk = 10_000
    parts = [P[s:s + chunk] for s in range(0, n, chunk)]
    for lv in hierarchy.levels(TG):  # warm every compiled path
        if (lv.answers_question("frequencies") and lv.name != "linear_exact:reference"
                and not lv.name.endswith("polyroots")):
            F.answer(TG, lv, P[:2], {})
    _certified_first(P[:2], [1])  # and the certificate's (its rounding enclosure is compiled on first use)
    exact = "linear_exact:default"
    ks = range(1, 11)
    runs = {"exact": lambda p: ladder.spectrum(TG, p, "default"),
            "exact_selected": lambda p: select(TG, "frequencies", p, 1e-3, {}, among=[exact])}
    for key, tol, opts in REQUESTS:
        runs[key] = lambda p, tol=tol, opts=opts: select(TG, "frequencies", p, tol, opts)
    for k in ks:  # modes 1..1 is mode 1 alone: one run of it, not two verdicts
        if k > 1:
            runs[f"certified_first_{k}"] = lambda p, k=k: _certified_first(p, list(range(1, k + 1)))
        runs[f"certified_first_mode_{k}"] = lambda p, k=k: _certified_first(p, [k])
    seconds = {key: 0.0 for key in runs}
    used = {key: {} for key, _, _ in REQUESTS}
    for p in parts:
        for key, fn in runs.items():
            t0 = time.perf_counter()
            res = fn(p)
            seconds[key] += time.perf_counter() - t0
            if key in used:
                for name, c in zip(*np.unique(res.level, return_counts=True)):
                    used[key][str(name)] = used[key].get(str(name), 0) + int(c)
    per = {key: t / n for key, t in seconds.items()}
    t_exact = per["exact"]
    out = {"sets": n, "seed": seed, "exact_default_s_per_set": t_exact}
    for key, _, _ in REQUESTS:
        out[key] = {"s_per_set": per[key], "ratio_to_exact": t_exact / per[key], "levels": used[key]}
    t_cf = [per[f"certified_first_{k}" if k > 1 else "certified_first_mode_1"] for k in ks]
    beat = per["exact_selected"] / F.MARGIN  # faster by more than the runs' scatter
    faster = [bool(t < beat) for t in t_cf]
    t_one = [per[f"certified_first_mode_{k}"] for k in ks]
    out["modes_1e-3"] = {"k": list(ks), "certified_first_s_per_set": t_cf,
                         "exact_alone_s_per_set": per["exact_selected"], "margin": F.MARGIN,
                         "certified_first_faster": faster, "CERTIFIED_MODES": (faster + [False]).index(False),
                         "mode_k_alone_certified_first_s_per_set": t_one,
                         "CERTIFIED_ALONE": [k for k, t in zip(ks, t_one) if t < beat],
                         "modes_alone_not_faster": [k for k, t in zip(ks, t_one) if not t < beat]}
    out["certificate"] = certificate_costs(parts[0], t_exact)
    return out


def _certified_first(p: np.ndarray, modes: list):
    """The selector at 1e-3 for `modes` with the certificate's declared costs set to 0 and no
    retirement: the certified levels tried before the exact operator, whatever their proof
    costs."""
    saved = F.OPERATOR_COST, F.COUNT_COST, F.CERTIFIED_MODES, F.CERTIFIED_ALONE
    F.OPERATOR_COST = F.COUNT_COST = 0.0
    F.CERTIFIED_MODES = len(TG.meta["reduced"])
    F.CERTIFIED_ALONE = tuple(range(1, len(TG.meta["reduced"]) + 1))
    try:
        return select(TG, "frequencies", p, 1e-3, {"modes": modes})
    finally:
        F.OPERATOR_COST, F.COUNT_COST, F.CERTIFIED_MODES, F.CERTIFIED_ALONE = saved


def certificate_costs(p: np.ndarray, t_exact: float) -> dict:
    """What the frequencies' certificate costs on the sets p, on the formulas' answers with
    a bound of 1e-3 (s per set): a count alone (the compiled inertia over the points of the
    ten modes' intervals), the certificate of one, three and ten modes, and the rest of it
    beside its counts (the equilibrium, the operator, the bookkeeping: one mode's certificate
    less its three counts); and the same on the scale of the methods' COST (the default
    method's COST over its time t_exact in this run), which is how the question declares
    them (gyro.questions.frequencies COUNT_COST, OPERATOR_COST: the selector's order)."""
    from gyro import methods
    from gyro.equilibrium import equilibria, operators

    lv = hierarchy.get(TG, "formulas")
    ans = F.answer(TG, lv, p, {})
    b = np.full(ans.values.shape, 1e-3)
    out = {}
    for key, idx in (("1_mode", [3]), ("3_modes", [0, 1, 3]), ("10_modes", list(range(10)))):
        out[f"certificate_{key}_s_per_set"] = per_set(lambda: F.certify(TG, lv, p, ans, b, idx), p.shape[0])
    M, D, K = operators(TG, p, equilibria(TG, p)[0])
    f = ans.values
    W = np.concatenate([np.zeros((len(p), 1)), f / (1 + 1e-3), f / (1 - 1e-3)], axis=1)
    out["count_s"] = per_set(lambda: F.counts_at(M, D, K, W), W.size)
    out["rest_s_per_set"] = out["certificate_1_mode_s_per_set"] - 3 * out["count_s"]
    for name in ("formulas", "decoupled", "linear_paper", "quartic"):
        level = hierarchy.get(TG, name)
        out[f"{name}_s_per_set"] = per_set(lambda: F.answer(TG, level, p, {}), p.shape[0])
    scale = methods.get("default").COST / t_exact
    out["scale_to_COST"] = scale
    out["declare"] = {"COUNT_COST": out["count_s"] * scale, "OPERATOR_COST": out["rest_s_per_set"] * scale}
    return out


def rungs(quick: bool) -> dict:
    """How far above the cheapest level that was enough the selector goes: per tolerance,
    the sets whose chosen level is more than one rung (a level answering every frequency and
    not dominated there, cheapest first: gyro.analyses.scene.rungs) above the cheapest level whose measured error meets tol / margin, for
    margins 1, 2 and 5 (tests/methods/test_hierarchy.py holds it with no margin)."""
    n = 100 if quick else 400
    P = joint(n, seed=12)
    ref = F.answer(TG, hierarchy.get(TG, "linear_exact:default"), P, {})
    names = scene_rungs(TG, "frequencies", P, until="linear_exact:default")
    err = {n: F.error(F.answer(TG, hierarchy.get(TG, n), P, {}), ref) for n in names
           if hierarchy.get(TG, n).cost <= hierarchy.get(TG, "linear_exact").cost}
    out = {"sets": n, "rungs": names, "tolerances": {}}
    for tol in (3e-2, 1e-3, 1e-4, 1e-6, 1e-9):
        sc = select(TG, "frequencies", P, tol)
        row = {"chosen": {str(k): int(v) for k, v in zip(*np.unique(sc.level, return_counts=True))}}
        for margin in (1, 2, 5):
            above = 0
            for k in range(n):
                need = [m for m, e in err.items() if np.all(e[k] <= tol / margin)] or [sc.level[k]]
                above += names.index(sc.level[k]) > names.index(need[0]) + 1
            row[f"more_than_one_rung_margin_{margin}"] = above
        out["tolerances"][f"{tol:g}"] = row
    return out


# ------------------------------------------------------------------ figures


def error_figures(samples: dict) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    for name, (err, bound) in samples.items():
        fig, ax = plt.subplots(figsize=(5.5, 4.5))
        e, b = err.ravel(), bound.ravel()
        good = np.isfinite(e) & np.isfinite(b) & (e > 0) & (b > 0)
        if good.any():
            ax.loglog(b[good], e[good], ".", ms=2, alpha=0.4, color="C0", label="a mode of a set")
            lo, hi = np.nanmin(b[good]), np.nanmax(b[good])
            ax.loglog([lo, hi], [lo, hi], "k-", lw=1, label="error = bound")
            ax.loglog([lo, hi], [lo / 100, hi / 100], "k:", lw=1, label="bound 100x loose")
        else:  # every set beyond an edge (a lost root leaves no rank decided)
            ax.text(0.5, 0.5, "no finite bound outside the question's edges", ha="center", transform=ax.transAxes)
        ax.set_xlabel("declared bound (relative)")
        ax.set_ylabel("measured error against linear_exact")
        ax.set_title(f"torsion_gyrocompass, level {name}\n(spreads and a joint random spread)", fontsize=9)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = RESULTS / f"levels_error_{name.replace(':', '_')}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        files.append(path.name)
    return files


@dataclass
class Sweep:
    """One scene figure: a question of a model along a sweep of one physical input. `groups`
    are the batches the sweep runs in, (P (sets, parameters), the question's options) each:
    one batch for a parameter sweep, one per point for a sweep of an initial condition (the
    options hold the initial conditions). `shown`: the levels whose error is drawn, each
    (level, the level it is measured against or None for the reference itself (its bound
    alone), every how many points)."""

    model: str
    question: str
    x: np.ndarray
    xlabel: str
    title: str
    groups: list
    shown: tuple
    logx: bool = True


def scene_sweeps(quick: bool) -> list:
    """The swept inputs of the scene figures, one per model with a hierarchy of levels."""
    from gyro.systems.gimbal_gyroscope import stationary_motion

    points = 25 if quick else 61
    P, s = spreads(points)["spin 0.1x..10x"]
    out = [Sweep("torsion_gyrocompass", "frequencies", s, "spin H / H of the paper example",
                 "torsion_gyrocompass: which level the selector picks, against spin\n"
                 "(H 0.1x..10x the paper example; all ten frequencies)", [(P, {})],
                 (("formulas", "linear_exact:default", 1), ("linear_paper", "linear_exact:default", 1),
                  ("linear_exact:companion", "linear_exact:default", 1),
                  ("linear_exact:default", "linear_exact:reference", 4)))]
    # the gimbal gyroscope kicked off its unstable stationary motion theta0 = 0.3 rad, H = 0.05
    # (docs/gimbal.md): the smaller the kick theta'(0), the nearer the separatrix
    gm = load("gimbal_gyroscope")
    st = stationary_motion(dict(zip(gm.param_names, gm.vector())), 0.3, 0.05)
    kicks = np.geomspace(1e-1, 1e-9, 9 if quick else 17)  # one a decade (two)
    groups = [(gm.vector()[None, :], {"horizon": 30.0, "initial": {"theta0": st.theta0, "dtheta0": float(k),
                                                                    "dpsi0": st.dpsi0, "dphi0": st.dphi0}})
              for k in kicks]
    out.append(Sweep("gimbal_gyroscope", "motion", kicks, "kick theta'(0), rad/s (off the unstable stationary "
                     "motion theta0 = 0.3 rad, H = 0.05)",
                     "gimbal_gyroscope: which level the selector picks, toward the separatrix\n"
                     "(motion psi, theta, phi over 30 s; errors against the closed form)", groups,
                     (("closed_form", None, 1), ("integrated:DOP853", "closed_form", 1),
                      ("integrated:Radau", "closed_form", 1))))
    ghc = load("gyrohorizoncompass")
    s = np.geomspace(0.1, 10.0, points)
    P = np.tile(ghc.vector(), (points, 1))
    P[:, ghc.param_names.index("zeta")] *= s
    out.append(Sweep("gyrohorizoncompass", "frequencies", s, "zeta = v/R / its default (the ship's speed)",
                     "gyrohorizoncompass: which level the selector picks, against the speed\n"
                     "(zeta 0.1x..10x the default; all four frequencies; errors against the 40-digit reference)",
                     [(P, {})],
                     (("linear_exact:default", "linear_exact:reference", 1),
                      ("linear_exact:companion", "linear_exact:reference", 1),
                      ("linear_exact:polyroots", "linear_exact:reference", 1))))
    # the precession theories (Ishlinsky) as the outer ring's imbalance grows: (2) of (29) fails
    gp = load("gimbal_precession")
    k = np.geomspace(1e-8, 1e-3, 6 if quick else 11)
    P = np.tile(gp.vector(), (len(k), 1))
    P[:, gp.param_names.index("k_xi1")] = k
    out.append(Sweep("gimbal_precession", "motion", k, "outer ring imbalance k_xi1, N m (l_x = 1e-3 N m, H = 1 N m s)",
                     "gimbal_precession: which theory the selector picks, as the outer ring's imbalance grows\n"
                     "(the spin axis' image point over 10 s; errors against the full level)", [(P, {"horizon": 10.0})],
                     (("elementary", "full", 1), ("small", "full", 1), ("rigorous", "full", 1),
                      ("image", "full", 1), ("full", None, 1))))
    return out


def scene_data(sw: Sweep) -> dict:
    """What a scene figure draws, measured: per point the level `select` picks at each of
    TOLS ('' where no level meets it) with its bound, and each shown level's largest error
    over the quantities against its reference level, with its declared bound."""
    model = load(sw.model)
    picked, bound_of_pick, errors = {}, {}, {}
    for tol in TOLS:
        lv, bd = [], []
        for P, opts in sw.groups:
            sc = select(model, sw.question, P, tol, opts)
            lv += [str(x) for x in sc.level]
            bd += [float(b) if np.isfinite(b) else None for b in np.max(sc.bound, axis=1)]
        picked[str(tol)], bound_of_pick[str(tol)] = lv, bd
    sizes = np.cumsum([0] + [len(P) for P, _ in sw.groups])
    for name, against, every in sw.shown:
        keep = np.arange(len(sw.x))[::every]
        err, bd = [], []
        for g, (P, opts) in enumerate(sw.groups):
            rows = keep[(keep >= sizes[g]) & (keep < sizes[g + 1])] - sizes[g]
            if rows.size == 0:
                continue
            if against is None:
                B = hierarchy.bounds(model, hierarchy.get(model, name), sw.question, P[rows],
                                     len(questions.get(sw.question).quantities(model, opts)))
                ans = questions.get(sw.question).answer(model, hierarchy.get(model, name), P[rows], opts)
                b, e = B.total(ans.estimate), np.full(len(rows), np.nan)
            else:
                e_, b = level_error(model, sw.question, name, against, P[rows], opts)
                with np.errstate(all="ignore"):  # NaN where a quantity has no relative error (a zero root)
                    e = np.array([np.nanmax(r) if np.isfinite(r).any() else np.nan for r in e_])
            err += [float(x) if np.isfinite(x) else None for x in e]
            bd += [float(x) if np.isfinite(x) else None for x in np.max(b, axis=1)]
        errors[name] = {"against": against, "x": [float(v) for v in sw.x[keep]], "error": err, "bound": bd}
    return {"question": sw.question, "xlabel": sw.xlabel, "x": [float(v) for v in sw.x],
            "options": [o for _, o in sw.groups],
            "picked": picked, "bound_of_pick": bound_of_pick, "errors": errors}


def scene_figure(sw: Sweep, data: dict) -> str:
    """One model's scene figure from its measured data: above, each shown level's largest
    error over the quantities (line; its bound dashed) and the three tolerances; below, the
    level the selector picks at each point for each tolerance, a cross on the row 'no level
    meets it' where none does (gyro scene exits 1 there)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    model = load(sw.model)
    x = np.asarray(data["x"])
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    nan = lambda v: np.array([np.nan if y is None else y for y in v], dtype=float)  # noqa: E731
    for i, (name, against, _) in enumerate(sw.shown):
        d = data["errors"][name]
        xs = np.asarray(d["x"])
        if against is not None:
            ax.plot(xs, nan(d["error"]), "-", color=f"C{i}", marker="." if len(xs) < 15 else None,
                    label=f"{name}: error against {against}")
        ax.plot(xs, nan(d["bound"]), "--", color=f"C{i}", lw=1,
                label=f"{name}: bound" + (" (the reference)" if against is None else ""))
    for tol in TOLS:
        ax.axhline(tol, color="0.6", lw=0.8)
        ax.text(x.min(), tol * 1.3, f"tol {tol:g}", fontsize=7, color="0.4")
    drawn = [v for d in data["errors"].values() for v in d["error"] + d["bound"] if v]
    ax.set_yscale("log")
    ax.set_ylabel("largest relative error over the quantities")
    ax.set_ylim(max(1e-17, min(drawn + [min(TOLS)]) / 30), 10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(sw.title, fontsize=9)
    order = [lv.name for lv in hierarchy.levels(model) if lv.answers_question(sw.question)]
    rows = ["no level meets it", *order]
    for j, tol in enumerate(TOLS):
        y = np.array([rows.index(v or "no level meets it") for v in data["picked"][str(tol)]])
        ax2.plot(x, y + (j - 1) * 0.08, "-", lw=1, color=f"C{j + 4}", label=f"tol {tol:g}")
        none = y == 0
        ax2.plot(x[~none], y[~none] + (j - 1) * 0.08, "o", ms=3, color=f"C{j + 4}")
        ax2.plot(x[none], y[none] + (j - 1) * 0.08, "x", ms=6, mew=1.5, color=f"C{j + 4}")
    ax2.set_yticks(range(len(rows)), rows, fontsize=7)
    ax2.set_ylim(-0.5, len(rows) - 0.5)
    if sw.logx:
        ax.set_xscale("log")
    ax2.set_xlabel(sw.xlabel)
    ax2.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    name = f"scene_{sw.model}.png"
    fig.savefig(RESULTS / name, dpi=110)
    plt.close(fig)
    return name


def scenes(quick: bool, only: list | None = None) -> dict:
    """Every scene figure and its data (bench/results/scenes.json)."""
    path = RESULTS / "scenes.json"
    out = json.loads(path.read_text()) if path.exists() and only else {}
    for sw in scene_sweeps(quick):
        if only and sw.model not in only:
            continue
        t0 = time.perf_counter()
        out[sw.model] = scene_data(sw) | {"quick": quick}
        out[sw.model]["figure"] = scene_figure(sw, out[sw.model])
        print(f"scene {sw.model}: {time.perf_counter() - t0:.0f} s", flush=True)
    path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--scenes", nargs="*", metavar="MODEL",
                    help="only the scene figures (of these models; all without a name): scenes.json")
    ap.add_argument("--torsion-motion", action="store_true",
                    help="only the torsion gyrocompass's motion map (levels.json 'torsion_motion_map')")
    ap.add_argument("--ghc-motion", action="store_true",
                    help="only the gyrohorizoncompass's motion levels (costs, error map), into levels.json")
    ap.add_argument("--random-speed", type=int, metavar="N",
                    help="only the speed over N random sets of the joint spread (levels.json 'random_speed')")
    args = ap.parse_args(argv)
    if args.random_speed:
        path = RESULTS / "levels.json"
        out = json.loads(path.read_text()) if path.exists() else {}
        out["random_speed"] = random_speed(args.random_speed)
        path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
        print(json.dumps(out["random_speed"], indent=1))
        return 0
    if args.torsion_motion:
        path = RESULTS / "levels.json"
        out = json.loads(path.read_text()) if path.exists() else {}
        out["torsion_motion_map"] = torsion_motion_map(args.quick)
        out["torsion_motion_map"]["figure"] = torsion_motion_figure(out["torsion_motion_map"])
        path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
        return 0
    if args.scenes is not None:
        scenes(args.quick, args.scenes or None)
        return 0
    if args.ghc_motion:
        path = RESULTS / "levels.json"
        doc = ghc_motion(args.quick, json.loads(path.read_text()) if path.exists() else {})
        path.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
        print(json.dumps(doc["ghc_motion_error_map"]["summary"], indent=1))
        return 0
    out = {"machine": {"python": platform.python_version(), "processor": platform.machine(),
                       "cores": os.cpu_count()}, "quick": args.quick}
    t0 = time.perf_counter()
    out["costs"] = costs(args.quick)
    print(f"costs: {time.perf_counter() - t0:.0f} s", flush=True)
    stats, samples = error_maps(args.quick)
    out["error_maps"] = stats
    out["gimbal_error_map"] = gimbal_map(args.quick)
    out["torsion_motion_map"] = torsion_motion_map(args.quick)
    out["torsion_motion_map"]["figure"] = torsion_motion_figure(out["torsion_motion_map"])
    ghc_motion(args.quick, out)
    print(f"error maps: {time.perf_counter() - t0:.0f} s", flush=True)
    out["rungs"] = rungs(args.quick)
    out["figures"] = error_figures(samples)
    scenes(args.quick)
    print(f"figures: {time.perf_counter() - t0:.0f} s", flush=True)
    out["speed"] = speed(args.quick)
    print(f"speed: {time.perf_counter() - t0:.0f} s", flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "levels.json").write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    sp = out["speed"]
    print(json.dumps({k: sp[k] for k in ("modes_1e-3", "all_1e-3", "tol_1e-9", "selector_overhead",
                                          "million_sets_1e-3")}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""`python -m bench.precession_bounds SEED N [--span LO HI] [--module PATH] [--out FILE]`:
gimbal_precession's bounds on N random sets of tests/paper/test_precession_bounds.py's spread
(beta0 to +-1.5 rad, alpha0 to +-1, H 0.05x..20x, inertias 0.2x..5x, the outer ring equal,
flat, flat across or C1, C2 0.2x..5x C3, u_zeta to 300 rad/s, u_xi, u_eta to 1 rad/s, moments
from 1e-12 N m, friction on and off), horizons LO..HI s (default 0.3..2), 201 samples.

For each set and level: the error against `full` by BDF at rtol 1e-14 (the motion
question's measure), the bound and its CPU time; sets whose reference reaches +-90 deg are
drawn again. Prints per level the worst error/bound and the refused sets, and the cheapest
level whose bound meets 1e-2, 1e-4, 1e-6 with the model's declared edge (|u| J/(H cos beta0)
< 1/10 for the precession levels): the selector's choice. `--module PATH` loads another
version of gyro/systems/gimbal_precession.py (a file from an earlier commit: `git show
REV:gyro/systems/gimbal_precession.py > old.py`) for a before/after on the same sets.
Several JSON files from --out are summarised together by `--summary FILE ...`.

`--enclosure N`: the enclosed constants of the tube checked on N answered sets (`rigorous`,
`small`; seed SEED): at 40 random steps of each set's bound grid, the constants over the
step's box and the tube about it (the radius of the first try) against the constants at 60
random points of the box and of the ball about each; prints per constant the smallest
margin, (enclosure - the points' extreme) over the enclosure's magnitude (never below 0:
an enclosure), and the median overestimate.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import time

import numpy as np

DEFAULT = {"C3": 2e-3, "B1": 1.2e-3, "B2": 1e-3, "B3": 0.8e-3, "A1": 0.5e-3, "A3": 1e-3}
RINGS = [(1.0, 1.0), (1.0, 2.0), (2.0, 1.0), None]  # (C1, C2)/C3: equal, flat, flat across, spread
ORDER = ["elementary", "small", "rigorous", "image", "full"]  # the declared order, cheapest first


def _log(r, lo, hi):
    return float(10 ** r.uniform(np.log10(lo), np.log10(hi)))


def _signed(r, lo, hi):
    return float(r.choice([-1.0, 1.0])) * _log(r, lo, hi)


def _maybe(r, f):
    return 0.0 if r.random() < 0.5 else f()


def draw(r, span):
    s = {"beta0": r.uniform(-1.5, 1.5), "alpha0": r.uniform(-1, 1), "H": _log(r, 0.05, 20),
         "u_zeta": _maybe(r, lambda: _signed(r, 1e-3, 300)), "u_xi": _maybe(r, lambda: _signed(r, 1e-6, 1)),
         "u_eta": _maybe(r, lambda: _signed(r, 1e-6, 1))}
    for k, v in DEFAULT.items():
        s[k] = v * _log(r, 0.2, 5)
    ring = RINGS[r.integers(4)]
    c1, c2 = ring if ring else (_log(r, 0.2, 5), _log(r, 0.2, 5))
    s["C1"], s["C2"] = c1 * s["C3"], c2 * s["C3"]
    for k in ("l_x", "l_y", "m_z", "k_xi1"):
        s[k] = _maybe(r, lambda: _signed(r, 1e-12, 1e-2))
    for k in ("f_alpha", "f_beta"):
        s[k] = _maybe(r, lambda: _log(r, 1e-4, 0.1))
    return s, float(r.uniform(*span))


def _module(path):
    if path is None:
        from gyro.systems import gimbal_precession
        return gimbal_precession
    spec = importlib.util.spec_from_file_location("gimbal_precession_other", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def measure(seed, n, span, pr):
    r = np.random.default_rng(seed)
    rows = []
    while len(rows) < n:
        s, T = draw(r, span)
        t = np.linspace(0, T, 201)
        v = pr.parameters(s)
        try:
            ref = pr.simulate(v, t, "full", rtol_scale=0.01, multistep="bdf")
        except (pr.Singular, pr.IntegrationBudget):
            continue
        scale = pr._scale(ref)
        if not scale > 0:
            continue
        row = {"set": s, "T": T, "levels": {}}
        for lv in pr.LEVELS:
            try:
                m = pr.simulate(v, t, lv)
                c0 = time.process_time()
                b = pr.bound(v, m)
                c = time.process_time() - c0
            except (pr.Singular, pr.IntegrationBudget):
                row["levels"][lv] = None
                continue
            err = max(np.abs(m.x - ref.x).max(), np.abs(m.y - ref.y).max()) / scale
            row["levels"][lv] = {"err": float(err), "bound": float(b), "seconds": c}
        rows.append(row)
    return rows


def _edge(s, pr):
    v = pr.parameters(s)
    J = sum(float(v[k]) for k in ("C1", "C2", "C3", "B1", "B2", "B3", "A1", "A1", "A3"))
    u = float(np.linalg.norm([v["u_xi"], v["u_eta"], v["u_zeta"]]))
    return u * J < float(v["H"]) * abs(np.cos(float(v["beta0"]))) / 10


def summary(rows, pr) -> dict:
    out = {"sets": len(rows), "levels": {}, "selector": {}}
    for lv in ORDER:
        xs = [r["levels"][lv] for r in rows]
        ratios = [x["err"] / x["bound"] for x in xs if x and np.isfinite(x["bound"])]
        out["levels"][lv] = {"worst_error_over_bound": max(ratios) if ratios else None,
                             "beaten": sum(q > 1 for q in ratios),
                             "refused": sum(1 for x in xs if x is None or not np.isfinite(x["bound"])),
                             "median_bound_seconds": float(np.median([x["seconds"] for x in xs if x]))}
    for tol in (1e-2, 1e-4, 1e-6):
        pick = {}
        for r in rows:
            ok = _edge(r["set"], pr)
            chosen = "none"
            for lv in ORDER:
                x = r["levels"][lv]
                if (lv == "full" or ok) and x and x["bound"] <= tol:
                    chosen = lv
                    break
            pick[chosen] = pick.get(chosen, 0) + 1
        out["selector"][f"{tol:g}"] = pick
    return out


def enclosure(seed, n, pr):
    r, rng = np.random.default_rng(seed), np.random.default_rng(seed + 1)
    margin, over = {}, {}
    done = 0
    while done < n:
        s, T = draw(r, (0.3, 2.0))
        v = pr.parameters(s)
        level = ("rigorous", "small")[done % 2]
        try:
            m = pr.simulate(v, np.linspace(0, T, 201), level)
        except (pr.Singular, pr.IntegrationBudget):
            continue
        if not np.isfinite(pr.bound(v, m)):
            continue
        g = pr._bound_grid(v, m)
        S = np.stack([g.alpha, g.beta, g.H], -1)
        guess = pr._guess(v, g, pr._at(v, S))
        rad = pr.TUBE_GROWTH * guess + 1e-300
        box, rates_, dl = pr._level_boxes(v, g)
        pick = np.sort(rng.choice(len(box[0]), min(40, len(box[0])), replace=False))
        lo, hi = box[0][pick], box[1][pick]
        c = pr._enclosed_constants(v, (lo, hi), (rates_[0][pick], rates_[1][pick]), (dl[0][pick], dl[1][pick]), rad, S[:1])
        done += 1
        for _ in range(60):
            SL = lo + rng.uniform(0, 1, lo.shape) * (hi - lo)
            d = rng.normal(size=SL.shape)
            d *= rad * rng.uniform(0, 1, (len(SL), 1)) ** (1 / 3) / np.linalg.norm(d, axis=1, keepdims=True)
            G = np.stack([np.abs(np.cos(SL[:, 1])), np.ones(len(SL)), np.full(len(SL), 1 / abs(float(v["H"])))], -1)
            pts = pr._constants_at(v, level, SL, SL + d / G)
            for k, x in pts.items():
                if k not in c:
                    continue
                gap = (x - c[k]) if k == "mmin" else (c[k] - x)
                scale = np.maximum(np.abs(c[k]), 1e-300)
                margin[k] = min(margin.get(k, np.inf), float(np.min(gap / scale)))
                over.setdefault(k, []).append(np.abs(c[k]) / np.maximum(np.abs(x), 1e-300))
    return {"smallest margin": margin, "median enclosure / point": {k: float(np.median(np.concatenate(x)))
                                                                     for k, x in over.items()}}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seed", type=int, nargs="?", default=1)
    ap.add_argument("n", type=int, nargs="?", default=40)
    ap.add_argument("--span", type=float, nargs=2, default=(0.3, 2.0))
    ap.add_argument("--module", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--summary", nargs="+", default=None, help="summarise these --out files together")
    ap.add_argument("--enclosure", type=int, default=None, metavar="N")
    a = ap.parse_args(argv)
    pr = _module(a.module)
    if a.enclosure:
        print(json.dumps(enclosure(a.seed, a.enclosure, pr), indent=1))
        return
    if a.summary:
        rows = [row for f in a.summary for row in json.load(open(f))]
    else:
        rows = measure(a.seed, a.n, tuple(a.span), pr)
        if a.out:
            json.dump(rows, open(a.out, "w"))
    print(json.dumps(summary(rows, pr), indent=1))


if __name__ == "__main__":
    main()

"""Design questions at scale, measured in one run (docs/tolerance.md):

1. sensitivities of all frequencies to all parameters against the frequencies alone, over
   the same batch (goal: <= 3x), by the emitted derivatives (compiled) and by CasADi's AD;
2. a local Dask cluster of two workers against one worker on the same large sweep
   (goal: >= 1.7x the throughput), and both against the in-process run, bit for bit;
3. a tolerance study of the paper's torsion gyrocompass over the bearing tolerances with
   N samples (goal: 1e7 within 10 minutes on two cores), with its figures.

    python -m bench.scale [--samples N] [--sweep N] [--skip-tolerance] [--sensitivities-only]

--skip-tolerance keeps the study of the previous run (and the load it ran under);
--sensitivities-only measures question 1 alone, with where its time goes, and writes nothing.

Writes bench/results/scale.json, tolerance_histograms.png and tolerance_tornado.png."""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODEL = "torsion_gyrocompass"
# the study of docs/tolerance.md: bearing stiffnesses normal 5 %, rotor inertias 1 %, spin 0.5 %
SPREADS = ["Kp=normal:0.05", "K0=normal:0.05", "Kgamma=normal:0.05", "A=normal:0.01", "C=normal:0.01",
           "H=normal:0.005"]
HARMONICS = (1, 2, 3)


def _median_time(f, runs):
    out = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        out.append(time.perf_counter() - t0)
    return statistics.median(out)


def bench_sensitivities(n=2000, runs=5) -> dict:
    from gyro import ladder
    from gyro.analyses.sensitivity import sensitivities
    from gyro.models import load

    model = load(MODEL)
    p0 = model.vector()
    P = np.tile(p0, (n, 1)) * (1 + 0.01 * np.random.default_rng(7).standard_normal((n, len(p0))))
    spec = ladder.spectrum(model, P)
    sensitivities(model, P[:8], None, route="casadi")  # build CasADi's Jacobian once
    sensitivities(model, P[:8], None, route="emitted")  # and load the compiled one
    # the frequencies and the sensitivities alternate, so that a change of load weighs on both
    t_f, t_e = (statistics.median(t) for t in zip(*[
        (_median_time(lambda: ladder.spectrum(model, P), 1),
         _median_time(lambda: sensitivities(model, P, spec, route="emitted"), 1)) for _ in range(runs)]))
    t_c = _median_time(lambda: sensitivities(model, P, spec, route="casadi"), max(1, runs // 2))
    pieces = _sensitivity_pieces(model, P[:1024], _first(spec, 1024), runs)
    e = sensitivities(model, P, spec, route="emitted").d
    c = sensitivities(model, P, spec, route="casadi").d
    agree = float(np.nanmax(np.abs(e - c) / np.maximum(np.abs(e), np.nanmax(np.abs(e), axis=2, keepdims=True))))
    out = {"sets": n, "frequencies_us_per_set": 1e6 * t_f / n,
           "sensitivities_emitted_us_per_set": 1e6 * t_e / n, "sensitivities_casadi_us_per_set": 1e6 * t_c / n,
           "ratio_sensitivities_to_frequencies": t_e / t_f, "ratio_total_to_frequencies": (t_f + t_e) / t_f,
           "casadi_over_emitted": t_c / t_e, "routes_agree_rel": agree, "goal_ratio": 3.0,
           "pieces_us_per_set": pieces}
    print(f"sensitivities: frequencies {out['frequencies_us_per_set']:.1f} us/set, sensitivities "
          f"{out['sensitivities_emitted_us_per_set']:.1f} us/set emitted (ratio {t_e / t_f:.2f}; with the "
          f"frequencies {(t_f + t_e) / t_f:.2f}), CasADi AD {out['sensitivities_casadi_us_per_set']:.1f} us/set "
          f"({t_c / t_e:.1f}x the emitted); routes agree to {agree:.1e}", flush=True)
    print("  per set, in one chunk of 1024: " + ", ".join(f"{k} {v:.1f} us" for k, v in pieces.items()), flush=True)
    return out


def _first(spec, k):
    from gyro.analyses.sensitivity import _rows

    return _rows(spec, slice(0, k))


def _sensitivity_pieces(model, P, spec, runs) -> dict:
    """Where the time of gyro/analyses/sensitivity.py's _chunk goes, step by step on one
    chunk (us a set, medians of `runs`): the emitted Jacobians' nonzeros, the operator, the
    equilibrium's derivative, the null vectors and the contraction (compiled where there
    is a compiler, as the runtime calls them)."""
    from gyro import cbackend
    from gyro.analyses import sensitivity as S
    from gyro.equilibrium import operators
    from gyro.kernels import compiled

    n = P.shape[0]
    names = model.meta["equilibrium_coordinates"]
    idx = [model.meta["reduced"].index(c) for c in names]
    npar, nq = len(model.param_names), len(names)
    qe = spec.equilibrium
    lam = spec.growth + 1j * spec.frequencies
    null, contract = compiled(cbackend.sens_null_vectors, model), compiled(cbackend.sens_contract, model)
    vals, rows, cols, dr = S.sparse_partials(model, P, qe, "emitted")
    M, D, K = operators(model, P, qe)
    herm = np.ones(n, bool)  # the bench's sets are conservative: J(i omega) Hermitian
    x, y = S._null_vectors(M, D, K, lam, herm, null)
    steps = {
        "emitted Jacobians": lambda: S.sparse_partials(model, P, qe, "emitted"),
        "operator": lambda: operators(model, P, qe),
        "equilibrium derivative": lambda: S._equilibrium_derivative(dr[:, idx, npar:], dr[:, idx, :npar]),
        "null vectors": lambda: S._null_vectors(M, D, K, lam, herm, null),
        "contraction": lambda: S._contract(rows, cols, npar + nq, vals, M, D, lam, x, y, contract),
    }
    return {k: 1e6 * _median_time(f, runs) / n for k, f in steps.items()}


def bench_dask(n=400000) -> dict:
    from distributed import Client, LocalCluster

    from gyro.analyses.sweep import spectra
    from gyro.models import load

    model = load(MODEL)
    p0 = model.vector()
    P = np.tile(p0, (n, 1)) * (1 + 0.02 * np.random.default_rng(3).standard_normal((n, len(p0))))
    chunk = 2048
    t0 = time.perf_counter()
    serial = spectra(model, P, chunk=chunk)
    t_serial = time.perf_counter() - t0
    out = {"sets": n, "chunk": chunk, "in_process_s": t_serial}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
                Client(cl) as c:
            spectra(model, P[:chunk], scheduler=c, chunk=chunk)  # workers warm: kernels loaded
            t0 = time.perf_counter()
            s = spectra(model, P, scheduler=c, chunk=chunk)
            out[f"workers_{workers}_s"] = time.perf_counter() - t0
            out[f"workers_{workers}_identical"] = bool(np.array_equal(s.frequencies, serial.frequencies, equal_nan=True)
                                                       and np.array_equal(s.error_estimate, serial.error_estimate,
                                                                          equal_nan=True))
    out["speedup_2_over_1"] = out["workers_1_s"] / out["workers_2_s"]
    out["goal_speedup"] = 1.7
    print(f"dask: {n} sets in process {t_serial:.1f} s, 1 worker {out['workers_1_s']:.1f} s, 2 workers "
          f"{out['workers_2_s']:.1f} s: {out['speedup_2_over_1']:.2f}x; identical to in-process: "
          f"{out['workers_1_identical']} / {out['workers_2_identical']}", flush=True)
    return out


def bench_tolerance(n: int) -> dict:
    from gyro.analyses.tolerance import parse_spread, tolerance
    from gyro.models import load

    model = load(MODEL)
    t0 = time.perf_counter()
    study = tolerance(model, model.defaults, [parse_spread(s) for s in SPREADS], n, seed=1,
                      scheduler="local", harmonics=HARMONICS, band=0.02, progress=True)
    wall = time.perf_counter() - t0
    study.plot(RESULTS / "tolerance_histograms.png")
    study.sensitivities.plot(RESULTS / "tolerance_tornado.png",
                                title=f"{model.meta['title']}: relative sensitivities at the paper's set")
    print(study.table(), flush=True)
    print(f"tolerance: {n} samples in {wall:.1f} s on {os.cpu_count()} cores (goal for 1e7: 600 s)", flush=True)
    return {"samples": n, "wall_s": wall, "goal_s_for_1e7": 600.0, "spreads": SPREADS,
            "command": "gyro tolerance torsion_gyrocompass " + " ".join(f"--spread {s}" for s in SPREADS)
                       + f" --samples {n} --seed 1 --harmonics 1,2,3 --scheduler local",
            "study": study.to_dict(), "table": study.table()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.scale")
    ap.add_argument("--samples", type=int, default=10**7)
    ap.add_argument("--sweep", type=int, default=400000)  # long enough that task starts do not weigh (40 000: 1.7 s on two workers)
    ap.add_argument("--skip-tolerance", action="store_true")
    ap.add_argument("--sensitivities-only", action="store_true",
                    help="measure the sensitivities alone and print them; bench/results is not written")
    a = ap.parse_args(argv)
    if a.sensitivities_only:
        load0 = os.getloadavg()
        bench_sensitivities()
        print(f"load average at the start {load0[0]:.2f}, at the end {os.getloadavg()[0]:.2f}")
        return 0
    RESULTS.mkdir(parents=True, exist_ok=True)
    res = {"machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                       "load_average_at_start": os.getloadavg()}}
    res["sensitivities"] = bench_sensitivities()
    res["dask"] = bench_dask(a.sweep)
    if not a.skip_tolerance:
        res["tolerance"] = bench_tolerance(a.samples)
    elif (RESULTS / "scale.json").exists():  # the study of an earlier run stays, with its own load
        old = json.loads((RESULTS / "scale.json").read_text())
        if "tolerance" in old:
            res["tolerance"] = dict({"machine": old.get("machine")}, **old["tolerance"])
    res["machine"]["load_average_at_end"] = os.getloadavg()
    (RESULTS / "scale.json").write_text(json.dumps(res, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

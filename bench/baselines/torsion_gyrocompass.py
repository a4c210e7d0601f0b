"""Baseline: the torsion gyrocompass, bench/baseline_mechanics.py (sympy.physics.mechanics:
frames, points, two rigid bodies, LagrangesMethod -> Linearizer, the cyclic spin eliminated
through its integral), run as the other seed models' baselines are: derivation and one
linearisation at the given parameters and equilibrium, the operator's M, D, K returned in
the baseline's coordinate order `COORD_NAMES_10`."""
from __future__ import annotations

import time


def run(point: dict) -> dict:
    t0 = time.perf_counter()
    from bench import baseline_mechanics as bm

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    system = bm.derive_baseline(lambda s: None)
    t_derive = time.perf_counter() - t1
    t2 = time.perf_counter()
    M, D, K = bm.baseline_operator(point["params"], point["q0"], system=system)
    t_eval = time.perf_counter() - t2
    return {"import_s": t_import, "derive_s": t_derive, "evaluate_s": t_eval,
            "total_s": t_import + t_derive + t_eval, "steps_s": system.timings,
            "order": list(bm.COORD_NAMES_10),
            "values": {"M": M.tolist(), "D": D.tolist(), "K": K.tolist()}}


if __name__ == "__main__":
    from bench.baselines.common import main

    main(run)

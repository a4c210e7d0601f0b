"""Time this project's derivation of J(p) of the torsion gyrocompass, in a fresh process.

`python -m bench.derive_speed` prints one JSON line: the seconds from the model's energies
to the exact symbolic M, D, K (Routh reduction and second-order expansion), with the
same parameters symbolic throughout, and the operator evaluated at the paper example.
"""
from __future__ import annotations

import json
import time


def run() -> dict:
    t0 = time.perf_counter()
    from derive import mechanics as mech
    from derive.models import torsion_gyrocompass as tg

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    L = tg.lagrangian().subs({f: 0 for f in (tg.f1(tg.gamma3), tg.f2(tg.gamma3), tg.f3(tg.gamma3))})
    R = mech.routhian(L, tg.gamma3d, tg.H)
    q = [tg.q[tg.COORDINATES.index(c)] for c in tg.REDUCED]
    qd = [tg.qd[tg.COORDINATES.index(c)] for c in tg.REDUCED]
    op = mech.quadratic_expansion(R, q, qd, at={tg.q[tg.COORDINATES.index(c)]: 0 for c in tg.ODD})
    t_J = time.perf_counter() - t1
    return {"import_s": t_import, "derive_J_s": t_J,
            "ops": {k: int(sum(e.count_ops() for e in getattr(op, k))) for k in ("M", "D", "K")}}


if __name__ == "__main__":
    print(json.dumps(run()))

"""This project's generated C against CasADi's own C code generator, function by function.

`python -m bench.codegen_casadi [--evals N] [--repeats R] [--processes P]`: for every
emitted function of every generated model, casadi.CodeGenerator writes C for the same
casadi.Function (the one in generated/<model>/casadi_functions.py). Both are compiled by the
same compiler with the same flags (gyro.cbackend.FLAGS without -shared and -fPIC) into one
harness that calls each through a function pointer N times on the model's defaults (a
pointer call across translation units: nothing inlined or hoisted), alternating ours and
CasADi's, R times, ours first in even runs and CasADi's first in odd ones; the harness runs
as P processes one after another. Within one process the ratio ours / CasADi's (< 1: ours
faster) is the median of the runs' ratios; from one process to the next it can move by
15-20 % for a function that spills to the stack (where address randomisation puts the
stack), so the figure is the median over the processes, and a function is called faster or
slower only where every process says so. Both write only
the structural nonzeros of an output (their caller zeroes the rest once:
generated/<model>/<model>.h's contract);
ours at their positions in the row-major matrix, CasADi's packed column after column.
Ours' time includes that zeroing (a memset of its outputs before each run of N calls, as
CasADi's packed values in the shared buffers are not ours' zeros). The column "outputs
(CasADi nonzeros)" shows where the layout counts. Writes bench/results/codegen_casadi.json
and the table bench/results/codegen_casadi.md.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from gyro import cbackend, load
from gyro.catalog import available

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
FLAGS = [f for f in cbackend.FLAGS if f not in ("-shared", "-fPIC")]

HARNESS = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
typedef long long casadi_int;
%(decls)s
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
int main(int argc, char **argv)
{
    const long evals = atol(argv[1]), repeats = atol(argv[2]);
    volatile double sink = 0.0;
%(body)s
    return 0;
}
"""


def inputs_for(model, fname) -> list[np.ndarray]:
    """The defaults for params, the approximate equilibrium for qe, 0.1 elsewhere."""
    meta = model.meta["functions"][fname]
    p = model.vector(model.defaults)
    out = []
    for inp in meta["inputs"]:
        k = len(inp["symbols"])
        if inp["name"] == "params":
            out.append(p)
        elif inp["name"] == "qe" and "equilibrium_approx" in model.meta["functions"]:
            out.append(np.ravel(model.numpy.equilibrium_approx(p))[:k])
        else:
            out.append(np.full(k, 0.1))
    return out


def one_model(name: str, evals: int, repeats: int, tmp: Path, processes: int = 1) -> list[dict]:
    import casadi as ca

    model = load(name)
    cas = importlib.import_module(f"gyro.generated.{name}.casadi_functions")
    src = Path(model.directory) / f"{name}.c"
    decls, body, rows = [], [], []
    cg = ca.CodeGenerator(f"cas_{name}.c", {"with_header": False})
    for fname, meta in model.meta["functions"].items():
        f = getattr(cas, fname, None)
        if not isinstance(f, ca.Function):
            continue
        cg.add(f)
        ins = inputs_for(model, fname)
        outs = [o["shape"][0] * o["shape"][1] for o in meta["outputs"]]
        i = len(rows)
        rows.append({"model": name, "function": fname, "outputs": int(sum(outs)),
                     "output_nonzeros_casadi": int(sum(f.nnz_out(j) for j in range(f.n_out())))})
        decls.append(f"void {name}_{fname}({', '.join(['const double *'] * len(ins) + ['double *'] * len(outs))});")
        decls.append(f"int {fname}(const double **, double **, casadi_int *, double *, int);")
        decls.append(f"int {fname}_work(casadi_int *, casadi_int *, casadi_int *, casadi_int *);")
        lines = [f"  {{ /* {fname} */"]
        for j, x in enumerate(ins):
            vals = ", ".join(repr(float(v)) for v in x) or "0.0"
            lines.append(f"    static double in{j}[] = {{{vals}}};")
        for j, k in enumerate(outs):
            lines.append(f"    static double out{j}[{k}];")
        lines.append("    casadi_int na, nr, niw, nw;")
        lines.append(f"    {fname}_work(&na, &nr, &niw, &nw);")
        lines.append("    const double **arg = calloc(na + 1, sizeof(double *)); double **res = calloc(nr + 1, sizeof(double *));")
        lines.append("    casadi_int *iw = calloc(niw + 1, sizeof(casadi_int)); double *w = calloc(nw + 1, sizeof(double));")
        for j in range(len(ins)):
            lines.append(f"    arg[{j}] = in{j};")
        for j in range(len(outs)):
            lines.append(f"    res[{j}] = out{j};")
        ours_args = ", ".join([f"in{j}" for j in range(len(ins))] + [f"out{j}" for j in range(len(outs))])
        lines.append(f"    void (*volatile ours)({', '.join(['const double *'] * len(ins) + ['double *'] * len(outs))}) = {name}_{fname};")
        lines.append(f"    int (*volatile theirs)(const double **, double **, casadi_int *, double *, int) = {fname};")
        lines.append("    for (long r = 0; r < repeats; ++r) {")
        zero = " ".join(f"memset(out{j}, 0, sizeof out{j});" for j in range(len(outs)))
        # the order alternates run by run (ours first, then CasADi's first): whatever the
        # first of a pair pays or gains (a warmer cache, a clock ramping up) falls on both
        lines.append("      double ta, tb;")
        lines.append(f"      if (r % 2 == 0) {{ double t0 = now(); {zero} for (long e = 0; e < evals; ++e) {{ ours({ours_args}); sink += out0[0]; }}")
        lines.append("        double t1 = now(); for (long e = 0; e < evals; ++e) { theirs(arg, res, iw, w, 0); sink += out0[0]; }")
        lines.append("        double t2 = now(); ta = t1 - t0; tb = t2 - t1; }")
        lines.append("      else { double t0 = now(); for (long e = 0; e < evals; ++e) { theirs(arg, res, iw, w, 0); sink += out0[0]; }")
        lines.append(f"        double t1 = now(); {zero} for (long e = 0; e < evals; ++e) {{ ours({ours_args}); sink += out0[0]; }}")
        lines.append("        double t2 = now(); tb = t1 - t0; ta = t2 - t1; }")
        lines.append(f"      printf(\"%d %.6e %.6e\\n\", ta / evals, tb / evals);", )
        lines.append("    }")
        lines.append("  }")
        body.append("\n".join(lines).replace("%d", str(i)))
    cg.generate(str(tmp) + "/")
    harness = tmp / f"harness_{name}.c"
    harness.write_text(HARNESS % {"decls": "\n".join(decls), "body": "\n".join(body)})
    exe = tmp / f"harness_{name}"
    objs = []
    for c in (src, tmp / f"cas_{name}.c", harness):
        o = tmp / (c.stem + ".o")
        proc = subprocess.run(["gcc", *FLAGS, "-I", str(src.parent), "-c", str(c), "-o", str(o)],
                              capture_output=True, text=True)
        if proc.returncode:
            raise RuntimeError(f"gcc failed on {c.name}: {proc.stderr[:2000]}")
        objs.append(str(o))
    subprocess.run(["gcc", *objs, "-o", str(exe), "-lm"], check=True)
    # several processes: where the stack and the heap land (address randomisation) moves the
    # time of a function that spills by up to 15-20 % from one process to the next, more
    # than the alternation within one process can see
    times: dict[int, list[list[tuple[float, float]]]] = {}
    for _ in range(processes):
        out = subprocess.run([str(exe), str(evals), str(repeats)], check=True, capture_output=True, text=True).stdout
        runs: dict[int, list[tuple[float, float]]] = {}
        for line in out.split("\n"):
            if line.strip():
                k, a, b = line.split()
                runs.setdefault(int(k), []).append((float(a), float(b)))
        for k, v in runs.items():
            times.setdefault(k, []).append(v)
    for k, row in enumerate(rows):
        per = [np.array(v) for v in times[k]]  # per process: (repeats, 2)
        a = np.concatenate(per)
        row["ours_ns"] = float(np.median(a[:, 0]) * 1e9)
        row["casadi_ns"] = float(np.median(a[:, 1]) * 1e9)
        # per process the median of the ratio run by run (each run times both back to back);
        # the figure is their median, and their least and greatest say how far it moves
        proc = [float(np.median(p[:, 0] / p[:, 1])) for p in per]
        row["ratio_by_process"] = proc
        row["ratio_ours_over_casadi"] = float(np.median(proc))
        row["ratio_quartiles"] = [float(q) for q in np.percentile(a[:, 0] / a[:, 1], [25, 75])]
        # the medians of the ratio with ours first (even runs) and with CasADi's first (odd)
        row["ratio_by_order"] = {"ours_first": float(np.median(np.concatenate([p[0::2, 0] / p[0::2, 1] for p in per]))),
                                 "casadi_first": float(np.median(np.concatenate([p[1::2, 0] / p[1::2, 1] for p in per])))}
        row["verdict"] = ("faster" if max(proc) < 1 else "slower" if min(proc) > 1 else
                          "no difference beyond the processes' spread")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.codegen_casadi", description=__doc__.splitlines()[0])
    ap.add_argument("--evals", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=51)
    ap.add_argument("--processes", type=int, default=7, help="harness processes per model (default 7)")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in available():
            print(f"{name}: CasADi's code generator and ours, same compiler and flags ...", flush=True)
            rows += one_model(name, args.evals, args.repeats, Path(tmp), args.processes)
    lines = ["| model | function | outputs (CasADi nonzeros) | ours ns/eval | CasADi ns/eval | ours / CasADi "
             "| least-greatest over the processes | ours first / CasADi's first | verdict |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        p, o = r["ratio_by_process"], r["ratio_by_order"]
        lines.append(f"| {r['model']} | {r['function']} | {r['outputs']} ({r['output_nonzeros_casadi']}) | "
                     f"{r['ours_ns']:.1f} | {r['casadi_ns']:.1f} | {r['ratio_ours_over_casadi']:.2f} | "
                     f"{min(p):.2f}-{max(p):.2f} | {o['ours_first']:.2f} / {o['casadi_first']:.2f} | {r['verdict']} |")
        print(f"  {r['model']:22s} {r['function']:22s} ours {r['ours_ns']:9.1f} ns  CasADi {r['casadi_ns']:9.1f} ns"
              f"  ratio {r['ratio_ours_over_casadi']:.2f} ({min(p):.2f}-{max(p):.2f}, {r['verdict']})")
    RESULTS.mkdir(parents=True, exist_ok=True)
    note = (f"{args.processes} processes per model, each {args.repeats} runs of {args.evals} evaluations, ours "
            f"and CasADi's alternating in one process on a shared machine, ours first in even runs and "
            f"CasADi's first in odd ones. The ratio is the median over the processes of each one's median "
            f"ratio run by run; faster or slower where every process says so. gcc {' '.join(FLAGS)}.")
    (RESULTS / "codegen_casadi.md").write_text("\n".join(["# Generated C against casadi.CodeGenerator", "", note, "", *lines]) + "\n")
    (RESULTS / "codegen_casadi.json").write_text(json.dumps({"note": note, "rows": rows}, indent=1) + "\n")
    slower = [r for r in rows if r["ratio_ours_over_casadi"] > 1]
    verdicts = {v: sum(r["verdict"] == v for r in rows) for v in ("faster", "slower")}
    print(f"{len(rows) - len(slower)} of {len(rows)} functions at least as fast as CasADi's code by the median; "
          f"{verdicts['faster']} faster and {verdicts['slower']} slower in every process; written "
          f"bench/results/codegen_casadi.md")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())

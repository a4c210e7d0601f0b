"""A seeded fuzz of the command line: 1,200 command lines over every command and
parameter, valid and not (unknown names, NaN, inf, huge and tiny values, degenerate but
valid physics, bad output paths). Each must end in one of the contract's ways: exit 0
with strict output (one JSON object with --json, and no verdict beside a non-finite
number), or exit 2 (bad input) or 1 (numerical failure) with one line on stderr; never a
traceback, and never a run over 30 s."""
from __future__ import annotations

import contextlib
import io
import json
import math
import random
import time

import pytest

from gyro.cli import main
from gyro.models import load
from tests.conftest import error_lines

N_LINES = 1400
# another seed, and more lines of the fuzz of every command, for a run by hand (docs/fuzz.md):
# GYRO_FUZZ_SEED=11 GYRO_FUZZ_LINES=500 pytest tests/cli/test_fuzz.py -k seeded -p no:xdist
SEED = int(__import__("os").environ.get("GYRO_FUZZ_SEED", 20261130))
EVERY_LINES = int(__import__("os").environ.get("GYRO_FUZZ_LINES", 100))
WEIRD = ["nan", "inf", "-inf", "0", "-0", "-1", "1e-300", "1e300", "1e-12", "1e12", "abc", "", "1,5",
         "9223372036854775808", "3", "0.5", "-1e300"]


def _value(rng, default):
    r = rng.random()
    if r < 0.75:  # a valid-looking value near the default
        return repr(default * rng.choice([0.1, 0.5, 0.9, 1.0, 1.1, 2.0, 10.0]) if default else rng.choice([0.0, 0.1, 1.0]))
    return rng.choice(WEIRD)


def _sets(rng, model, extra=(), k=None):
    names = [p.name for p in model.params] + list(extra)
    out = []
    for _ in range(rng.randint(0, 3) if k is None else k):
        name = rng.choice(names + ["nosuch", "", "m=1"]) if rng.random() < 0.95 else "=3"
        default = next((p.default for p in model.params if p.name == name), 1.0)
        out += ["--set", f"{name}={_value(rng, default)}" if rng.random() < 0.97 else name]
    return out


def _out(rng, tmp, stem):
    return rng.choice([str(tmp / f"{stem}.png")] * 6 + [str(tmp), str(tmp / "nodir" / "x.png"), str(tmp / "x.txt"),
                                                         str(tmp / ("n" * 300 + ".png"))])


def command_lines(tmp):
    rng = random.Random(SEED)
    tg, gg, ghc = load("torsion_gyrocompass"), load("gimbal_gyroscope"), load("gyrohorizoncompass")
    models = ["torsion_gyrocompass", "gimbal_gyroscope", "nosuch"]
    for i in range(N_LINES):
        cmd = rng.choice(["frequencies"] * 5 + ["params", "sweep", "sweep", "campbell", "stability-map",
                                                "simulate", "simulate", "simulate", "bogus", "stability", "stability",
                                                "map", "ghc-simulate"])
        if cmd == "frequencies":
            model = rng.choice(models[:1] * 4 + models[1:])
            argv = [cmd, model] + _sets(rng, tg)
            if rng.random() < 0.6:
                argv += ["--method", rng.choice(["formulas", "polyroots", "companion", "default", "default",
                                                 "default", "nosuch"] + (["reference"] if rng.random() < 0.1 else []))]
            if rng.random() < 0.6:
                argv.append("--json")
        elif cmd == "params":
            argv = [cmd, rng.choice(models)]
        elif cmd == "sweep":
            x = rng.choice([p.name for p in tg.params] + ["nosuch"])
            lo, hi = rng.choice([("0.1", "1"), ("0", "1e-4"), ("1", "0"), ("-1", "1"), ("1e-300", "1e300"), ("nan", "1"),
                                 ("0.2", "inf")])
            argv = [cmd, "torsion_gyrocompass", "--x", x, "--x-range", lo, hi,
                    "--points", rng.choice(["2", "3", "5", "1", "0", "-3", "100001"])] + _sets(rng, tg, k=rng.randint(0, 1))
            if rng.random() < 0.3:
                argv += ["--method", rng.choice(["formulas", "companion", "default", "polyroots"])]
            argv += rng.choice([["--json"], [], ["--out", _out(rng, tmp, f"s{i}")]])
        elif cmd == "campbell":
            argv = [cmd, rng.choice(["torsion_gyrocompass"] * 4 + ["gimbal_gyroscope"]), "--out", _out(rng, tmp, f"c{i}"),
                    "--points", rng.choice(["2", "4", "6", "1", "-1", "100001"]), "--quiet"]
            argv += rng.choice([[], ["--range", "0.5", "2"], ["--range", "1", "inf"], ["--range", "2", "1"],
                                ["--range", "1e-300", "1e300"]]) + _sets(rng, tg, k=rng.randint(0, 1))
        elif cmd == "stability-map":
            x, y = rng.choice([p.name for p in tg.params] + ["nosuch"]), rng.choice(["H", "g", "l2", "u", "phi"])
            argv = [cmd, "torsion_gyrocompass", "--x", x, "--x-range", *rng.choice([("0.1", "0.3"), ("-0.5", "0.3"),
                                                                                    ("0", "1e300"), ("1", "1")]),
                    "--y", y, "--y-range", *rng.choice([("0.1", "1"), ("0", "1e-4"), ("-90", "90")]),
                    "--points", rng.choice(["2", "3", "4", "1", "1001"]), "--out", _out(rng, tmp, f"m{i}"), "--quiet"]
            argv += rng.choice([[], ["--x-log"], ["--y-log"]])
        elif cmd == "simulate":
            argv = [cmd, rng.choice(["gimbal_gyroscope"] * 6 + ["torsion_gyrocompass"]),
                    "--t-end", rng.choice(["0.01", "0.1", "1", "0", "-1", "nan", "1e308", "abc", "1e12"]),
                    "--points", rng.choice(["2", "5", "21", "1", "x", "9223372036854775808", "1000000000"])]
            argv += _sets(rng, gg, extra=("theta0", "dtheta0", "dpsi0", "dphi0"))
            if rng.random() < 0.3:
                m = rng.choice(["closed_form", "DOP853", "RK45", "cvodes", "nosuch"])
                argv += ["--method", m]
                if m not in ("closed_form", "nosuch"):
                    argv[argv.index("--t-end") + 1] = rng.choice(["0.01", "0.05"])
            argv += rng.choice([[], ["--json"], ["--out", _out(rng, tmp, f"t{i}")]])
        elif cmd == "stability":
            argv = [cmd, rng.choice(["gyrohorizoncompass"] * 5 + ["torsion_gyrocompass"])]
            argv += _sets(rng, ghc, extra=("lambda",)) + rng.choice([[], ["--orbit"]]) + rng.choice([[], ["--json"]])
        elif cmd == "map":
            axis = lambda: f"{rng.choice(['zeta', 'eta', 'theta', 'chi', 'nu', 'L', 'nosuch'])}={rng.choice(['0.05:0.8', '0:1', '1:0', 'nan:1', '0:1e300', '0.1'])}:{rng.choice(['3', '4', '1', '0', 'x', '100000'])}"  # noqa: E731
            argv = [cmd, "gyrohorizoncompass", "--x", axis(), "--y", axis(), "--out", _out(rng, tmp, f"g{i}")]
            argv += _sets(rng, ghc, k=rng.randint(0, 1)) + rng.choice([[], ["--json"], ["--orbit"]])
        elif cmd == "ghc-simulate":
            argv = ["simulate", "gyrohorizoncompass", "--t-end", rng.choice(["1", "10", "0", "-1", "nan", "1e308"]),
                    "--points", rng.choice(["2", "5", "1", "x"])] + _sets(rng, ghc, extra=("lambda",))
            argv += rng.choice([[], ["--perturb", "0.01,0,0,0"], ["--perturb", "1,2"], ["--perturb", "nan,0,0,0"],
                                ["--perturb", "1e300,0,0,0"]])
            argv += rng.choice([[], ["--json"], ["--method", rng.choice(["DOP853", "projected", "nosuch"])]])
        else:
            argv = [cmd] + rng.choice([[], ["--help-me"], ["torsion_gyrocompass"]])
        yield argv


N_VALID = 250
DEGENERATE = {"u": [0.0, 1e-20], "g": [0.0], "phi": [90.0, -90.0, 0.0], "H": [1e-9, 1e3], "Kgamma": [1e-9, 1e9],
              "I1": [1e-12], "l1": [-0.15, 0.0], "l2": [-0.25, 0.0], "K0": [1e-6, 1e12], "Kp": [1e-6, 1e12]}


def valid_lines(tmp):
    """Valid input only: every value within its kind and range, spread over decades, and the
    degenerate but valid sets (no Earth rate, no gravity, the pole, a free or a stiff
    bearing). These must never be refused as bad input."""
    rng = random.Random(SEED + 1)
    tg, gg = load("torsion_gyrocompass"), load("gimbal_gyroscope")

    def sets(model, degenerate=False):
        out = []
        free = [p for p in model.params if p.name != "C0"]  # the closed form needs C0 = 0
        for p in rng.sample(free, rng.randint(0, 3)):
            if degenerate and p.name in DEGENERATE:
                v = rng.choice(DEGENERATE[p.name])
            elif p.name == "phi":
                v = rng.uniform(-90, 90)
            else:
                v = p.default * 10 ** rng.uniform(-2, 2) if p.default else rng.uniform(0, 1)
                if p.kind == "real" and rng.random() < 0.3:
                    v = -v
            out += ["--set", f"{p.name}={v!r}"]
        return out

    from tests.cli.test_ghc_cli import LAB

    def lab_sets():
        v = dict(LAB)
        for k in rng.sample(["J", "L", "zeta", "eta"], 2):
            v[k] = v[k] * rng.uniform(0.8, 1.2)
        v["zeta"] = min(v["zeta"], 0.6 * 2 * v["L"] / v["I"])  # I lambda zeta/2L < 1: an equilibrium (lambda ~ 1)
        return [f"--set={k}={x!r}" for k, x in v.items()]

    for i in range(N_VALID):
        cmd = rng.choice(["frequencies"] * 4 + ["sweep", "campbell", "stability-map", "simulate", "simulate",
                                                "ghc"])
        if cmd == "ghc":
            argv = rng.choice([["stability", "gyrohorizoncompass", "--json"] + lab_sets(),
                               ["simulate", "gyrohorizoncompass", "--t-end", "5", "--points", "5", "--json",
                                "--perturb", "0.01,0,0,0"] + lab_sets(),
                               ["map", "gyrohorizoncompass", "--x", "zeta=0.05:0.85:3", "--y", "eta=-0.5:0.5:3",
                                "--out", str(tmp / f"vg{i}.png")] + [f"--set={k}={LAB[k]!r}" for k in ("A", "B", "C", "J", "L", "I", "nu")]])
            yield argv
            continue
        deg = rng.random() < 0.4
        if cmd == "frequencies":
            argv = [cmd, "torsion_gyrocompass"] + sets(tg, deg) + ["--method", rng.choice(
                ["formulas", "companion", "default", "default", "polyroots"])] + rng.choice([["--json"], []])
        elif cmd == "sweep":
            argv = [cmd, "torsion_gyrocompass", "--x", "H", "--x-range", "0.1", "1", "--points", "3", "--json"] + sets(tg, deg)
        elif cmd == "campbell":
            argv = [cmd, "torsion_gyrocompass", "--out", str(tmp / f"vc{i}.png"), "--points", "2", "--quiet"] + sets(tg, deg)
        elif cmd == "stability-map":
            argv = [cmd, "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.5", "0.3", "--y", "H", "--y-range",
                    "0.01", "10", "--y-log", "--points", "2", "--out", str(tmp / f"vm{i}.png"), "--quiet"] + sets(tg, deg)
        else:
            ic = [f"theta0={rng.uniform(0.05, 3.0)!r}", f"dtheta0={rng.uniform(-5, 5)!r}",
                  f"dpsi0={rng.uniform(-5, 5)!r}", f"dphi0={rng.uniform(-500, 500)!r}"]
            argv = [cmd, "gimbal_gyroscope", "--t-end", repr(rng.uniform(0.01, 10)), "--points", "11", "--json"]
            argv += [a for x in rng.sample(ic, 2) for a in ("--set", x)] + sets(gg)
            if rng.random() < 0.2:
                argv += ["--method", "DOP853", "--set", "C0=0.003"]
                argv[argv.index("--t-end") + 1] = "0.1"
        yield argv


N_NEWER = 260


def newer_lines(tmp):
    """The commands that came after the first fuzz: scene, level-map, tolerance, forced,
    unbalance, the precession's simulate with --level, and campbell's spin, harmonics and
    JSON; valid-looking values mixed with weird ones, small sizes."""
    rng = random.Random(SEED + 2)
    models = ["torsion_gyrocompass", "gimbal_gyroscope", "gyrohorizoncompass", "gimbal_precession", "nosuch"]
    loaded = {m: load(m) for m in models[:-1]}
    tg, gp = loaded["torsion_gyrocompass"], loaded["gimbal_precession"]

    def w(choices):  # a valid-looking value, one time in twelve a weird one
        return rng.choice(choices) if rng.random() < 11 / 12 else rng.choice(WEIRD)

    for i in range(N_NEWER):
        cmd = rng.choice(["scene", "scene", "level-map", "tolerance", "forced", "unbalance", "precession", "campbell"])
        if cmd == "scene":
            model = rng.choice(models)
            argv = [cmd, model, rng.choice(["frequencies", "stability", "motion", "nosuch"]), "--tol", w(["1e-3", "1e-6", "0.1"])]
            argv += rng.choice([[], ["--modes", w(["1", "2,1", "0", "99"])], ["--t-end", w(["1", "5"])],
                                ["--horizon", w(["1", "2"])]])
            argv += _sets(rng, loaded.get(model, tg), k=rng.randint(0, 1)) + rng.choice([[], ["--json"]])
        elif cmd == "level-map":
            if rng.random() < 0.5:
                lv = [rng.choice(["elementary", "small", "rigorous", "image", "full", "nosuch"]) for _ in range(2)]
                ax = [f"k_xi1={w(['0:1e-4', '1e-4:0', '0:1e300'])}:{w(['2', '3', '1'])}",
                      f"l_x={w(['5e-4:1e-3', 'nan:1'])}:{w(['2', '0'])}"]
                argv = [cmd, "gimbal_precession", "--level", lv[0], "--against", lv[1], "--t-end", w(["0.5", "1"])]
            else:
                lv = [rng.choice(["formulas", "decoupled", "linear_paper", "linear_exact", "nosuch"]) for _ in range(2)]
                ax = [f"u={w(['5e-5:1e-4', '1:0'])}:{w(['2', '3'])}", f"H={w(['1:3', '0:1e300'])}:{w(['2', 'x'])}"]
                argv = [cmd, "torsion_gyrocompass", "--level", lv[0], "--against", lv[1]]
            argv += ["--x", ax[0], "--y", ax[1], "--out", _out(rng, tmp, f"lm{i}")] + rng.choice([[], ["--json"], ["--tol", w(["0.01", "2"])]])
        elif cmd == "tolerance":
            name = rng.choice([p.name for p in tg.params] + ["nosuch"])
            argv = [cmd, "torsion_gyrocompass", "--spread", f"{name}={rng.choice(['normal', 'uniform', 'gauss'])}:{w(['0.05', '0.1'])}",
                    "--samples", w(["10", "20", "1"]), "--quiet"]
            argv += rng.choice([[], ["--seed", w(["1", "2"])], ["--harmonics", w(["1", "1,2"])], ["--band", w(["0.01"])],
                                ["--correlate", f"Kp,{name}={w(['0.5', '2'])}"]])
            argv += rng.choice([["--json"], ["--out", _out(rng, tmp, f"tl{i}")], ["--tornado", _out(rng, tmp, f"tt{i}")]])
        elif cmd == "forced":
            h = f"{w(['1', '2', '3', '0'])}:{w(['1', '2'])}:{w(['0.01', '1', '-1'])}" + rng.choice(["", f":{w(['0.5'])}"])
            argv = [cmd, rng.choice(["torsion_gyrocompass"] * 4 + ["gimbal_gyroscope"]), "--harmonic", h]
            argv += _sets(rng, tg, k=rng.randint(0, 1)) + rng.choice([["--json"], [], ["--out", _out(rng, tmp, f"f{i}")]])
        elif cmd == "unbalance":
            argv = [cmd, rng.choice(["torsion_gyrocompass"] * 4 + ["gyrohorizoncompass"]), "--force-x", rng.choice(["F1", "F2", "x"]),
                    "--force-y", rng.choice(["F2", "F3", "F1"]), "--magnitude", w(["1e-4", "1"]),
                    "--spin-range", w(["0.5", "1"]), w(["2", "0.5"]), "--points", w(["3", "5", "1"]), "--quiet"]
            argv += rng.choice([[], ["--phase", w(["0.3"])], ["--spin", rng.choice(["H", "u", "nosuch"])]])
            argv += rng.choice([["--json"], ["--out", _out(rng, tmp, f"u{i}")]])
        elif cmd == "precession":
            argv = ["simulate", "gimbal_precession", "--level", rng.choice(["elementary", "small", "rigorous", "image", "full", "x"]),
                    "--t-end", w(["0.5", "2", "1e12"]), "--points", w(["3", "5", "1"])] + _sets(rng, gp, k=rng.randint(0, 2))
            argv += rng.choice([["--json"], [], ["--out", _out(rng, tmp, f"p{i}")]])
        else:
            argv = [cmd, rng.choice(["torsion_gyrocompass", "gyrohorizoncompass", "gimbal_precession"]), "--points", w(["2", "3"]),
                    "--quiet"] + rng.choice([[], ["--spin", rng.choice(["H", "u", "nu", "nosuch"])],
                                             ["--spin-range", w(["0.5", "1"]), w(["2", "1"])], ["--harmonics", w(["1", "1,2", "0"])]])
            argv += rng.choice([["--json"], ["--out", _out(rng, tmp, f"cb{i}")]])
        yield argv


def run(argv):
    """(exit code, stdout, stderr, seconds) of one command line in this process; stderr
    without the one-off notice of a first compile (a cold cache: whichever test needs a
    model's C first prints it), which precedes the command's own line."""
    out, err = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse's usage errors
            code = exc.code
    err = "".join(line for line in err.getvalue().splitlines(keepends=True)
                  if not line.startswith("gyro: compiling the generated C"))
    return code, out.getvalue(), err, time.perf_counter() - t0


@pytest.fixture
def short_budgets(monkeypatch):
    """The integrators' wall-time budget at 2 s instead of the command line's 25: a runaway
    (--t-end 1e308) still has to stop by it and end in exit 1 with one line, sooner."""
    from gyro.systems import gimbal_gyroscope as gimbal, gyrohorizoncompass

    for mod in (gimbal, gyrohorizoncompass):
        monkeypatch.setattr(mod, "BUDGET_SECONDS", 2.0)


def _contract(argv, code, out, err, dt):
    where = " ".join(argv)
    assert dt < 30, f"{where}: {dt:.1f} s"
    assert "Traceback" not in err and "Traceback" not in out, where
    assert code in (0, 1, 2), f"{where}: exit {code}"
    if code:
        assert len(error_lines(err)) == 1 and error_lines(err)[0].startswith(("gyro", "usage")), f"{where}: {err!r}"
    elif "--json" in argv:
        doc = json.loads(out, parse_constant=lambda c: pytest.fail(f"{where}: {c} in the JSON"))
        # no verdict beside a non-finite frequency
        if isinstance(doc, dict) and "stability" in doc and isinstance(doc["stability"], dict):
            if doc["stability"]["class"] not in ("failed", "unknown"):
                assert all(math.isfinite(f) for f in doc["frequencies"]), where


def test_fuzz_of_the_command_line(tmp_path, short_budgets):
    worst, count = 0.0, 0
    for argv in command_lines(tmp_path):
        code, out, err, dt = run(argv)
        count += 1
        worst = max(worst, dt)
        _contract(argv, code, out, err, dt)
    assert count == N_LINES and worst < 30


def test_valid_input_is_answered_or_fails_numerically_never_refused(tmp_path):
    codes = []
    for argv in valid_lines(tmp_path):
        code, out, err, dt = run(argv)
        where = " ".join(argv)
        assert dt < 30, f"{where}: {dt:.1f} s"
        # valid input is answered; the exceptions are a paper formula outside its domain
        # (a square root of a negative number at far-off parameters) and a degenerate set at
        # which no point balances the equilibrium equations (gyro.equilibrium's residual
        # test: g = 0 with a torsion stiffness of 1e-9, tests/methods/test_rightmodel.py): exit 1,
        # one line naming the residual
        formulas = "--method" in argv and argv[argv.index("--method") + 1] == "formulas"
        unbalanced = err.startswith("gyro: error: no equilibrium found:") and "keeps a residual" in err
        assert "Traceback" not in err and (code == 0 or (code == 1 and (formulas or unbalanced))), \
            f"{where}: exit {code}: {err}"
        if code:
            assert len(error_lines(err)) == 1, f"{where}: {err!r}"
        elif "--json" in argv:
            json.loads(out, parse_constant=lambda c: pytest.fail(f"{where}: {c} in the JSON"))
        codes.append(code)
    assert len(codes) == N_VALID


def test_fuzz_of_the_newer_commands(tmp_path, short_budgets):
    codes = []
    for argv in newer_lines(tmp_path):
        code, out, err, dt = run(argv)
        _contract(argv, code, out, err, dt)
        codes.append(code)
    assert len(codes) == N_NEWER and {0, 2} <= set(codes)  # answers and refusals both met


# ------------------------------------------------------------------ every command, and model paths
# The classes of issue 41 (docs/fuzz.md): each command line below once fell short in one of
# them (a traceback, a runaway, a wrong exit, a contradiction accepted, a non-number printed,
# something left behind, noise on stderr). Run in this process, under a temporary folder of
# their own (TMPDIR), which must be empty after every command.

LONG_NAME = "m" * 300 + ".py"  # over NAME_MAX (255 bytes)
SECONDS = 30  # a command's wall time at the most (each below runs in about 1 s or less)


def issue_lines(tmp):
    """The command lines of the issue's classes, one or more each, for every command."""
    deep = "/" + "/".join(["d" * 200] * 25) + ".py"  # over PATH_MAX (4096 bytes)
    tg = ["torsion_gyrocompass"]
    sweep = ["sweep", *tg, "--x", "H", "--x-range", "0.1", "1", "--points", "3"]
    tol = ["tolerance", *tg, "--spread", "Kp=normal:0.05", "--spread", "K0=normal:0.05", "--quiet"]
    unb = ["unbalance", *tg, "--force-x", "F1", "--force-y", "F2", "--magnitude", "1e-4", "--spin-range", "0.5",
           "2", "--points", "3", "--quiet"]
    png = str(tmp / "out.png")
    yield from ([cmd, path] + rest for path in (LONG_NAME, deep) for cmd, rest in (
        ("frequencies", []), ("params", []), ("stability", []), ("campbell", ["--json"]),
        ("scene", ["frequencies", "--tol", "1e-3"]), ("level-map", ["--level", "a", "--against", "b", "--x", "u=0:1:2",
                                                                    "--y", "H=1:2:2", "--out", png]),
        ("unbalance", unb[2:]), ("tolerance", tol[2:] + ["--samples", "10"]), ("sweep", sweep[2:]),
        ("stability-map", ["--x", "H", "--x-range", "0.1", "1", "--y", "u", "--y-range", "0", "1e-4", "--out", png])))
    for out in ("", str(tmp / LONG_NAME.replace(".py", ".png")), "/proc/gyro-fuzz.png", str(tmp / "no" / "x.png")):
        yield ["campbell", *tg, "--points", "2", "--quiet", "--out", out]
        yield sweep + ["--out", out]
        yield ["forced", *tg, "--harmonic", "1:1:1", "--out", out]
        yield tol + ["--samples", "10", "--out", out]
        yield tol + ["--samples", "10", "--tornado", out]
        yield unb + ["--out", out]
        yield ["simulate", "gimbal_gyroscope", "--t-end", "0.1", "--points", "3", "--out", out]
        yield ["map", "gyrohorizoncompass", "--x", "zeta=0.05:0.8:2", "--y", "eta=-0.5:0.5:2", "--out", out]
    yield ["forced", *tg, "--harmonic", "1:1:1", "--set", "Kp=1e300"]
    yield unb[:7] + ["1e300", "--spin-range", "0", "1e300", "--points", "3", "--quiet"]
    yield ["sweep", "gimbal_precession", "--x", "k_xi1", "--x-range", "0", "1e-4", "--points", "3"]
    yield ["tolerance", "gimbal_precession", "--spread", "l_x=normal:0.05", "--samples", "10", "--quiet"]
    yield tol + ["--samples", "10", "--correlate", "Kp,K0=0.5", "--correlate", "K0,Kp=-0.5"]
    yield tol + ["--samples", "10", "--correlate", "Kp,K0=0.5", "--correlate", "Kp,K0=0.5"]
    yield tol + ["--samples", "1"]
    yield tol + ["--samples", "10", "--store", "/proc/gyro-fuzz/store"]
    yield tol + ["--samples", "10000000"]
    yield tol + ["--samples", "1000000000"]
    yield ["frequencies", *tg, "--set", "A=1e-300"]
    yield ["frequencies", *tg, "--set", "u=5e-324"]
    yield ["frequencies", "gimbal_precession"]
    yield ["scene", "gimbal_gyroscope", "motion", "--tol", "1e-30"]
    yield ["scene", "gimbal_gyroscope", "motion", "--tol", "1e-3", "--horizon", "1e6"]
    yield ["scene", "gyrohorizoncompass", "motion", "--tol", "1e-3", "--horizon", "1e6"]
    yield ["map", "gyrohorizoncompass", "--x", "nu=1e-4:1e-3:1000", "--y", "eta=0:0.1:1000", "--out", png]
    yield ["level-map", "gimbal_precession", "--level", "small", "--against", "full", "--x", "k_xi1=0:1e-4:100",
           "--y", "l_x=5e-4:1e-3:100", "--out", png]
    for method in ("cvodes", "idas"):
        yield ["simulate", "gimbal_gyroscope", "--method", method, "--t-end", "1e308", "--points", "5"]


def every_command_lines(tmp, n):
    """n seeded lines over every command, valid-looking values mixed with the weird ones and
    with the model paths that are no model (too long, missing, a folder, a junk folder)."""
    rng = random.Random(SEED + 3)
    tg = load("torsion_gyrocompass")
    junk = tmp / "junk_model"
    models = ["torsion_gyrocompass"] * 6 + [LONG_NAME, str(tmp / "none.py"), str(tmp), str(junk)]

    def model():
        return rng.choice(models)

    def w(choices):
        return rng.choice(choices) if rng.random() < 0.8 else rng.choice(WEIRD)

    def out(stem):
        return rng.choice([[], ["--out", str(tmp / f"{stem}.png")], ["--out", ""], ["--out", "/proc/x.png"]])

    for i in range(n):
        cmd = rng.choice(["scene", "stability", "map", "sweep", "level-map", "tolerance", "forced", "unbalance",
                          "simulate", "campbell", "frequencies", "stability-map", "params"])
        if cmd == "scene":
            argv = [cmd, model(), rng.choice(["frequencies", "stability", "motion"]), "--tol", w(["1e-3", "1e-30", "0.1"])]
        elif cmd == "stability":
            argv = [cmd, rng.choice(["gyrohorizoncompass", "torsion_gyrocompass", LONG_NAME])]
        elif cmd == "map":
            argv = [cmd, "gyrohorizoncompass", "--x", f"nu={w(['1e-4:1e-3'])}:{w(['2', '3', '1000'])}",
                    "--y", f"eta={w(['0:0.1'])}:{w(['2', '1000'])}"] + (out(f"g{i}") or ["--out", ""])
        elif cmd == "sweep":
            argv = [cmd, model(), "--x", "H", "--x-range", w(["0.1"]), w(["1"]), "--points", w(["2", "3"])] + out(f"s{i}")
        elif cmd == "level-map":
            argv = [cmd, model(), "--level", "formulas", "--against", "linear_exact", "--x", f"u={w(['5e-5:1e-4'])}:2",
                    "--y", f"H={w(['1:3'])}:2"] + (out(f"l{i}") or ["--out", ""])
        elif cmd == "tolerance":
            argv = [cmd, model(), "--spread", f"Kp=normal:{w(['0.05'])}", "--samples", w(["10", "1", "10000000"]),
                    "--quiet"] + rng.choice([[], ["--correlate", "Kp,Kp=0.5"]]) + out(f"t{i}")
        elif cmd == "forced":
            argv = [cmd, "torsion_gyrocompass", "--harmonic", f"1:1:{w(['1'])}"] + _sets(rng, tg, k=1) + out(f"f{i}")
        elif cmd == "unbalance":
            argv = [cmd, model(), "--force-x", "F1", "--force-y", "F2", "--magnitude", w(["1e-4"]), "--spin-range",
                    "0.5", "2", "--points", w(["3"]), "--quiet"] + out(f"u{i}")
        elif cmd == "simulate":
            argv = [cmd, rng.choice(["gimbal_gyroscope", LONG_NAME]), "--t-end", w(["0.1", "1e308"]), "--points", "3",
                    "--method", rng.choice(["closed_form", "DOP853", "cvodes"])]
            if argv[4] == "1e308" and argv[-1] == "DOP853":
                argv[4] = "0.1"  # a SciPy integrator to 1e308 runs to its 25 s budget: too long for a fuzz
        elif cmd == "campbell":
            argv = [cmd, model(), "--points", w(["2", "3"]), "--quiet"] + (out(f"c{i}") or ["--json"])
        elif cmd == "frequencies":
            argv = [cmd, model()] + _sets(rng, tg)
        elif cmd == "stability-map":
            argv = [cmd, model(), "--x", "H", "--x-range", "0.1", "1", "--y", "u", "--y-range", "0", w(["1e-4"]),
                    "--points", w(["2", "3"]), "--quiet"] + (out(f"m{i}") or ["--out", ""])
        else:
            argv = [cmd, model()]
        yield argv


NUMBER_WORDS = __import__("re").compile(r"(?<![A-Za-z_])-?(nan|inf)(?![A-Za-z_])", __import__("re").I)


def _holds(argv, code, out, err, dt, tmp, scratch):
    """The contract of every command line, as docs/fuzz.md states it."""
    where = " ".join(a if len(a) < 80 else a[:30] + "..." for a in argv)
    assert dt < SECONDS, f"{where}: {dt:.1f} s"
    assert "Traceback" not in err + out, f"{where}: {err}"
    assert code in (0, 1, 2), f"{where}: exit {code}"
    if code:
        assert len(error_lines(err)) == 1 and error_lines(err)[0].startswith(("gyro", "usage")), f"{where}: {err!r}"
        assert "np.float64" not in err and "__init__.py" not in err, f"{where}: {err!r}"
        assert not err.startswith(("gyro: error: omega:", "gyro: error: u:")), f"{where}: an internal name: {err!r}"
    if code == 2:
        assert out == "", f"{where}: stdout on bad input: {out[:200]!r}"
    if code == 0 and "--json" not in argv:
        assert not NUMBER_WORDS.search(out), f"{where}: a non-number printed as a number:\n{out}"
    assert not any(scratch.iterdir()), f"{where}: left in the temporary folder: {sorted(scratch.iterdir())}"
    left = [p.name for p in tmp.iterdir() if p.name.startswith(".")]
    assert not left, f"{where}: left beside the outputs: {left}"


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """TMPDIR for the commands: a folder of the test's own, checked empty after each."""
    import tempfile

    folder = tmp_path / "tmpdir"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    return folder


def _junk_model(tmp):
    """A folder that looks emitted (an __init__.py beside a metadata.json) but is junk."""
    junk = tmp / "junk_model"
    junk.mkdir(exist_ok=True)
    (junk / "__init__.py").write_text("import json\nfrom pathlib import Path\n"
                                      "METADATA = json.loads((Path(__file__).parent / 'metadata.json').read_text())\n")
    (junk / "metadata.json").write_text("{junk")
    return junk


def test_the_issue_classes_on_every_command(tmp_path, scratch, short_budgets):
    outs = tmp_path / "outs"
    outs.mkdir()
    codes = {}
    for argv in issue_lines(outs):
        code, out, err, dt = run(argv)
        _holds(argv, code, out, err, dt, outs, scratch)
        codes[" ".join(argv)[:120]] = code
    assert set(codes.values()) <= {0, 1, 2} and 2 in codes.values()
    # the exits the issue names, exactly
    assert all(c == 2 for k, c in codes.items() if LONG_NAME[:100] in k or "--out  " in k or k.endswith("--out"))
    assert codes["forced torsion_gyrocompass --harmonic 1:1:1 --set Kp=1e300"] == 1


def test_the_issue_errors_name_what_the_user_gave(scratch):
    """Each refusal names the argument the user typed, never an internal one."""
    says = {("forced", "torsion_gyrocompass", "--harmonic", "1:1:1", "--set", "Kp=1e300"): "Kp=1e300",
            ("tolerance", "torsion_gyrocompass", "--spread", "Kp=normal:0.05", "--spread", "K0=normal:0.05",
             "--samples", "10", "--correlate", "Kp,K0=0.5", "--correlate", "K0,Kp=-0.5"): "--correlate",
            ("tolerance", "torsion_gyrocompass", "--spread", "Kp=normal:0.05", "--samples", "1"): "--samples",
            ("tolerance", "torsion_gyrocompass", "--spread", "Kp=normal:0.05", "--samples", "10000000"): "--samples",
            ("campbell", "torsion_gyrocompass", "--out", ""): "--out",
            ("sweep", "torsion_gyrocompass", "--x", "H", "--x-range", "0.1", "1", "--out", "/proc/x.png"): "--out",
            ("frequencies", LONG_NAME): "File name too long",
            ("scene", "gimbal_gyroscope", "motion", "--tol", "1e-3", "--horizon", "1e6"): "--horizon"}
    for argv, word in says.items():
        code, out, err, _ = run(list(argv))
        assert code in (1, 2) and word in err and "omega" not in err, (argv, err)


def test_every_command_under_a_seeded_fuzz(tmp_path, scratch, short_budgets):
    outs = tmp_path / "outs"
    outs.mkdir()
    _junk_model(outs)
    codes = []
    for argv in every_command_lines(outs, EVERY_LINES):
        code, out, err, dt = run(argv)
        _holds(argv, code, out, err, dt, outs, scratch)
        codes.append((argv[0], code))
    assert {c for _, c in codes} >= {0, 2}
    assert {cmd for cmd, _ in codes} == {"scene", "stability", "map", "sweep", "level-map", "tolerance", "forced",
                                         "unbalance", "simulate", "campbell", "frequencies", "stability-map", "params"}


def test_a_junk_model_folder_is_one_clean_line_every_time(tmp_path):
    """gyro.load of a junk emitted folder fails naming its metadata.json, the same way
    again in the same process (the half-imported package is not kept)."""
    from gyro.errors import ParameterError

    junk = _junk_model(tmp_path)
    for _ in range(2):
        with pytest.raises(ParameterError, match="metadata.json"):
            load(junk)
    assert not (junk / "__pycache__").exists()


def test_a_model_file_that_fails_to_derive_says_one_line_and_leaves_nothing(tmp_path, monkeypatch):
    """Derived once (the notice and the line), then cached as failed: one line, and no
    __pycache__ beside the file or the module it imports."""
    monkeypatch.setenv("GYRO_CACHE", str(tmp_path / "cache"))
    src = tmp_path / "src"
    src.mkdir()
    (src / "helper.py").write_text("VALUE = 2\n")
    (src / "broken.py").write_text("import helper\n\n\ndef build():\n    raise ValueError('no model here')\n")
    errs = []
    for _ in range(2):
        code, out, err, dt = run(["params", str(src / "broken.py")])
        assert code == 2 and out == "" and "no model here" in err.splitlines()[-1], err
        errs.append([ln for ln in err.splitlines() if ln.strip()])
    assert len(errs[1]) == 1 and errs[1][0] == errs[0][-1]
    assert sorted(p.name for p in src.iterdir()) == ["broken.py", "helper.py"]


def _signals_delivered():
    """In the child before exec: SIGINT handled by default (a shell's background job ignores
    it) and neither signal blocked (a mask the test process may carry from a library)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})


@pytest.mark.parametrize("sig, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_stopped_tolerance_leaves_no_temporary_folder(tmp_path, sig, code):
    """A study large enough for its on-disk arrays (the threshold lowered here), stopped
    while it runs: one line, the signal's exit code, and the temporary folder empty."""
    import os
    import signal
    import subprocess
    import sys

    scratch = tmp_path / "tmpdir"
    scratch.mkdir()
    driver = ("import sys\nimport gyro.analyses.tolerance as t\nt.IN_MEMORY = 1000\nfrom gyro.cli import main\n"
              "sys.exit(main(['tolerance', 'torsion_gyrocompass', '--spread', 'Kp=normal:0.05', "
              "'--samples', '400000', '--quiet']))\n")
    p = subprocess.Popen([sys.executable, "-c", driver], env=dict(os.environ, TMPDIR=str(scratch)),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=_signals_delivered)
    t0 = time.monotonic()
    while not any(scratch.iterdir()) and p.poll() is None and time.monotonic() - t0 < 60:
        time.sleep(0.05)  # until the study's folder is there: stopped while it runs
    assert p.poll() is None, p.communicate()
    p.send_signal(getattr(signal, sig))
    out, err = p.communicate(timeout=60)
    assert p.returncode == code and out == "" and len(error_lines(err)) == 1, (p.returncode, err)
    assert not any(scratch.iterdir()), sorted(scratch.iterdir())


def test_sundials_and_casadi_say_nothing_on_stderr(tmp_path):
    """SUNDIALS' own lines (IDACalcIC's) and CasADi's warnings (a NaN of the right-hand side
    at a horizon of 1e308) go to file descriptor 2, past Python's sys.stderr: in a process
    of its own, every CasADi integrator's failure is the command's one line, nothing else."""
    import subprocess
    import sys

    lines = [["simulate", "gimbal_gyroscope", "--method", "idas", "--t-end", "1e308", "--points", "5"],
             ["simulate", "gimbal_gyroscope", "--method", "cvodes", "--t-end", "1e308", "--points", "5"],
             ["simulate", "gyrohorizoncompass", "--method", "cvodes-adams", "--t-end", "1e308", "--points", "5"],
             # a precession level's own CVODES near +-90 deg (newer_lines under SEED 22, its line 257):
             # 316814 lines of CasADi's NaN warnings and 54 s before, one line in 7 s now
             ["simulate", "gimbal_precession", "--level", "small", "--t-end", "0.2", "--points", "2", "--set",
              "f_phi=1"]]
    says = ["idas stopped", "cvodes stopped", "cvodes-adams stopped", "small: the integration stopped near"]
    driver = ("import os, sys\nfrom gyro.cli import main\n"
              f"for argv in {lines!r}:\n"
              "    code = main(argv)\n    sys.stderr.flush()\n    os.write(2, f'exit {code}\\n'.encode())\n")
    p = subprocess.run([sys.executable, "-c", driver], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == 0 and p.stdout == "", p.stderr
    said = [ln for ln in p.stderr.splitlines() if not ln.startswith("gyro: compiling the generated C")]
    for k, argv in enumerate(lines):
        line, code = said[2 * k: 2 * k + 2]
        assert line.startswith("gyro: error: ") and says[k] in line and code in ("exit 1", "exit 2"), said
    assert len(said) == 2 * len(lines), said

"""docs/models.md runs as written.

The guide's code blocks are run and their printed output is compared to the page:

- ```python blocks are excerpts of the example model: each must appear verbatim in
  docs/examples/damped_pendulum.py;
- ```console blocks are shell sessions: each line starting with `$ ` is a command, run by
  bash in the repository root with stderr merged into stdout; the lines up to the next
  command are its expected output. A line `...` stands for any number of lines, and a
  duration (`0.01 s`) matches any duration;
- ```pycon blocks are one Python session (started in the repository root, shared by all
  blocks, in the page's order, after the shell blocks), run by doctest: text compares
  exactly (up to whitespace, `...` matching anything as doctest's ELLIPSIS), numbers to a
  relative tolerance of 1e-9.

The page writes its output folder as /tmp/pendulum; the test replaces that string,
everywhere in the page (commands, code and expected output), by a temporary folder, and
compiles the C into a temporary cache ($GYRO_CACHE).

`python tests/generated/test_docs_models.py --fill` rewrites the expected outputs of the page's Python
session with what it prints now (console blocks are updated by hand): run the shell blocks
into /tmp/pendulum first. For updating the guide, never in a test.
"""
from __future__ import annotations

import doctest
import math
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "models.md"
EXAMPLE = ROOT / "docs" / "examples" / "damped_pendulum.py"
PLACEHOLDER = "/tmp/pendulum"  # the page's output folder

FENCE = re.compile(r"^```(\w*)\n(.*?)^```\n", re.S | re.M)
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
DURATION = re.compile(r"\d+\.\d+ s\b")
RTOL = 1e-9


def blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of every fenced block of the page, in order."""
    return [(m.group(1), m.group(2)) for m in FENCE.finditer(text)]


# --------------------------------------------------------------------------- shell


def shell_session(body: str) -> list[tuple[str, list[str]]]:
    """(command, expected output lines) of a console block."""
    out = []
    for line in body.splitlines():
        if line.startswith("$ "):
            out.append((line[2:], []))
        elif out:
            out[-1][1].append(line)
        elif line.strip():
            raise ValueError(f"console block: output before any command: {line!r}")
    return out


def expected_pattern(lines: list[str]) -> re.Pattern:
    """The expected output as a regular expression: `...` lines match any lines, durations
    any duration, everything else literally."""
    parts = []
    for line in lines:
        if line == "...":
            parts.append(r"(?:[^\n]*\n)*?")
        else:
            pieces = DURATION.split(line)
            parts.append(r"\d+\.\d+ s".join(re.escape(p) for p in pieces) + r"\n")
    return re.compile("".join(parts))


def run_command(command: str, env: dict) -> str:
    proc = subprocess.run(["bash", "-c", command], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=120)
    return proc.stdout


# --------------------------------------------------------------------------- python


def _numbers_close(want: str, got: str) -> bool:
    """Same text between the numbers (whitespace normalised), numbers within RTOL."""
    w_nums, g_nums = NUMBER.findall(want), NUMBER.findall(got)
    w_text = " ".join(NUMBER.sub("#", want).split())
    g_text = " ".join(NUMBER.sub("#", got).split())
    if w_text != g_text or len(w_nums) != len(g_nums):
        return False
    return all(math.isclose(float(a), float(b), rel_tol=RTOL, abs_tol=0.0) for a, b in zip(w_nums, g_nums))


class Checker(doctest.OutputChecker):
    def check_output(self, want, got, optionflags):
        if super().check_output(want, got, optionflags):
            return True
        return "..." not in want and _numbers_close(want, got)


class Recorder(doctest.DocTestRunner):
    """Runs the session accepting anything and keeps what each example printed (--fill)."""

    def __init__(self):
        class Anything(doctest.OutputChecker):
            def check_output(self, want, got, optionflags):
                return True

        super().__init__(checker=Anything())
        self.got = {}

    def report_success(self, out, test, example, got):
        self.got[id(example)] = got

    def report_unexpected_exception(self, out, test, example, exc_info):
        import traceback

        self.got[id(example)] = "".join(traceback.format_exception(*exc_info))
        sys.stderr.write(f"unexpected exception in: {example.source}{self.got[id(example)]}")


def python_test(text: str, doc: Path = DOC) -> doctest.DocTest:
    """The page's pycon blocks as one doctest, with the page's line numbers."""
    examples = []
    for m in FENCE.finditer(text):
        if m.group(1) == "pycon":
            start = text.count("\n", 0, m.start(2))
            for ex in doctest.DocTestParser().get_examples(m.group(2)):
                ex.lineno += start
                examples.append(ex)
    return doctest.DocTest(examples, {"__name__": "__main__"}, doc.relative_to(ROOT).as_posix(), str(doc), 0, None)


def run_python(text: str, doc: Path = DOC) -> tuple[int, str]:
    """Run the page's Python session here (in a fresh process); (failures, report)."""
    import io

    out = io.StringIO()
    runner = doctest.DocTestRunner(checker=Checker(), optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(python_test(text, doc), out=out.write)
    return runner.failures, out.getvalue()


# --------------------------------------------------------------------------- the page


def page(folder: str) -> str:
    return DOC.read_text().replace(PLACEHOLDER, folder)


def environment(cache: Path) -> dict:
    env = dict(os.environ)
    env["GYRO_CACHE"] = str(cache)
    env.pop("LC_ALL", None)
    env["LC_COLLATE"] = "C"  # `ls` sorts as the page shows it in any locale
    env.pop("PYTHONPATH", None)
    return env


def test_model_excerpts_are_the_example_file():
    source = EXAMPLE.read_text()
    excerpts = [body for lang, body in blocks(DOC.read_text()) if lang == "python"]
    assert excerpts, "the guide shows no part of the example model"
    for body in excerpts:
        assert body in source, f"not verbatim in {EXAMPLE.name}:\n{body}"


def test_guide_runs_as_written(tmp_path):
    folder = str(tmp_path / "pendulum")
    text = page(folder)
    env = environment(tmp_path / "cache")
    commands = [c for lang, body in blocks(text) if lang == "console" for c in shell_session(body)]
    assert commands, "the guide has no shell session"
    for command, lines in commands:
        got = run_command(command, env)
        assert expected_pattern(lines).fullmatch(got), (
            f"$ {command}\n--- expected (page) ---\n" + "\n".join(lines) + f"\n--- got ---\n{got}")
    assert python_test(text).examples, "the guide has no Python session"
    proc = subprocess.run([sys.executable, __file__, "--run", folder], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


# --------------------------------------------------------------------------- as a script


def fill(doc: Path = DOC) -> None:
    """Rewrite the expected outputs of the page's Python session with what it prints now
    (run into /tmp/pendulum after the shell blocks were run by hand)."""
    text = doc.read_text()
    test = python_test(text, doc)
    rec = Recorder()
    rec.run(test, clear_globs=False)
    examples = iter(test.examples)
    pieces, last = [], 0
    for m in FENCE.finditer(text):
        if m.group(1) != "pycon":
            continue
        lines = []
        for _ in doctest.DocTestParser().get_examples(m.group(2)):
            ex = next(examples)
            src = ex.source.rstrip("\n").splitlines()
            lines.append(">>> " + src[0])
            lines += ["... " + s for s in src[1:]]
            if ex.exc_msg is not None:
                lines.append(ex.want.rstrip("\n"))  # tracebacks stay as written
            elif rec.got.get(id(ex), "").rstrip("\n"):
                lines.append(rec.got[id(ex)].rstrip("\n"))
        pieces += [text[last:m.start(2)], "\n".join(lines) + "\n"]
        last = m.end(2)
    doc.write_text("".join(pieces) + text[last:])


if __name__ == "__main__":
    if sys.argv[1:2] == ["--run"]:
        sys.path[0] = str(ROOT)  # as a session started in the repository root
        doc = Path(sys.argv[3]) if len(sys.argv) > 3 else DOC
        text = doc.read_text().replace(PLACEHOLDER, sys.argv[2]) if doc == DOC else doc.read_text()
        failures, report = run_python(text, doc)
        print(report)
        sys.exit(1 if failures else 0)
    elif sys.argv[1:2] == ["--fill"]:
        sys.path[0] = str(ROOT)
        fill(Path(sys.argv[2]) if len(sys.argv) > 2 else DOC)
    else:
        sys.exit("usage: test_docs_models.py --run FOLDER [PAGE] | --fill [PAGE]")

"""Every console block of the README is real output: each `$ ` command runs (from a
temporary folder, `.venv/bin/` being this interpreter's folder) and its output is compared
with the block, line by line.

The README's shorthand: a line `...` stands for any lines; `...` inside a line for any
text there; a trailing `# exit code N` on an output line says the command exits with N
(else 0); a trailing `# comment` on a command line is a comment; a command continues on the
next line after a backslash."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

README = ROOT / "README.md"
BIN = Path(sys.executable).parent


def console_blocks(text: str) -> list[list[str]]:
    return [b.splitlines() for b in re.findall(r"```console\n(.*?)```", text, re.S)]


def sessions(block: list[str]):
    """(command, expected output lines, exit code) of each `$ ` command of a block."""
    out, i = [], 0
    while i < len(block):
        line = block[i]
        if not line.startswith("$ "):
            i += 1
            continue
        cmd = line[2:]
        while cmd.rstrip().endswith("\\"):
            i += 1
            cmd = cmd.rstrip()[:-1] + " " + block[i].strip()
        cmd = re.sub(r"\s+#.*$", "", cmd)
        i += 1
        expected, code = [], 0
        while i < len(block) and not block[i].startswith("$ "):
            m = re.match(r"(.*?)\s+# exit code (\d+)$", block[i])
            if m:
                expected.append(m.group(1))
                code = int(m.group(2))
            else:
                expected.append(block[i])
            i += 1
        while expected and not expected[-1].strip():
            expected.pop()
        out.append((cmd, expected, code))
    return out


def _pattern(expected: list[str]) -> re.Pattern:
    parts = []
    for line in expected:
        if line.strip() == "...":
            parts.append(r"(?:.*\n)*?")
        else:
            parts.append(".*?".join(re.escape(p) for p in line.split("...")) + r"\n")
    return re.compile("".join(parts))


def _screen(text: str) -> str:
    """What a terminal keeps of a stream: a line rewritten with carriage returns (a progress
    bar that clears itself) leaves only its last state; lines left blank are dropped."""
    lines = [line.rsplit("\r", 1)[-1] for line in text.split("\n")]
    return "".join(line + "\n" for line in lines if line.strip())


CASES = [s for b in console_blocks(README.read_text()) for s in sessions(b)]


@pytest.mark.parametrize("k", range(len(re.findall(r"```python\n", README.read_text()))))
def test_readme_python_examples_run(k, capsys):
    """Each Python block of the README runs as written."""
    block = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)[k]
    exec(compile(block, f"README.md[python {k}]", "exec"), {"__name__": "__main__"})
    assert capsys.readouterr().out.strip()


def test_the_readme_has_console_sessions():
    assert len(CASES) >= 8


@pytest.mark.parametrize("cmd, expected, code", CASES, ids=[c for c, _, _ in CASES])
def test_readme_console_session(cmd, expected, code, tmp_path):
    run = cmd.replace(".venv/bin/", f"{BIN}/")
    # the README's commands run from the checkout's root; here in a fresh folder, so that
    # what they write lands there: the checkout's own files by their full paths
    for rel in (" tests/models/", " examples/"):
        run = run.replace(rel, f" {ROOT}/{rel.strip()}")
    env = dict(os.environ, GYRO_CACHE=os.environ.get("GYRO_CACHE", str(Path.home() / ".cache" / "gyro-dynamics")))
    proc = subprocess.run(run, shell=True, cwd=tmp_path, capture_output=True, text=True, env=env, timeout=600)
    got = proc.stdout + _screen(proc.stderr)
    assert proc.returncode == code, f"{cmd}: exit {proc.returncode}\n{got}"
    assert _pattern(expected).fullmatch(got if got.endswith("\n") or not got else got + "\n"), \
        f"{cmd}: output differs from the README:\n{got}"

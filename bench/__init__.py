"""The project's benchmarks (`make bench`, `python -m bench.<name>`); bench/results/ keeps
the committed runs."""
from __future__ import annotations


def machine() -> dict:
    """What a run was measured on: Python, the processor's architecture, model name and
    family/model/stepping, the kernel's bogomips and the cores. The machine is shared and
    virtual: the same code measured up to 1.8x apart in absolute time within a quarter of an
    hour (LAPACK's eigvals of the bench's companion 68.8-123.8 us a set), which is why every
    figure is a ratio against a baseline of the same run, and a record says where it came
    from."""
    import os
    import platform

    out = {"python": platform.python_version(), "processor": platform.machine(), "cores": os.cpu_count()}
    try:
        with open("/proc/cpuinfo") as f:
            info = dict(line.split(":", 1) for line in f if ":" in line)
        info = {k.strip(): v.strip() for k, v in info.items()}
        out["cpu_model"] = info.get("model name")
        out["cpu_family_model_stepping"] = "/".join(info.get(k, "?") for k in ("cpu family", "model", "stepping"))
        if "bogomips" in info:
            out["bogomips"] = float(info["bogomips"])
    except (OSError, ValueError):
        pass
    return out

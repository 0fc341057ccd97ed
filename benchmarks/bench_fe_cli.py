"""``geardyn stiffness --method fe`` on an empty geardyn cache: both paper FE maps and their
figures, as a user meets them (issue 16: target < 15 s).

The command runs in a child process (wall time; peak resident memory from ``os.wait4``), with
the machine's numba cache as it is (the FE map evaluation's compiled kernels; a fresh numba cache
adds their compilation). Baseline in the same run: the same command into a new folder once the
bodies are cached (what is left when nothing is solved: imports, map evaluation, figures).
``--quick`` measures the coarse mesh (``stiffness.fe.refinement=0.5``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import Row


def _stiffness(out: Path, env: dict, extra: list[str]) -> tuple[float, float]:
    """Wall time [s] and peak resident memory [MB] of ``geardyn stiffness --method fe``."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as err:
        p = subprocess.Popen([sys.executable, "-m", "geardyn", "stiffness", "--method", "fe",
                              "--out", str(out), *extra], env=env, stdout=subprocess.DEVNULL,
                             stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise RuntimeError(f"geardyn stiffness failed:\n{err.read().decode()}")
    return wall, usage.ru_maxrss / 1024.0  # Linux: kB


def run(quick: bool) -> list[Row]:
    extra = ["--set", "stiffness.fe.refinement=0.5"] if quick else []
    label = " (coarse mesh)" if quick else ""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp / "cache"))
        t_cold, mem = _stiffness(tmp / "a", env, extra)
        env_maps_gone = dict(env)
        # bodies cached, maps not: a new cache folder holding only the bodies' entries
        fe_only = tmp / "cache_fe"
        (fe_only / "fe").mkdir(parents=True)
        for f in (tmp / "cache" / "fe").iterdir():
            os.link(f, fe_only / "fe" / f.name)
        env_maps_gone["GEARDYN_CACHE_DIR"] = str(fe_only)
        t_bodies, _ = _stiffness(tmp / "b", env_maps_gone, extra)
    return [
        Row(f"geardyn stiffness --method fe, empty cache: both paper maps and figures{label}",
            t_cold, "s", "same with the bodies cached (maps, figures, imports)", t_bodies,
            "< 15 s (issue 16)", t_cold < 15.0),
        Row(f"geardyn stiffness --method fe, empty cache, peak memory{label}", mem, "MB"),
    ]

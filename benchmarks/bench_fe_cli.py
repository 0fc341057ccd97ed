"""``geardyn stiffness --method fe`` on an empty geardyn cache: both paper FE maps and their
figures, as a user meets them (issue 16: target < 15 s).

The command runs in a child process (wall time; peak memory summed over its process tree,
sampled from ``/proc``, and the largest process's ``ru_maxrss``), with
the machine's numba cache as it is (the FE map evaluation's compiled kernels; a fresh numba cache
adds their compilation). Baselines in the same run: the same command with the FE bodies in one process
(``GEARDYN_FE_PROCESSES=0``), into a new folder once the bodies are cached (what is left when
nothing is solved: imports, map evaluation, figures), and into a new folder with everything
cached (the maps, and the files and figures copied from the output cache).
``--quick`` measures the coarse mesh (``stiffness.fe.refinement=0.5``).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

from _common import Row, run_measured


def _stiffness(out: Path, env: dict, extra: list[str]) -> tuple[float, float, float]:
    """Wall time [s], peak summed memory of the process tree [MB] and peak of its largest
    process [MB] of ``geardyn stiffness --method fe``."""
    wall, peak, largest, _pss = run_measured(
        [sys.executable, "-m", "geardyn", "stiffness", "--method", "fe", "--out", str(out),
         *extra], env)
    return wall, peak, largest


def run(quick: bool) -> list[Row]:
    extra = ["--set", "stiffness.fe.refinement=0.5"] if quick else []
    label = " (coarse mesh)" if quick else ""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp / "cache"))
        env.pop("GEARDYN_FE_PROCESSES", None)  # the default: a second process where allowed
        t_cold, mem, mem1 = _stiffness(tmp / "a", env, extra)
        # into a new folder with everything cached (maps, and since 2026-11-28 the files and
        # figures of the output cache): the everyday re-run
        t_warm, _, _ = _stiffness(tmp / "w", env, extra)
        # the same in one process (GEARDYN_FE_PROCESSES=0), into an empty cache
        env_one = dict(env, GEARDYN_CACHE_DIR=str(tmp / "cache_one"), GEARDYN_FE_PROCESSES="0")
        t_one, mem_one, _ = _stiffness(tmp / "o", env_one, extra)
        env_maps_gone = dict(env)
        # bodies cached, maps not: a new cache folder holding only the bodies' entries
        fe_only = tmp / "cache_fe"
        (fe_only / "fe").mkdir(parents=True)
        for f in (tmp / "cache" / "fe").iterdir():
            os.link(f, fe_only / "fe" / f.name)
        env_maps_gone["GEARDYN_CACHE_DIR"] = str(fe_only)
        t_bodies, _, _ = _stiffness(tmp / "b", env_maps_gone, extra)
    from geardyn.stiffness.fe.background import fe_processes

    two = fe_processes() == 1
    how = "faulty bodies in a second process" if two else "one process (second not allowed here)"
    return [
        Row(f"geardyn stiffness --method fe, empty cache: both paper maps and figures, {how}"
            f"{label}", t_cold, "s", "same in one process (GEARDYN_FE_PROCESSES=0)", t_one,
            "< 15 s (issue 16)", t_cold < 15.0),
        Row(f"  same, bodies cached (maps, figures, imports){label}", t_bodies, "s",
            "empty cache, same run", t_cold),
        Row(f"  same into a new folder, everything cached (files copied){label}", t_warm, "s",
            "empty cache, same run", t_cold),
        Row(f"  peak memory, sum over its processes, {how}{label}", mem, "MB",
            "one process", mem_one, "< 600 MB", mem < 600),
        Row(f"  peak memory of its largest process (ru_maxrss){label}", mem1, "MB"),
    ]

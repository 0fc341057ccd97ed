"""``geardyn run``: wall time cold (empty caches, nothing compiled), warm and --quick.

Cold means a fresh geardyn cache *and* a fresh numba cache (``NUMBA_CACHE_DIR``), as on a newly
installed machine. Warm means the same command into a *new* output folder after the cold run
(maps, records, diagnoses, output files and figures in the cache), three times: the first warm
run is the one that used to redraw figures whose fingerprint differed between a computed and a
loaded record (issue 16). Targets: issue 7, cold < 10 min, --quick < 2 min; issue 16, warm
< 5 s. The baseline of the warm rows is the cold run measured in the same session.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import Row


def _run(args: list[str], env: dict) -> float:
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "geardyn", "run", *args], env=env,
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"geardyn run {' '.join(args)} failed:\n{r.stderr}")
    return time.perf_counter() - t0


def run(quick: bool) -> list[Row]:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp / "cache"),
                   NUMBA_CACHE_DIR=str(tmp / "numba"))
        extra = ["--stiffness", "pem"] if quick else []
        t_quick = _run(["--quick", "--out", str(tmp / "q"), *extra], env)
        env_cold = dict(env, GEARDYN_CACHE_DIR=str(tmp / "cache2"),
                        NUMBA_CACHE_DIR=str(tmp / "numba2"))
        t_cold = _run(["--out", str(tmp / "c"), *extra], env_cold)
        t_warm = [_run(["--out", str(tmp / f"w{i}"), *extra], env_cold) for i in range(3)]
    label = " (pem)" if quick else ""
    return [
        Row(f"geardyn run --quick, cold{label}", t_quick, "s", target="< 120 s",
            met=t_quick < 120),
        Row(f"geardyn run, cold{label}", t_cold, "s", target="< 600 s", met=t_cold < 600),
        Row(f"geardyn run, first warm run into a new folder{label}", t_warm[0], "s",
            "the same run cold", t_cold, target="< 5 s", met=t_warm[0] < 5),
        Row(f"geardyn run, warm into a new folder, slowest of the next 2{label}", max(t_warm[1:]),
            "s", "the same run cold", t_cold, target="< 5 s", met=max(t_warm[1:]) < 5),
    ]

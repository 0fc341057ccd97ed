"""``geardyn run``: wall time cold (empty caches, nothing compiled), warm and --quick.

Cold means a fresh geardyn cache *and* a fresh numba cache (``NUMBA_CACHE_DIR``), as on a newly
installed machine. Warm means the same command into a *new* output folder after the cold run
(maps, records, diagnoses, output files and figures in the cache), three times: the first warm
run is the one that used to redraw figures whose fingerprint differed between a computed and a
loaded record (issue 16). Targets: issue 7, cold < 10 min, --quick < 2 min; issue 16, warm
< 5 s, --quick < 15 s, peak memory < 600 MB. The baseline of the warm rows is the cold run
measured in the same session. Peak memory is the peak of the resident memory summed over the
command's processes (sampled from ``/proc``; the FE bodies of a faulty map may be built by a second
process, ``geardyn.stiffness.fe.background``). The last two cold runs have a compiled numba cache:
one with the default (a second FE process where the machine allows), one with
``GEARDYN_FE_PROCESSES=0``; then ``--quick`` again on an empty geardyn cache, numba compiled,
with the default (second processes for the FE bodies and the figures,
``geardyn.studies.figure_process``) and in one process. Memory is also given as the peak of the
summed proportional set sizes, which counts a page shared by two processes once.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

from _common import Row, run_measured

_PEAK_MB: dict[str, float] = {}
_PEAK_PSS_MB: dict[str, float] = {}
_CPU_S: dict[str, float] = {}


def _run(args: list[str], env: dict) -> float:
    """Wall time [s] of ``geardyn run args``; its peak memory summed over its processes [MB]
    into ``_PEAK_MB`` (resident sets) and ``_PEAK_PSS_MB`` (proportional set sizes: shared
    pages once), sampled from ``/proc`` (the FE bodies and the figures may use second
    processes), and its CPU time [s], summed over its processes, into ``_CPU_S``."""
    cpu: list[float] = []
    wall, peak, _largest, pss = run_measured([sys.executable, "-m", "geardyn", "run", *args],
                                             env, cpu_out=cpu)
    _PEAK_MB[" ".join(args)] = peak
    _PEAK_PSS_MB[" ".join(args)] = pss
    _CPU_S[" ".join(args)] = cpu[0] if cpu else float("nan")
    return wall


def run(quick: bool) -> list[Row]:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        env = dict(os.environ, GEARDYN_CACHE_DIR=str(tmp / "cache"),
                   NUMBA_CACHE_DIR=str(tmp / "numba"))
        extra = ["--stiffness", "pem"] if quick else []
        quick_args = ["--quick", "--out", str(tmp / "q"), *extra]
        t_quick = _run(quick_args, env)
        env_cold = dict(env, GEARDYN_CACHE_DIR=str(tmp / "cache2"),
                        NUMBA_CACHE_DIR=str(tmp / "numba2"))
        cold_args = ["--out", str(tmp / "c"), *extra]
        t_cold = _run(cold_args, env_cold)
        mem_quick = _PEAK_MB[" ".join(quick_args)]
        mem_cold = _PEAK_MB[" ".join(cold_args)]
        t_warm = [_run(["--out", str(tmp / f"w{i}"), *extra], env_cold) for i in range(3)]
        # cold again in one process (GEARDYN_FE_PROCESSES=0), numba compiled by now
        env_one = dict(env_cold, GEARDYN_CACHE_DIR=str(tmp / "cache3"), GEARDYN_FE_PROCESSES="0")
        one_args = ["--out", str(tmp / "one"), *extra]
        t_one = _run(one_args, env_one)
        env_two = dict(env_cold, GEARDYN_CACHE_DIR=str(tmp / "cache4"))
        env_two.pop("GEARDYN_FE_PROCESSES", None)
        two_args = ["--out", str(tmp / "two"), *extra]
        t_two = _run(two_args, env_two)
        # --quick on an empty geardyn cache with numba compiled (every run after the first)
        env_q2 = dict(env_two, GEARDYN_CACHE_DIR=str(tmp / "cache5"))
        q2_args = ["--quick", "--out", str(tmp / "q2"), *extra]
        t_quick2 = _run(q2_args, env_q2)
        # the same in one process (no second process for the FE bodies or the figures)
        env_q1 = dict(env_q2, GEARDYN_CACHE_DIR=str(tmp / "cache6"), GEARDYN_FE_PROCESSES="0")
        q1_args = ["--quick", "--out", str(tmp / "q1"), *extra]
        t_quick1 = _run(q1_args, env_q1)
    label = " (pem)" if quick else ""
    mem_one, mem_two = _PEAK_MB[" ".join(one_args)], _PEAK_MB[" ".join(two_args)]
    mem_q2, mem_q1 = _PEAK_MB[" ".join(q2_args)], _PEAK_MB[" ".join(q1_args)]
    pss = {k: _PEAK_PSS_MB[" ".join(a)] for k, a in
           (("quick", quick_args), ("cold", cold_args), ("two", two_args), ("one", one_args))}
    return [
        Row(f"geardyn run --quick, cold{label}", t_quick, "s", target="< 15 s (issue 16)",
            met=t_quick < 15),
        Row(f"geardyn run --quick, cold geardyn cache, numba compiled{label}", t_quick2, "s",
            "nothing compiled (the row above)", t_quick, "< 15 s", t_quick2 < 15),
        Row(f"  same in one process (GEARDYN_FE_PROCESSES=0){label}", t_quick1, "s",
            "the default (the row above)", t_quick2, "< 15 s", t_quick1 < 15),
        Row(f"  their peak memory, default / one process{label}", mem_q2, "MB",
            "one process", mem_q1, "< 600 MB", mem_q2 < 600),
        Row(f"geardyn run --quick, cold, peak memory{label}", mem_quick, "MB",
            target="< 600 MB", met=mem_quick < 600),
        Row(f"  the same as proportional set sizes (shared pages once){label}", pss["quick"],
            "MB", target="< 600 MB", met=pss["quick"] < 600),
        Row(f"geardyn run, cold, peak memory{label}", mem_cold, "MB", target="< 600 MB",
            met=mem_cold < 600),
        Row(f"  the same as proportional set sizes{label}", pss["cold"], "MB",
            target="< 600 MB", met=pss["cold"] < 600),
        Row(f"geardyn run, cold{label}", t_cold, "s", target="< 40 s", met=t_cold < 40),
        # the CPU a first run spends compiling numba's kernels, in whichever process (until
        # 2026-11-28 the study compiled the time-step kernel a second time, beside the FE
        # bodies' process that compiles it)
        Row(f"  its CPU time, summed over its processes{label}", _CPU_S[" ".join(cold_args)],
            "s", "the same run numba compiled (the next row)", _CPU_S[" ".join(two_args)]),
        Row(f"geardyn run, cold geardyn cache, numba compiled, FE bodies by the default{label}",
            t_two, "s", "same in one process (GEARDYN_FE_PROCESSES=0)", t_one, "< 40 s",
            t_two < 40),
        Row(f"  its peak memory, summed over its processes{label}", mem_two, "MB",
            "one process", mem_one, "< 600 MB", mem_two < 600),
        Row(f"  the same as proportional set sizes{label}", pss["two"], "MB",
            "one process", pss["one"], "< 600 MB", pss["two"] < 600),
        Row(f"geardyn run, first warm run into a new folder{label}", t_warm[0], "s",
            "the same run cold", t_cold, target="< 5 s", met=t_warm[0] < 5),
        Row(f"geardyn run, warm into a new folder, slowest of the next 2{label}", max(t_warm[1:]),
            "s", "the same run cold", t_cold, target="< 5 s", met=max(t_warm[1:]) < 5),
    ]

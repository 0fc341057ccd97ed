"""The benchmark table says by how much each target is met or missed (issue 16: "the benchmark
table ... shows each target met or says by how much it misses")."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

_SPEC = importlib.util.spec_from_file_location(
    "bench_common", Path(__file__).resolve().parents[1] / "benchmarks" / "_common.py")
common = importlib.util.module_from_spec(_SPEC)
sys.modules.setdefault("bench_common", common)  # (dataclasses look the module up)
_SPEC.loader.exec_module(common)
Row = common.Row


def test_margin_of_a_time_target_met_and_missed():
    assert Row("quick", 12.48, "s", target="< 15 s (issue 16)", met=True).margin == "by 2.52 s"
    assert Row("quick", 18.67, "s", target="< 15 s (issue 16)", met=False).margin == "by 3.67 s"


def test_margin_in_the_rows_unit_only():
    assert Row("memory", 970.0, "MB", target="< 600 MB", met=False).margin == "by 370 MB"
    assert Row("rate", 1.1e7, "lookups/s", target="> 1e7 lookups/s", met=True).margin == \
        "by 1e+06 lookups/s"
    # a target in another unit, or relative to another figure: no margin rather than a wrong one
    assert Row("step", 0.147, "us/step", target="<= 1.5x the C step", met=True).margin == ""
    assert Row("scaling", 85.0, "%", target=">= 80 % of one worker", met=True).margin == "by 5 %"
    assert Row("memory", 0.97, "GB", target="< 600 MB", met=False).margin == ""
    assert Row("no target", 1.0, "s").margin == ""
    assert Row("skipped", math.nan, "s", target="< 1 s").margin == ""


def test_memory_of_a_process_tree(tmp_path, monkeypatch):
    """The benchmark's memory sampler sums a process and its child (the children files, and the
    scan of ``/proc`` where there are none): a parent holding 80 MB and its child holding
    120 MB, both alive (the child says so by a file), read at least 200 MB and at most 200 MB
    plus two interpreters; the proportional set size lies between 0 and the resident sum."""
    import os
    import subprocess
    import textwrap
    import time

    import pytest

    if not os.path.isdir("/proc"):
        pytest.skip("no /proc on this system: the benchmark reads 0 MB here")
    ready = tmp_path / "ready"
    child = ("import pathlib, sys; held = b'c' * (120 * 2**20); "
             "pathlib.Path(sys.argv[1]).write_text('x'); sys.stdin.read()")
    code = textwrap.dedent(f"""
        import subprocess, sys
        held = b'p' * (80 * 2**20)
        child = subprocess.Popen([sys.executable, "-c", {child!r}, {str(ready)!r}],
                                 stdin=subprocess.PIPE)
        sys.stdin.read()
        child.stdin.close()
        child.wait()
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE)
    try:
        t0 = time.monotonic()
        while not ready.exists():
            assert proc.poll() is None and time.monotonic() - t0 < 120
            time.sleep(0.01)
        mb = 1024  # kB
        tree = common._tree(proc.pid)
        assert len(tree) == 2 and proc.pid in tree
        rss, pss = common._tree_rss_kb(proc.pid)
        assert 200 * mb <= rss <= (200 + 2 * 60) * mb, rss / mb
        assert 0 < pss <= rss
        rss_only, none = common._tree_rss_kb(proc.pid, pss=False)
        assert none is None and 200 * mb <= rss_only <= (200 + 2 * 60) * mb
        monkeypatch.setattr(common, "_children", lambda pid: None)  # a kernel without them
        assert common._tree(proc.pid) == tree
    finally:
        proc.stdin.close()
        proc.wait(timeout=60)


def test_cpu_time_of_a_process_tree_counts_a_child_nobody_waits_for():
    """``run_measured(cpu_out=...)``: a command that burns 0.4 s of CPU and starts a child that
    burns 0.4 s and is not waited for (as a Dask forkserver is not) reads the CPU of both: at
    least 0.8 s less one sampling interval per process, at most that plus two interpreters'
    start. ``wait4``'s usage would miss the child."""
    import os

    import pytest

    if not os.path.isdir("/proc"):
        pytest.skip("no /proc on this system")
    burn = ("import time\nt = time.process_time()\n"
            "while time.process_time() - t < 0.4:\n    pass\n")
    child = burn + "import os, sys\nos.write(int(sys.argv[1]), b'x')\n"
    code = (f"import os, subprocess, sys\nr, w = os.pipe()\n"
            f"subprocess.Popen([sys.executable, '-c', {child!r}, str(w)], pass_fds=(w,))\n"
            f"{burn}"
            "os.read(r, 1)  # the child has burnt its share; it is left to exit on its own\n")
    cpu: list[float] = []
    common.run_measured([sys.executable, "-c", code], dict(os.environ), cpu_out=cpu)
    assert len(cpu) == 1
    assert 0.8 - 2 * 0.05 <= cpu[0] <= 0.8 + 2 * 0.5, cpu


def test_the_host_probe_runs_its_whole_loop():
    """The host probe printed with every benchmark table (``_common.python_loop``) adds every
    integer below n, at a script's top level: the sum is n (n - 1) / 2, and a loop of no
    additions sums to 0."""
    seconds, total = common.python_loop(100_000)
    assert total == 100_000 * 99_999 // 2
    assert 0.0 < seconds < 60.0
    assert common.python_loop(0)[1] == 0

"""Shared pieces of the benchmark suite.

Each ``benchmarks/bench_<subsystem>.py`` defines ``run(quick: bool) -> list[Row]``. A row reports one
measured figure, the baseline measured *in the same run* (a straightforward implementation of the
same computation), their ratio, and the project's target, so a reader sees at once whether the
target is met on this machine.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass

#: A target the table can measure a margin against: a comparison, a number and the row's unit
#: (``"< 15 s"``, ``">= 1e7 lookups/s"``; words after the unit are allowed: ``"< 15 s (issue 16)"``).
_TARGET = re.compile(r"^\s*(<=|<|>=|>)\s*([0-9][0-9.,]*(?:e[+-]?[0-9]+)?)\s*(\S+)")


@dataclass(frozen=True)
class Row:
    """One benchmark figure.

    Attributes
    ----------
    name : str
        What was measured.
    value : float
        The measured figure, in ``unit``.
    unit : str
        Unit of ``value`` (e.g. ``"s"``, ``"us/step"``, ``"lookups/s"``).
    baseline : str
        What the baseline is (empty if there is none).
    baseline_value : float or None
        The baseline's figure in the same unit, measured in the same run.
    target : str
        The target in words, e.g. ``"< 2 s"``.
    met : bool or None
        Whether the target is met (``None`` if there is no target).
    """

    name: str
    value: float
    unit: str
    baseline: str = ""
    baseline_value: float | None = None
    target: str = ""
    met: bool | None = None

    @property
    def margin(self) -> str:
        """How far the measured figure is inside (``"by 0.4 s"``) or outside (``"by 3.7 s"``,
        with ``met`` False) its target, in the row's unit; empty when the target is not a plain
        comparison in that unit (``"<= 1.5x the C step"``, ``"< 600 MB"`` on a row in GB)."""
        m = _TARGET.match(self.target)
        if m is None or m.group(3) != self.unit or self.value != self.value:  # (NaN: skipped)
            return ""
        limit = float(m.group(2).replace(",", ""))
        return f"by {abs(self.value - limit):.3g} {self.unit}"

    @property
    def ratio(self) -> float | None:
        """Speed-up of the measured figure over the baseline (> 1 means faster / better)."""
        if self.baseline_value is None or self.value == 0:
            return None
        # for rates (per second) larger is better; for times smaller is better
        if self.unit.endswith("/s") or self.unit.startswith("runs/"):
            return self.value / self.baseline_value
        return self.baseline_value / self.value


def best_time(fn: Callable[[], object], repeat: int = 3, number: int = 1) -> float:
    """Best wall-clock time of ``number`` calls of ``fn`` over ``repeat`` trials [s per call]."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best


def _pss_kb(pid: int) -> int:
    """Proportional set size [kB] of ``pid`` (``/proc/<pid>/smaps_rollup``): its resident pages,
    each shared page divided among the processes sharing it; 0 where unreadable."""
    try:
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Pss:"):
                    return int(line.split()[1])
    except (OSError, IndexError, ValueError):
        return 0
    return 0


def _children(pid: int) -> list[int] | None:
    """Child processes of ``pid`` (``/proc/<pid>/task/<tid>/children``); None where the kernel
    has no such file."""
    import os

    out: list[int] = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return []  # the process has ended
    for tid in tasks:
        try:
            with open(f"/proc/{pid}/task/{tid}/children") as fh:
                out += [int(c) for c in fh.read().split()]
        except FileNotFoundError:
            if not os.path.exists(f"/proc/{pid}/task/{tid}"):
                continue  # the thread has ended
            return None  # no children file: the caller scans /proc
        except (OSError, ValueError):
            continue
    return out


def _tree(root: int) -> set[int]:
    """``root`` and all its descendants now: from the ``children`` files (a few reads), or,
    where the kernel has none, from the parent field of every process in ``/proc``."""
    import os

    children_of = _children
    if _children(root) is None:  # a kernel without the children files: scan /proc once
        parent: dict[int, int] = {}
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    with open(f"/proc/{entry}/stat") as fh:
                        parent[int(entry)] = int(fh.read().rsplit(")", 1)[1].split()[1])
                except (OSError, IndexError, ValueError):
                    continue

        def children_of(pid: int) -> list[int]:
            return [child for child, par in parent.items() if par == pid]

    tree, frontier = {root}, [root]
    while frontier:
        for child in children_of(frontier.pop()) or ():
            if child not in tree:
                tree.add(child)
                frontier.append(child)
    return tree


def _rss_kb(pid: int) -> int:
    """Resident set [kB] of ``pid`` (``/proc/<pid>/statm``); 0 where unreadable."""
    import os

    try:
        with open(f"/proc/{pid}/statm") as fh:
            return int(fh.read().split()[1]) * (os.sysconf("SC_PAGE_SIZE") // 1024)
    except (OSError, IndexError, ValueError):
        return 0


def _tree_rss_kb(root: int, pss: bool = True) -> tuple[int, int | None]:
    """Resident memory [kB] of ``root`` and all its descendants now (Linux ``/proc``): the sum
    of their resident sets, and (``pss``) the sum of their proportional set sizes
    (:func:`_pss_kb`), which counts a page shared by several of them once: the libraries every
    Python process maps, and a process forked from another before it executes a new program
    (a spawned worker's first milliseconds), which the sum of resident sets counts twice.

    The resident sets cost about 0.3 ms a sample; a proportional set size about 4 ms per
    process (the kernel walks the process's page tables; measured 2026-11-26 on a 300 MB
    Python process), which is why :func:`run_measured` asks for it only every tenth sample."""
    tree = _tree(root)
    return (sum(_rss_kb(p) for p in tree),
            sum(_pss_kb(p) for p in tree) if pss else None)


def _cpu_seconds(pid: int) -> float | None:
    """User + system CPU time [s] of ``pid`` so far (``/proc/<pid>/stat``); None if it ended."""
    import os

    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


def run_measured(cmd: list[str], env: dict, *, interval: float = 0.05, pss_every: int = 10,
                 cpu_out: list[float] | None = None) -> tuple[float, float, float, float]:
    """Run ``cmd``; return its wall time [s], the peak of the *summed* resident memory of the
    process and its children [MB] (sampled every ``interval`` s from ``/proc``; 0 where there
    is none), its own peak resident set [MB] (``ru_maxrss`` from ``wait4``: the largest single
    process of the tree, not their sum) and the peak of their summed proportional set sizes
    [MB] (:func:`_tree_rss_kb`: shared pages counted once; sampled every ``pss_every``-th
    sample only, as it costs about 4 ms per process; 0 where ``/proc`` has none).

    The sampler runs beside the command on the same cores: until 2026-11-26 it read every
    process's proportional set size at every sample, about 15 ms of CPU every 50 ms with three
    processes (a third of a core), which made ``geardyn run --quick`` about 1.6 s (12 %) slower
    than timed alone (measured 2026-11-26, docs/performance.md).

    With ``cpu_out`` (a list), the CPU time [s] of every process of the tree is appended to
    it: each process's user + system time as last read (every ``interval`` s; a process that
    ends between two samples loses at most its last ``interval``), summed. That includes
    processes the command does not wait for (a Dask forkserver and the workers it forks),
    which ``wait4``'s usage does not.

    The command runs with Python's bytecode cache on (``PYTHONDONTWRITEBYTECODE`` removed
    from ``env``), as a user's does: ``pip install`` compiles the bytecode of what it installs.
    The shell these benchmarks ran from until 2026-11-28 set it, so an editable install
    compiled geardyn's sources again in every process of every timed run (about 0.5 s of a
    5 s warm ``geardyn run``, measured 2026-11-28).

    Raises ``RuntimeError`` with the command's stderr if it fails.
    """
    import os
    import subprocess
    import tempfile
    import threading

    env = {k: v for k, v in env.items() if k != "PYTHONDONTWRITEBYTECODE"}
    peak = [0, 0]
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as err:
        p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=err)
        done = threading.Event()

        cpu: dict[int, float] = {}

        def sample() -> None:
            k = 0
            while not done.is_set():
                if os.path.isdir("/proc"):
                    rss, pss = _tree_rss_kb(p.pid, pss=k % pss_every == 0)
                    peak[0] = max(peak[0], rss)
                    if pss is not None:
                        peak[1] = max(peak[1], pss)
                    if cpu_out is not None:
                        for pid in _tree(p.pid):
                            seconds = _cpu_seconds(pid)
                            if seconds is not None:
                                cpu[pid] = seconds
                k += 1
                done.wait(interval)

        th = threading.Thread(target=sample, daemon=True)
        th.start()
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        done.set()
        th.join()
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(cmd)} failed:\n{err.read().decode()}")
    if cpu_out is not None:
        cpu_out.append(sum(cpu.values()))
    return wall, peak[0] / 1024.0, usage.ru_maxrss / 1024.0, peak[1] / 1024.0


def machine() -> str:
    """CPU model and logical cores of this machine (Linux /proc/cpuinfo; platform otherwise)."""
    import os
    import platform
    from pathlib import Path

    name = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{name}, {os.cpu_count()} logical cores, Python {platform.python_version()}"


#: The host probe's loop, run as a script's top level (its variables module globals), as
#: ``python3 -c "..."`` runs it: the form the performance log's hand measurements took.
_PROBE = ("import time\nt0 = time.perf_counter()\ns = 0\nfor i in range(n):\n    s += i\n"
          "seconds = time.perf_counter() - t0\n")


def python_loop(n: int = 10_000_000) -> tuple[float, int]:
    """The host's speed at interpreter-bound work: seconds for a pure-Python loop of ``n``
    integer additions at a script's top level, and the sum it made (``n (n - 1) / 2``).

    The virtual machine's host changes between sessions, up to about 2x apart in speed
    (docs/performance.md: 1e7 additions in about 1 s on 11-27's faster host, 1.7-2.4 s on
    11-28's); printed with every table (:func:`main` of ``run.py``) so that runs on different
    hosts are not read as a change of the code.
    """
    scope: dict = {"n": int(n)}
    exec(compile(_PROBE, "<host probe>", "exec"), scope)  # noqa: S102 (our own constant code)
    return float(scope["seconds"]), int(scope["s"])


def load_average() -> float:
    """The 1-minute load average (NaN where the system has none)."""
    import os

    try:
        return os.getloadavg()[0]
    except OSError:  # pragma: no cover - not on Linux
        return float("nan")

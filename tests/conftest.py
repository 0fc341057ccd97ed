"""Test-session settings: a private cache folder and a non-interactive matplotlib backend."""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
# FE bodies in one process (tests/fe/test_background_bodies.py turns the second one on): two
# test workers each starting a second FE process would oversubscribe the CI machine's two cores
os.environ.setdefault("GEARDYN_FE_PROCESSES", "0")


def pytest_configure(config):
    """pytest-xdist controller: one cache folder for the whole session, shared by the workers
    (the cache's entry locks make concurrent builders safe, so a body or map that tests on both
    workers need is built once, not once per worker); files with the longest tests first."""
    if hasattr(config, "workerinput"):  # a worker: the controller did this
        return
    if getattr(config.option, "numprocesses", None):
        config._geardyn_shared_cache = tempfile.mkdtemp(prefix="geardyn-test-cache-")
        # the work queue in the order of the collection (longest files first, below), not
        # xdist's default order by the number of tests in a file (pytest-xdist >= 3.8)
        if hasattr(config.option, "loadscopereorder"):
            config.option.loadscopereorder = False


def pytest_unconfigure(config):
    shared = getattr(config, "_geardyn_shared_cache", None)
    if shared:
        shutil.rmtree(shared, ignore_errors=True)


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist controller: hand each worker the session's shared cache folder."""
    shared = getattr(node.config, "_geardyn_shared_cache", None)
    if shared:
        node.workerinput["geardyn_cache_dir"] = shared


def pytest_collection_modifyitems(config, items):
    """The files with the longest tests first (longest-processing-time-first scheduling: the
    two workers then finish together instead of one running the last long file alone); other
    files keep their order. The weights are the files' test time in seconds, measured with
    ``python3 -m pytest --durations=120`` on the 2-core machine on 2026-11-26 (a file's place
    in the queue is all they decide: a stale weight costs time, never a result)."""
    order = {path: -weight for path, weight in LONGEST_FILES.items()}
    items.sort(key=lambda it: order.get(it.nodeid.split("::", 1)[0], 0.0))


#: Test files over 10 s, by their measured test time [s] (see pytest_collection_modifyitems;
#: 2026-11-26, the four sweep, crack-growth and direct-contact files after this morning's
#: changes to them).
LONGEST_FILES = {
    "tests/hardening/test_fuzz_commands.py": 56.5,
    "tests/faults/test_examples.py": 55.9,
    "tests/sweep/test_kill_resume.py": 29.0,
    "tests/studies/test_paper_run.py": 46.0,
    "tests/sweep/test_dask_cluster.py": 18.0,
    "tests/fe/test_load_consistent.py": 13.6,
    "tests/reliability/test_kill.py": 41.3,
    "tests/fe/test_background_bodies.py": 39.4,
    "tests/cli/test_reruns.py": 39.1,
    "tests/faults/test_crack_growth_cli.py": 20.3,
    "tests/hardening/test_interrupts.py": 24.5,
    "tests/faults/test_fault_sweeps.py": 23.6,
    "tests/hardening/test_fuzz_config.py": 17.4,
    "tests/faults/test_sif.py": 16.8,
    "tests/cli/test_cli_foundation.py": 16.3,
    "tests/studies/test_warm_run_cache.py": 15.7,
    "tests/fe/test_fe_faults.py": 13.7,
    "tests/dynamics/test_transverse_examples.py": 12.8,
    "tests/test_readme.py": 11.2,
    "tests/cli/test_cli_polish.py": 10.8,
    "tests/hardening/test_cache_and_files.py": 10.4,
    "tests/cli/test_simulate_cli.py": 10.1,
    # added in the afternoon's QA fixes (their test time under load / 1.25)
    "tests/cli/test_diagnose_pulses.py": 16.0,
    "tests/cli/test_diagnose_inputs.py": 13.0,
}


@pytest.fixture(autouse=True, scope="session")
def _private_cache(request, tmp_path_factory):
    """Keep the tests' stiffness maps and FE matrices out of the user's cache: one folder for
    the session (shared by pytest-xdist's workers, see :func:`pytest_configure`)."""
    old = os.environ.get("GEARDYN_CACHE_DIR")
    shared = getattr(request.config, "workerinput", {}).get("geardyn_cache_dir")
    os.environ["GEARDYN_CACHE_DIR"] = shared or str(tmp_path_factory.mktemp("geardyn-cache"))
    yield
    if old is None:
        os.environ.pop("GEARDYN_CACHE_DIR", None)
    else:
        os.environ["GEARDYN_CACHE_DIR"] = old


#: Fuzz counts reported by pytest-xdist workers (merged in the controller).
_WORKER_FUZZ_COUNTS: dict[str, int] = {}


def _fuzz_counts() -> dict[str, int]:
    try:
        from tests.hardening.conftest import FUZZ_COUNTS
    except ImportError:  # pragma: no cover
        return {}
    return dict(FUZZ_COUNTS)


def pytest_sessionfinish(session):
    """In a pytest-xdist worker: hand the fuzz counts to the controller."""
    out = getattr(session.config, "workeroutput", None)
    if out is not None:
        out["fuzz_counts"] = _fuzz_counts()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist controller: collect a finished worker's fuzz counts."""
    for family, n in getattr(node, "workeroutput", {}).get("fuzz_counts", {}).items():
        _WORKER_FUZZ_COUNTS[family] = _WORKER_FUZZ_COUNTS.get(family, 0) + n


def pytest_terminal_summary(terminalreporter):
    """Report how many fuzzed inputs each command family was given (hardening tests)."""
    counts = _fuzz_counts()
    for family, n in _WORKER_FUZZ_COUNTS.items():
        counts[family] = counts.get(family, 0) + n
    if counts:
        terminalreporter.section("fuzzed inputs per command family")
        for family, n in sorted(counts.items()):
            terminalreporter.write_line(f"{family}: {n} generated inputs, each a valid run or a "
                                        "clean error (exit 2, field named, no traceback)")

"""Test-session settings: a private cache folder and a non-interactive matplotlib backend."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
# FE bodies in one process (tests/fe/test_background_bodies.py turns the second one on): two
# test workers each starting a second FE process would oversubscribe the CI machine's two cores
os.environ.setdefault("GEARDYN_FE_PROCESSES", "0")


@pytest.fixture(autouse=True, scope="session")
def _private_cache(tmp_path_factory):
    """Keep the tests' stiffness maps and FE matrices out of the user's cache."""
    old = os.environ.get("GEARDYN_CACHE_DIR")
    os.environ["GEARDYN_CACHE_DIR"] = str(tmp_path_factory.mktemp("geardyn-cache"))
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

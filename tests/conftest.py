"""Test-session settings: a private cache folder and a non-interactive matplotlib backend."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


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


def pytest_terminal_summary(terminalreporter):
    """Report how many fuzzed inputs each command family was given (hardening tests)."""
    try:
        from tests.hardening.conftest import FUZZ_COUNTS
    except ImportError:  # pragma: no cover
        return
    if FUZZ_COUNTS:
        terminalreporter.section("fuzzed inputs per command family")
        for family, n in sorted(FUZZ_COUNTS.items()):
            terminalreporter.write_line(f"{family}: {n} generated inputs, each a valid run or a "
                                        "clean error (exit 2, field named, no traceback)")

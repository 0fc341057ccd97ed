"""``.ci/floors_fit``: whether ``.ci/run`` has time left for the dependency floors (issue 17.5:
"a test job run by .ci/run when time allows"). The rule, from the script's header:
``ELAPSED + SUITE // 2 + 150 <= GEARDYN_CI_BUDGET`` (default 1140 s); ``GEARDYN_CI_FLOORS=1``
always, ``0`` never, anything else refused (exit 2)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / ".ci" / "floors_fit"

pytestmark = pytest.mark.skipif(shutil.which("bash") is None, reason="no bash here")


def fit(*args, **env):
    base = {k: v for k, v in os.environ.items() if not k.startswith("GEARDYN_CI_")}
    return subprocess.run(["bash", str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, env={**base, **env}, timeout=30)


@pytest.mark.parametrize("elapsed, suite, runs", [
    (400, 345, True),     # 11-27's faster host: 400 + 172 + 150 = 722
    (820, 745, False),    # 11-28's slower host: 820 + 372 + 150 = 1342
    (618, 745, True),     # 618 + 372 + 150 = 1140: exactly the budget
    (619, 745, False),    # one second over
])
def test_the_floors_run_when_the_estimate_fits_the_budget(elapsed, suite, runs):
    r = fit(elapsed, suite)
    assert r.returncode == (0 if runs else 1), r.stdout + r.stderr
    if runs:
        assert r.stdout == ""
    else:  # the note says why, with the figures, and how to run them anyway
        assert f"the suite took {suite} s" in r.stdout
        assert f"{elapsed} s so far + an estimated {suite // 2 + 150} s" in r.stdout
        assert "1140 s budget" in r.stdout and "GEARDYN_CI_FLOORS=1" in r.stdout


def test_the_budget_and_the_setting_decide_over_the_estimate():
    assert fit(820, 745, GEARDYN_CI_BUDGET="1400").returncode == 0
    assert fit(400, 345, GEARDYN_CI_BUDGET="700").returncode == 1
    assert fit(10_000, 10_000, GEARDYN_CI_FLOORS="1").returncode == 0
    r = fit(0, 0, GEARDYN_CI_FLOORS="0")
    assert r.returncode == 1 and "GEARDYN_CI_FLOORS=0" in r.stdout


@pytest.mark.parametrize("args, env, names", [
    ((1, 1), {"GEARDYN_CI_FLOORS": "yes"}, "GEARDYN_CI_FLOORS: got 'yes'"),
    ((1, 1), {"GEARDYN_CI_BUDGET": "20 min"}, "got '20 min'"),
    (("x", 1), {}, "usage"),
    ((1,), {}, "usage"),
])
def test_bad_settings_are_refused_with_exit_2(args, env, names):
    r = fit(*args, **env)
    assert r.returncode == 2 and names in r.stderr and r.stdout == "", r.stderr

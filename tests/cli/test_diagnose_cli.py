"""``geardyn diagnose`` on measured data, as a user runs it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from .._cli_fork import run_geardyn


def _write_csv(path):
    t = np.linspace(0, 2, 40000, endpoint=False)
    th = 2 * np.pi * 18 * t
    bump = np.exp(-((np.mod(th, 2 * np.pi) - 3.0) ** 2) / 0.01)
    x = np.cos(115 * th) * (1 + 0.2 * bump) + 0.5 * np.cos(23 * th)
    np.savetxt(path, np.column_stack([t, th, x]), delimiter=",", header="t,angle,acc",
               comments="")


@pytest.mark.slow
def test_diagnose_measured_csv(tmp_path):
    csv = tmp_path / "m.csv"
    _write_csv(csv)
    out = tmp_path / "out"
    r = run_geardyn(["diagnose", str(csv), "--time", "t",
                     "--angle", "angle", "--signal", "acc", "--out", str(out)],
                    capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    m = json.loads((out / "metrics.json").read_text())
    sig = m["signals"]["acc"]
    assert sig["n_averages"] == 36
    # the localised amplitude bump at 3 rad (172 deg) on the 5th mesh harmonic is found by the
    # narrowband envelope: its kurtosis is far above a Gaussian's 3
    assert sig["kurtosis"]["envelope"] > 6
    assert len(list((out / "figures").glob("acc_*.png"))) == 7


@pytest.mark.slow
@pytest.mark.parametrize(("args", "words"), [
    (["--time", "t", "--signal", "acc"], "angle"),
    (["--time", "t", "--angle", "nope", "--signal", "acc"], "nope"),
])
def test_diagnose_bad_input(tmp_path, args, words):
    csv = tmp_path / "m.csv"
    _write_csv(csv)
    r = run_geardyn(["diagnose", str(csv), *args, "--out",
                     str(tmp_path / "o")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2
    assert words in r.stderr and "Traceback" not in r.stderr

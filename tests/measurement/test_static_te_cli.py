"""``geardyn static-te``: the NetCDF it writes (units, both loads) and its figure; the loaded
transmission error of a perfect pair is the mesh force over the mesh stiffness along the line of
action (``N / k_mb``, ``N = T / r_b1``; the oracle of tests/modifications/test_static_te.py)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from geardyn.cli import app

COARSE = ["--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8"]


@pytest.mark.slow  # builds a PEM map (about 5 s in a fresh cache)
def test_static_te_writes_units_and_the_perfect_pair_oracle(tmp_path):
    from geardyn.config import paper_case
    from geardyn.stiffness import build_map

    out = tmp_path / "te.nc"
    r = CliRunner().invoke(app, ["static-te", "--stiffness", "pem", "--no-errors", "--torque",
                                 "80 N m", "--points", "512", "--out", str(out), *COARSE])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "te.png").stat().st_size > 10_000
    ds = xr.open_dataset(out)
    assert list(ds["torque"].values) == [0.0, 80.0] and ds["torque"].attrs["units"] == "N m"
    assert ds["transmission_error"].attrs["units"] == "um"
    assert ds["transmission_error_angle"].attrs["units"] == "rad"
    assert ds["theta"].attrs["units"] == "rad" and ds.sizes["theta"] == 512
    assert "stiffness" in ds.attrs["case_toml"] and ds.attrs["stiffness_method"] == "pem"
    case = paper_case(["stiffness.method=\"pem\"", "stiffness.centre_distances=6",
                       "stiffness.nodes_per_segment=8"])
    smap = build_map(case, cracked=False)  # the map the command built (from the cache)
    pair = case.gear_pair()
    th = ds["theta"].values
    n = 80.0 / pair.pinion.base_radius
    te = ds["transmission_error"].values
    np.testing.assert_array_equal(te[0], 0.0)  # perfect teeth, no load: no TE
    np.testing.assert_allclose(te[1] * 1e-6, n / smap(th, 0.0), rtol=1e-12)
    np.testing.assert_allclose(ds["transmission_error_angle"].values[1],
                               te[1] * 1e-6 / pair.pinion.base_radius, rtol=1e-12)
    # refuses to overwrite, names the option, exit 2
    again = CliRunner().invoke(app, ["static-te", "--out", str(out), *COARSE])
    assert again.exit_code == 2 and "--out" in again.output


@pytest.mark.parametrize("args,field", [
    (["--torque", "-5"], "--torque"), (["--torque", "5 m"], "--torque"),
    (["--points", "3"], "--points"), (["--stiffness", "abc"], "--stiffness"),
    (["--dd", "1 s"], "--centre-distance-change"),
    # beyond the map's range (within the contact-ratio limit): named before the map is built
    (["--dd", "3 mm"], "--centre-distance-change: got '3 mm'; allowed: a change within the "
                       "stiffness map's range [-0.5, 2] mm")])
def test_static_te_bad_input_names_the_field(tmp_path, args, field):
    r = CliRunner().invoke(app, ["static-te", "--out", str(tmp_path / "x.nc"), *args])
    assert r.exit_code == 2, r.output
    assert field in r.output and "Traceback" not in r.output
    assert not (tmp_path / "x.nc").exists()


def test_tooth_errors_included_says_whether_the_curves_hold_any():
    """1 only where errors were asked for and the case has some (the healthy paper case said 1
    beside ``tooth_errors: 0``, a user audit of 2026-11-27)."""
    import geardyn
    from geardyn.static_te import static_te_curves

    small = {"stiffness.method": "pem", "stiffness.centre_distances": 3,
             "stiffness.nodes_per_segment": 6}
    plain = geardyn.paper_case(small)
    graded = geardyn.paper_case({**small, "modifications.pinion.grade": 6})
    assert static_te_curves(plain, n=64).attrs["tooth_errors_included"] == 0
    assert static_te_curves(graded, n=64).attrs["tooth_errors_included"] == 1
    assert static_te_curves(graded, n=64, errors=False).attrs["tooth_errors_included"] == 0

"""Sweep files: validation (errors name the field) and expansion (counts, order, sampling).

Oracles: itertools.product for the factorial order, numpy.linspace/geomspace for ranges, scipy's
own qmc engines called directly for the sampled points, and the defining properties of the
designs (a Sobol' net of 2^m points has one point in each 1/2^m interval of every coordinate; a
Latin hypercube one point in each 1/n stratum).
"""

from __future__ import annotations

import itertools
import math
import textwrap

import numpy as np
import pytest
from scipy.stats import qmc

from geardyn.errors import DataFileError, InputError
from geardyn.studies.sweep import load_sweep, parse_sweep, run_seeds

from .._cli_fork import run_geardyn


def sweep(text: str, **kw):
    return parse_sweep(textwrap.dedent(text), **kw)


def test_factorial_order_counts_units_and_links():
    sw = sweep("""
        name = "t"
        [axes]
        crack.depth = ["1 mm", "2.5 mm", 0.004]
        motor.torque = { start = "50 N m", stop = "150 N m", num = 3 }
        simulation.model = ["I", "II"]
        [link]
        gear.bearing_stiffness = "pinion.bearing_stiffness"
        [sample]
        method = "lhs"
        n = 3
        [sample.dimensions]
        pinion.bearing_stiffness = { low = "5e5 N/m", high = "2e6 N/m" }
    """)
    p = sw.plan()
    assert p.grid_shape == (3, 3, 2) and p.n_samples == 3 and p.n_runs == 54
    depths, torques, models = [0.001, 0.0025, 0.004], [50.0, 100.0, 150.0], ["I", "II"]
    expected = [(d, t, m, s) for d, t, m in itertools.product(depths, torques, models)
                for s in range(3)]
    for run, (d, t, m, s) in enumerate(expected):
        ov = p.overrides(run)
        assert ov["crack.depth"] == pytest.approx(d, rel=1e-15)
        assert ov["motor.torque"] == pytest.approx(t, rel=1e-15)
        assert ov["simulation.model"] == m
        # the same sampled points for every grid point (crossed design)
        assert ov["pinion.bearing_stiffness"] == p.values["pinion.bearing_stiffness"][s]
        assert ov["gear.bearing_stiffness"] == ov["pinion.bearing_stiffness"]
    units = {q.key: q.units for q in p.parameters}
    assert units == {"crack.depth": "m", "motor.torque": "N m", "simulation.model": "",
                     "pinion.bearing_stiffness": "N/m", "gear.bearing_stiffness": "N/m"}
    roles = {q.key: q.role for q in p.parameters}
    assert roles["gear.bearing_stiffness"] == "link" and roles["crack.depth"] == "axis"


@pytest.mark.parametrize(("rng", "expected"), [
    ('{ start = "1 mm", stop = "2 mm", num = 5 }', np.linspace(1e-3, 2e-3, 5)),
    ('{ start = "1 mm", stop = "2 mm", step = "0.25 mm" }', np.linspace(1e-3, 2e-3, 5)),
    ('{ start = "1 mm", stop = "2.1 mm", step = "0.25 mm" }', np.linspace(1e-3, 2e-3, 5)),
    ('{ start = "3 mm", stop = "1 mm", step = "-1 mm" }', [3e-3, 2e-3, 1e-3]),
    ('{ start = "1 mm", stop = "8 mm", num = 4, scale = "log" }', [1e-3, 2e-3, 4e-3, 8e-3]),
    ('{ start = 0.5e-3, stop = 0.5e-3, num = 1 }', [0.5e-3]),
])
def test_ranges(rng, expected):
    p = sweep(f"[axes]\ncrack.depth = {rng}\n").plan()
    np.testing.assert_allclose(p.values["crack.depth"], expected, rtol=1e-12)


def test_integer_range_and_explicit_integers():
    p = sweep("[axes]\npinion.teeth = { start = 19, stop = 25, step = 3 }\n").plan()
    assert p.values["pinion.teeth"].tolist() == [19, 22, 25]
    assert p.values["pinion.teeth"].dtype == np.int64
    assert isinstance(p.overrides(0)["pinion.teeth"], int)


@pytest.mark.parametrize("method", ["sobol", "lhs"])
def test_sampling_reproducible_in_bounds_and_equal_to_scipy(method):
    text = f"""
        seed = 42
        [sample]
        method = "{method}"
        n = 16
        [sample.dimensions]
        load.speed = {{ low = "80 rad/s", high = "150 rad/s" }}
        mesh.damping_ratio = {{ low = 0.02, high = 0.2, scale = "log" }}
    """
    a, b = sweep(text).plan(), sweep(text).plan()
    c = sweep(text.replace("seed = 42", "seed = 43")).plan()
    sp, zr = a.values["load.speed"], a.values["mesh.damping_ratio"]
    np.testing.assert_array_equal(sp, b.values["load.speed"])
    assert not np.allclose(sp, c.values["load.speed"])
    assert sp.min() >= 80 and sp.max() <= 150
    assert zr.min() >= 0.02 and zr.max() <= 0.2
    # the oracle: scipy's engine called directly with the same seed, mapped by hand
    eng = qmc.Sobol(2, scramble=True, rng=42) if method == "sobol" else \
        qmc.LatinHypercube(2, rng=42)
    u = eng.random_base2(4) if method == "sobol" else eng.random(16)
    np.testing.assert_allclose(sp, 80 + u[:, 0] * 70, rtol=1e-14)
    np.testing.assert_allclose(zr, 0.02 * 10.0 ** u[:, 1], rtol=1e-12)
    # one point per 1/16 stratum of each coordinate (Sobol' net / Latin hypercube)
    for col in a.unit_points.T:
        assert sorted(np.floor(col * 16).astype(int)) == list(range(16))


def test_per_run_seeds_stable_and_distinct():
    s = run_seeds(7, 100)
    assert len(set(s.tolist())) == 100
    np.testing.assert_array_equal(run_seeds(7, 10, start=90), s[90:])
    assert s[5] == np.random.SeedSequence(7, spawn_key=(5,)).generate_state(1)[0]
    p = sweep("seed = 7\n[axes]\nmotor.torque = [50, 60, 70]\n").plan()
    np.testing.assert_array_equal(p.seeds, s[:3])


def test_nested_and_quoted_keys_are_the_same_axis():
    a = sweep('[axes]\n"crack.depth" = ["1 mm", "2 mm"]\n').plan()
    b = sweep('[axes.crack]\ndepth = ["1 mm", "2 mm"]\n').plan()
    np.testing.assert_array_equal(a.values["crack.depth"], b.values["crack.depth"])


def test_set_overrides_apply_to_the_base_case():
    sw = sweep('[set]\nsimulation.record_time = "0.2 s"\n[axes]\nmotor.torque = [50]\n')
    assert sw.base_case.simulation.record_time == pytest.approx(0.2)


@pytest.mark.parametrize(("text", "field", "words"), [
    ('[axes]\npinion.tooth = [1, 2]\n', "axes.pinion.tooth", "not a key of pinion"),
    ('[axes]\npinon.teeth = [20]\n', "axes.pinon.teeth", "not a key"),
    ('[axes]\npinion = [1]\n', "axes.pinion", "whole section"),
    ('[axes]\ncrack.depth = ["1 mm", "5 kg"]\n', "axes.crack.depth[1]", "length"),
    ('[axes]\npinion.bearing_stiffness = ["1e6 N/m", "-1e6 N/m"]\n',
     "axes.pinion.bearing_stiffness[1]", "greater than 0"),
    ('[axes]\npinion.teeth = [20, 22.5]\n', "axes.pinion.teeth[1]", "whole number"),
    ('[axes]\nsimulation.model = ["I", "III"]\n', "axes.simulation.model[1]", "'II'"),
    ('[axes]\ncrack.depth = []\n', "axes.crack.depth", "non-empty"),
    ('[axes]\ncrack.depth = ["1 mm", "1 mm"]\n', "axes.crack.depth", "distinct"),
    ('[axes]\ncrack.depth = { start = "1 mm", stop = "2 mm" }\n', "axes.crack.depth",
     "exactly one of 'num' or 'step'"),
    ('[axes]\ncrack.depth = { start = "1 mm", stop = "2 mm", step = "-1 mm" }\n',
     "axes.crack.depth.step", "towards stop"),
    ('[axes]\nload.table_speeds = [[1.0, 2.0]]\n', "axes.load.table_speeds[0]", "one value"),
    ('[axes]\nload.table_speeds = [1.0, 2.0]\n', "axes.load.table_speeds", "lists cannot"),
    ('[axes]\nmotor.torque = [50]\n[wrong]\nx = 1\n', "wrong", "allowed keys here"),
    ('[axes]\nmotor.torque = { start = 1, stop = 2, nm = 3 }\n', "axes.motor.torque.nm",
     "num, scale, start, step, stop"),
    ('[axes]\nmotor.torque = [50]\n[store]\ntsa = "yes"\n', "store.tsa", "boolean"),
    ('[axes]\nmotor.torque = [50]\n[execution]\nbatch_size = 0\n', "execution.batch_size",
     "positive"),
    ('seed = -1\n[axes]\nmotor.torque = [50]\n', "seed", "greater than or equal to 0"),
    ('[sample]\nn = 10\n[sample.dimensions]\nload.speed = { low = 80, high = 150 }\n',
     "sample", "power of two"),
    ('[sample]\nn = 8\n[sample.dimensions]\nload.speed = { low = 150, high = 80 }\n',
     "sample.dimensions.load.speed.high", "above low"),
    ('[sample]\nn = 8\n[sample.dimensions]\nmesh.damping_ratio = { low = 0, high = 0.1, '
     'scale = "log" }\n', "sample.dimensions.mesh.damping_ratio.low", "positive"),
    ('[sample]\nn = 8\n[sample.dimensions]\npinion.teeth = { low = 20, high = 30 }\n',
     "sample.dimensions.pinion.teeth", "continuous"),
    ('[sample]\nn = 8\n[sample.dimensions]\nload.speed = { low = "80 m", high = 150 }\n',
     "sample.dimensions.load.speed.low", "angular velocity"),
    ('[set]\nmotor.torque = 50\n[axes]\nmotor.torque = [50, 60]\n', "axes.motor.torque",
     "[set]"),
    ('[axes]\nmotor.torque = [50]\n[link]\ngear.mass = "pinion.mass"\n', "link.gear.mass",
     "swept in [axes]"),
    ('[axes]\nmotor.torque = [50]\n[link]\ngear.mass = "motor.torque"\n', "link.gear.mass",
     "same kind and unit"),
    ('[set]\npinion.teeth = 3\n[axes]\nmotor.torque = [50]\n', "set.pinion.teeth",
     "greater than or equal to 5"),
    ('name = "x"\n', "axes", "at least one axis"),
    ('base = "no_such_case"\n[axes]\nmotor.torque = [50]\n', "base", "xue_howard"),
    ('[axes]\ndiagnostics.samples_per_rev = [1024, 2048]\n[store]\ntsa = true\n', "store.tsa",
     "samples_per_rev"),
    ('[axes]\nsimulation.dt = ["1e-5 s", "5e-6 s"]\n[store]\nraw = true\n', "store.raw",
     "simulation.dt"),
])
def test_bad_sweep_files_name_the_field(text, field, words):
    with pytest.raises(InputError) as info:
        sweep(text)
    assert info.value.field == field, str(info.value)
    assert words in str(info.value)


def test_bad_files(tmp_path):
    with pytest.raises(DataFileError, match="no such file"):
        load_sweep(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[axes\n")
    with pytest.raises(DataFileError, match="not valid TOML"):
        load_sweep(bad)


def test_relative_base_case_and_shipped_example(tmp_path):
    from geardyn.config import case_to_toml, paper_case

    (tmp_path / "cases").mkdir()
    (tmp_path / "cases" / "mine.toml").write_text(case_to_toml(paper_case(
        {"motor.torque": 77.0})))
    f = tmp_path / "s.toml"
    f.write_text('base = "cases/mine.toml"\n[axes]\ncrack.depth = ["1 mm"]\n')
    assert load_sweep(f).base_case.motor.torque == 77.0
    ex = load_sweep("crack_torque_bearing")  # the shipped example, by name
    p = ex.plan()
    assert p.grid_shape == (7, 3, 3) and p.n_runs == 63
    assert p.values["crack.depth"].min() == 0.0  # the healthy tooth is the first depth
    assert [q.key for q in p.parameters] == ["crack.depth", "motor.torque",
                                            "pinion.bearing_stiffness", "gear.bearing_stiffness"]
    np.testing.assert_allclose(np.unique(p.values["pinion.bearing_stiffness"]),
                               [5e5, 1e6, 2e6], rtol=1e-12)
    assert math.isclose(ex.base_case.stiffness.centre_distance_max, 3.8e-3)


def test_a_huge_grid_is_refused_before_it_is_expanded(monkeypatch):
    """1e6 x 1e6 runs: refused at once (before any value is expanded), with the count, the
    limit and how to raise it; the limit is the caller's to raise."""
    from geardyn.studies.sweep import DEFAULT_MAX_RUNS

    huge = textwrap.dedent("""
        [axes]
        motor.torque = { start = "50 N m", stop = "150 N m", num = 1000000 }
        load.speed = { start = "80 rad/s", stop = "150 rad/s", num = 1000000 }
    """)
    with pytest.raises(InputError) as info:
        parse_sweep(huge)
    msg = str(info.value)
    assert "1,000,000,000,000 runs" in msg and f"{DEFAULT_MAX_RUNS:,}" in msg
    assert "--max-runs" in msg and "GEARDYN_MAX_RUNS" in msg
    small = '[axes]\nmotor.torque = ["50 N m", "60 N m", "70 N m"]\n[sample]\nmethod = "lhs"\n' \
            'n = 2\n[sample.dimensions]\nload.speed = { low = "80 rad/s", high = "90 rad/s" }\n'
    with pytest.raises(InputError, match="got '6 runs'; allowed: at most 5 runs"):
        parse_sweep(small, max_runs=5)
    assert parse_sweep(small, max_runs=6).n_runs == 6
    monkeypatch.setenv("GEARDYN_MAX_RUNS", "5")
    with pytest.raises(InputError, match="at most 5 runs"):
        parse_sweep(small)
    monkeypatch.setenv("GEARDYN_MAX_RUNS", "many")
    with pytest.raises(InputError, match="GEARDYN_MAX_RUNS"):
        parse_sweep(small)
    # a 'step' range is counted once resolved
    monkeypatch.delenv("GEARDYN_MAX_RUNS")
    with pytest.raises(InputError, match="got '201 runs'"):
        parse_sweep('[axes]\nmotor.torque = { start = "50 N m", stop = "150 N m", '
                    'step = "0.5 N m" }\n', max_runs=200)


def test_long_axes_are_checked_at_their_bounds():
    """An axis of more than 200 values: its extreme values are still checked against the case
    (the bad one named by its index); the others are converted and type-checked."""
    values = ", ".join(f'"{v} kg"' for v in [*range(1, 150), -1, *range(150, 300)])
    with pytest.raises(InputError) as info:
        parse_sweep(f"[axes]\npinion.mass = [{values}]\n")
    assert info.value.field == "axes.pinion.mass[149]"
    values = ", ".join(f'"{v} N m"' for v in range(1, 301))
    assert parse_sweep(f"[axes]\nmotor.torque = [{values}]\n").n_runs == 300


def test_cli_refuses_a_huge_grid_in_one_line(tmp_path):

    from ._procs import env

    f = tmp_path / "huge.toml"
    f.write_text('[axes]\nmotor.torque = { start = "50 N m", stop = "150 N m", num = 1000000 }\n'
                 'load.speed = { start = "80 rad/s", stop = "150 rad/s", num = 1000000 }\n')
    r = run_geardyn(["sweep", str(f), "--out", str(tmp_path / "o.zarr")],
                    capture_output=True, text=True, env=env(), timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "1,000,000,000,000 runs" in r.stderr
    assert not (tmp_path / "o.zarr").exists()

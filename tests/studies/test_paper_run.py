"""``geardyn run``: the paper's case study end to end, as a user runs it.

A shortened configuration (short records, a coarse PEM map) keeps this fast; the full-size run is
``geardyn run`` itself (and ``benchmarks/bench_run.py``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from geardyn.studies.paper_validation import validation_tables

from .._cli_fork import run_geardyn

pytestmark = pytest.mark.slow

SHORT = ["--quick", "--stiffness", "pem", "--set", "simulation.record_time=0.2 s", "--set",
         "simulation.settle_time=0.05 s", "--set", "stiffness.centre_distances=11", "--set",
         "diagnostics.samples_per_rev=1024"]


@pytest.fixture(scope="module")
def run_cache(tmp_path_factory):
    """The run's own cache folder (the session's is shared with the other test worker, whose
    entries would come and go under :func:`test_warm_rerun_uses_the_cache`)."""
    return tmp_path_factory.mktemp("run-cache")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory, run_cache):
    out = tmp_path_factory.mktemp("run") / "out"
    r = run_geardyn(["run", "--out", str(out), *SHORT],
                    capture_output=True, text=True, timeout=600,
                    env={**os.environ, "GEARDYN_CACHE_DIR": str(run_cache)})
    assert r.returncode == 0, r.stderr + r.stdout
    return out, r


def test_summary_keys_and_paper_levels(run_dir):
    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    assert s["complete"] is True
    # static torque balance on the bearings (eq. 4) with zero torsional damping: 1.0852 mm,
    # 21.194 deg, contact ratio 1.4175 (physical) / 1.4286 (eq. 8); consistency, not validation
    assert s["centre_distance_change_mm"] == pytest.approx(1.0852, abs=2e-3)
    assert s["operating_pressure_angle_deg"] == pytest.approx(21.194, abs=5e-3)
    assert s["contact_ratio"]["physical"] == pytest.approx(1.4175, abs=1e-3)
    assert s["contact_ratio"]["paper_eq8"] == pytest.approx(1.4286, abs=1e-3)
    assert s["mean_pinion_speed_rad_s"] == pytest.approx(114.14, abs=0.01)
    assert s["mean_transmission_error_rad"] == pytest.approx(0.048, abs=2e-3)
    assert 150 <= s["crack_angle_deg"] <= 190
    for table in ("table2", "table3"):
        assert set(s[table]) == {"gear_vertical_velocity", "pinion_angular_velocity",
                                 "transmission_error"}
        for sig in s[table].values():
            assert set(sig) == {"I", "I-static", "II"}
    assert set(s["table2"]["transmission_error"]["I"]) == {"mean", "std", "skewness", "kurtosis",
                                                           "crest_factor"}
    rows = s["validation"]
    assert rows and all(set(v) >= {"quantity", "paper", "geardyn", "tolerance", "pass"}
                        for v in rows)


def test_model_ii_differs_from_model_i_where_the_paper_says(run_dir):
    """Phase modulation: the paper's striking difference between the models is the PM level;
    the crack raises the condition metrics in both models."""
    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    t3 = s["table3"]
    for sig in t3.values():
        d = abs(sig["II"]["pm_mean_deg"] - sig["I"]["pm_mean_deg"]) % 360
        assert min(d, 360 - d) > 10  # the PM level moves between the models
    cm = s["condition_metrics"]["gear_vertical_velocity"]
    assert set(cm) == {"I", "I-static", "II"}  # I-static: geardyn's addition, both states
    for m in ("I", "I-static", "II"):
        assert cm[m]["cracked"]["FM4"] > 1.5 * cm[m]["healthy"]["FM4"]
        assert cm[m]["cracked"]["EnergyRatio"] > 1.5 * cm[m]["healthy"]["EnergyRatio"]


class _Html(HTMLParser):
    def __init__(self):
        super().__init__()
        self.imgs, self.ext, self.text = [], [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.imgs.append(a)
        if tag in ("script", "link") or (tag == "img" and not a["src"].startswith("data:")):
            self.ext.append(tag)

    def handle_data(self, data):
        self.text.append(data)


def test_report_is_self_contained_with_every_figure(run_dir):
    out, _ = run_dir
    p = _Html()
    p.feed((out / "report.html").read_text())
    text = " ".join(p.text)
    assert not p.ext
    assert len(p.imgs) >= 19  # Figs. 5a, 5b, 6, 8-23
    assert all(img.get("alt") for img in p.imgs)
    for words in ("Table 2", "Table 3", "Consistency checks (not validation)",
                  "Comparisons with the paper", "Corrections to the paper", "Citations",
                  "Where geardyn disagrees"):
        assert words in text
    assert "reproduced the paper" not in text
    assert "design/" not in text and "dynamics.md" not in text
    assert len(list((out / "figures").glob("*.png"))) == len(p.imgs)


def test_results_open_the_obvious_way_and_are_compressed(run_dir):
    """results.nc opens with xr.open_dataset (tables at the root) and open_datatree (maps and
    diagnostics in groups); each simulated record is its own file in runs/, compressed."""
    out, _ = run_dir
    root = xr.open_dataset(out / "results.nc", engine="h5netcdf")
    assert {"table2", "table3", "paper_table2", "condition_metrics"} <= set(root.data_vars)
    assert "runs/model_II_cracked.nc" in root.attrs["contents"]
    s = json.loads((out / "summary.json").read_text())
    np.testing.assert_allclose(
        root["table2"].sel(signal="transmission_error", model="II", statistic2="std").item(),
        s["table2"]["transmission_error"]["II"]["std"], rtol=1e-15)
    # summary.json's units of the tables (built from the diagnoses' signal units) are
    # results.nc's unit coordinates (built from the report's own table of signal units)
    units = s["table_units"]
    for g in root["signal"].values:
        for k in root["statistic2"].values:
            assert units["table2"][g][k] == \
                root["statistic2_units"].sel(signal=g, statistic2=k).item(), (g, k)
        assert units["table3"][g] == dict(zip(root["statistic3"].values.tolist(),
                                              root["statistic3_units"].values.tolist(),
                                              strict=True))
    assert units["table2"]["transmission_error"]["std"] == "rad"
    root.close()
    tree = xr.open_datatree(out / "results.nc", engine="h5netcdf")
    assert {"stiffness", "diagnostics"} <= set(tree.children)
    # every model in both states (model I-static's healthy record was simulated but not
    # diagnosed until 2026-11-27)
    assert set(tree["diagnostics"].children) == {f"model_{m}_{st}" for m in ("I", "I-static", "II")
                                                 for st in ("healthy", "cracked")}
    assert {"healthy", "cracked"} <= set(tree["stiffness"].children)
    assert tree["diagnostics/model_II_cracked"]["v_yg_tsa"].attrs["units"] == "m/s"
    tree.close()
    runs = {p.name for p in (out / "runs").glob("*.nc")}
    assert runs == {"model_I_cracked.nc", "model_II_cracked.nc", "model_I_healthy.nc",
                    "model_II_healthy.nc", "model_II-start_cracked.nc",
                    "model_I-static_cracked.nc", "model_I-static_healthy.nc"}
    with xr.open_dataset(out / "runs" / "model_II_cracked.nc", engine="h5netcdf") as ds:
        assert ds["centre_distance_change"].attrs["units"] == "m"
        assert ds["v_yg"].dtype == np.float64 and ds["theta_p"].dtype == np.float64
    with h5py.File(out / "runs" / "model_II_cracked.nc", "r") as f:
        for name in ("v_yg", "theta_p", "transmission_error", "mesh_stiffness"):
            assert f[name].compression == "gzip" and f[name].shuffle, name
        assert f["v_yg"].dtype == np.float64
        assert f["mesh_stiffness"].dtype == np.float32  # shown only (Figs. 9, 10)
    assert s["output_size_bytes"]["results.nc"] == (out / "results.nc").stat().st_size


def test_diagnose_accepts_what_run_writes(run_dir, tmp_path):
    out, _ = run_dir
    r = run_geardyn(["diagnose",
                     str(out / "runs" / "model_II_cracked.nc"), "--out", str(tmp_path / "d"),
                     "--set", "diagnostics.samples_per_rev=1024"],
                    capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr + r.stdout
    m = json.loads((tmp_path / "d" / "metrics.json").read_text())
    s = json.loads((out / "summary.json").read_text())

    def numbers(node):
        if isinstance(node, dict):
            for v in node.values():
                yield from numbers(v)
        elif isinstance(node, list):
            for v in node:
                yield from numbers(v)
        elif isinstance(node, float):
            yield node

    # the same diagnosis as the report's Table 3 for that record
    want = s["table3"]["gear_vertical_velocity"]["II"]["residual_kurtosis"]
    assert any(abs(x - want) <= 1e-6 * abs(want) for x in numbers(m))
    r = run_geardyn(["diagnose", str(out / "results.nc"),
                     "--out", str(tmp_path / "d2")], capture_output=True, text=True,
                    timeout=120)
    assert r.returncode == 2
    assert "runs" in r.stderr and "model_II_cracked.nc" in r.stderr and "Traceback" not in r.stderr


class _Tables(HTMLParser):
    """Every table of the report as lists of cell texts, and the CSS class of each cell."""

    def __init__(self):
        super().__init__()
        self.rows: list[list[tuple[str, str]]] = []
        self._cell: list[str] | None = None
        self._cls = ""

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell, self._cls = [], dict(attrs).get("class") or ""

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append(("".join(self._cell).strip(), self._cls))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def _row_passes(r: dict) -> bool:
    """Pass/fail recomputed here, independently of geardyn.studies.paper_validation."""
    g, ref, tol = r["geardyn"], r["reference"], r["tolerance"]
    if g is None or not np.isfinite(g):
        return False
    if r["tolerance_kind"] == "factor":
        return g > 0 and abs(np.log(g / ref)) <= np.log(tol) + 1e-12
    return abs(g - ref) <= tol


def test_every_validation_row_is_asserted(run_dir):
    """Each check and comparison: its status recomputed from its numbers and from the summary,
    and shown so in the report (issue 20, item 3)."""
    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    assert s["paper_case"] is True and s["differences_from_paper"] == []
    rows = s["checks"] + s["comparisons"]
    assert len(s["comparisons"]) == 42 and len(s["checks"]) >= 10
    again = validation_tables(s, paper_case=True)
    assert [r["pass"] for r in again["checks"] + again["comparisons"]] == [r["pass"] for r in rows]
    for r in rows:
        assert r["pass"] == bool(_row_passes(r)), r["quantity"]
    p = _Tables()
    p.feed((out / "report.html").read_text())
    shown = {cells[0][0]: cells for cells in p.rows if len(cells) == 7}
    for r in rows:
        cells = shown[r["quantity"]]
        assert cells[4] == ("pass", "pass") if r["pass"] else cells[4] == ("FAIL", "fail")
    # the misses are counted in the summary paragraph and each is listed with a reason
    n_miss = sum(not r["pass"] for r in s["comparisons"])
    text = (out / "report.html").read_text()
    assert f"{42 - n_miss} of 42 within their tolerance, {n_miss} outside" in text
    for stat in {r["statistic"] for r in s["comparisons"] if not r["pass"]}:
        label = next(r["quantity"].split(",")[0] for r in s["comparisons"]
                     if r["statistic"] == stat)
        assert f"{label}: " in text


def test_undefined_metrics_and_run_times(run_dir):
    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    # the shipped case's healthy teeth are all alike: NA4* has a zero baseline in exact arithmetic
    assert "NA4star" in s["condition_metrics_undefined"]
    for sig in s["condition_metrics"].values():
        for m in sig.values():
            assert m["healthy"]["NA4star"] is None and m["cracked"]["NA4star"] is None
    p = _Tables()
    p.feed((out / "report.html").read_text())
    na4 = [c for c in p.rows if len(c) == 6 and c[1][0] == "NA4star"]
    er = [c for c in p.rows if len(c) == 6 and c[1][0] == "EnergyRatio"]
    assert len(na4) == len(er) == 9  # three signals, models I, I-static and II
    assert all(c[2][0] == c[3][0] == c[4][0] == "undefined" for c in na4)
    assert all(c[4][0] == "undefined" for c in er)
    stages = {c[0][0] for c in p.rows if len(c) == 2}
    assert {"geometry", "stiffness", "simulation", "diagnostics",
            "report (until this file was written)", "total"} <= stages
    assert set(s["run_time_s"]) >= {"report", "total"}
    backlash = [c for c in p.rows if len(c) == 7 and c[0][0] == "design"]
    assert backlash and backlash[0][6][0] == "0"  # the design pair has zero backlash


def _text(out: Path) -> str:
    import html
    import re

    p = _Html()
    p.feed((out / "report.html").read_text())
    return re.sub(r"\s+", " ", html.unescape(" ".join(p.text)))


def test_model_i_static_column_in_tables_2_and_3(run_dir):
    """Tables 2 and 3 gain a model I-static column (geardyn's values; '-' for the paper, which
    has none); the comparisons with the paper stay the 42 rows of models I and II."""
    from geardyn.studies.report import fmt

    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    assert {r["model"] for r in s["comparisons"]} == {"I", "II"} and len(s["comparisons"]) == 42
    p = _Tables()
    p.feed((out / "report.html").read_text())
    heads = [[c for c, _ in row] for row in p.rows if len(row) == 8
             and row[2][0] == "paper, model I"]
    assert len(heads) == 2  # Table 2 and Table 3
    for h in heads:
        assert h[2:] == ["paper, model I", "geardyn, model I", "paper, model I-static",
                         "geardyn, model I-static", "paper, model II", "geardyn, model II"]
    stats2 = {"mean", "std", "skewness", "kurtosis", "crest factor"}
    body = [[c for c, _ in row] for row in p.rows if len(row) == 8 and row[1][0] in stats2]
    assert len(body) == 15  # 3 signals x 5 statistics
    names = list(s["table2"])
    for i, row in enumerate(body):
        sig, stat = names[i // 5], row[1].replace(" ", "_")
        assert row[4] == "-"  # the paper has no model I-static
        assert row[5] == fmt(s["table2"][sig]["I-static"][stat])
        assert row[3] == fmt(s["table2"][sig]["I"][stat])
        assert row[7] == fmt(s["table2"][sig]["II"][stat])
    k3 = [row for row in p.rows if len(row) == 8 and row[1][0] == "residual kurtosis (text of "
          "Fig. 13)"]
    assert len(k3) == 3 and all(row[4][0] == "-" for row in k3)
    assert [float(row[5][0]) for row in k3] == pytest.approx(
        [s["table3"][sig]["I-static"]["residual_kurtosis"] for sig in names], rel=1e-3)
    with xr.open_dataset(out / "results.nc", engine="h5netcdf") as root:
        assert list(root["model"].values) == ["I", "I-static", "II"]
        np.testing.assert_array_equal(
            root["table3"].sel(model="I-static", statistic3="residual_kurtosis").values,
            [s["table3"][sig]["I-static"]["residual_kurtosis"] for sig in names])
        assert np.isnan(root["paper_table2"].sel(model="I-static").values).all()
        assert np.isfinite(root["paper_table2"].sel(model="II").values).all()


def test_model_comparison_recomputed_from_the_run_files(run_dir):
    """summary.json's model comparison equals compare_models of the records written to runs/,
    and RMS(II - I-static) / STD by hand for two signals; results.nc carries it with units.

    Figures measured on this short PEM run (0.2 s recorded): RMS(II - I-static) / STD(II)
    1.4-7.0 %, RMS(II - I) / STD(II) 82-147 % over the ten signals (docs/verification
    dynamics, full record: PEM 1.5-7.8 %, model I 82-140 %). Asserted: below 10 % and above
    50 %, i.e. the static shift explains more than 80 % of the II - I difference.
    """
    from geardyn.studies.model_compare import compare_models
    from geardyn.studies.paper import RUN_ENCODING_FLOAT32
    from geardyn.studies.paper_report import model_comparison_statements

    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    mc = s["model_comparison"]
    assert set(mc) == {"cracked", "healthy"}
    for state in ("cracked", "healthy"):
        recs = [xr.open_dataset(out / "runs" / f"model_{m}_{state}.nc", engine="h5netcdf")
                for m in ("I", "I-static", "II")]
        cmp = compare_models(*recs)
        got = mc[state]["signals"]
        assert list(got) == [str(v) for v in cmp["signal"].values]
        for i, sig in enumerate(got):
            rtol = 1e-4 if sig in RUN_ENCODING_FLOAT32 else 1e-12  # float32 in runs/*.nc
            for var in ("rms_ii_minus_i_static", "rms_ii_minus_i", "explained_fraction"):
                assert got[sig][var] == pytest.approx(float(cmp[var].values[i]), rel=rtol), \
                    (state, sig, var)
            assert got[sig]["rms_ii_minus_i_static"] < 0.10
            assert got[sig]["rms_ii_minus_i"] > 0.5
            assert got[sig]["explained_fraction"] > 0.8
        for sig in ("v_yg", "transmission_error"):  # by hand, independently of compare_models
            a1, a1s, a2 = (r[sig].values for r in recs)
            std = a2.std()
            rs = np.sqrt(np.mean((a2 - a1s) ** 2)) / std
            r1 = np.sqrt(np.mean((a2 - a1) ** 2)) / std
            assert got[sig]["rms_ii_minus_i_static"] == pytest.approx(rs, rel=1e-12)
            assert got[sig]["explained_fraction"] == pytest.approx(1 - rs / r1, rel=1e-12)
            d2 = np.sort((a2 - a1s) ** 2)
            n = int(np.ceil(0.01 * d2.size))
            assert got[sig]["top_share"] == pytest.approx(d2[-n:].sum() / d2.sum(), rel=1e-9)
        assert mc[state]["static_centre_distance_change_mm"] == pytest.approx(
            1e3 * recs[1].attrs["stiffness_centre_distance_change"], rel=1e-12)
        for r in recs:
            r.close()
    with xr.open_dataset(out / "results.nc", engine="h5netcdf") as root:
        for var in ("rms_ii_minus_i_static", "rms_ii_minus_i", "explained_fraction",
                    "top_share"):
            assert root[var].attrs["units"] == "1" and root[var].attrs["long_name"]
            for state in ("cracked", "healthy"):
                np.testing.assert_array_equal(
                    root[var].sel(comparison_state=state).values,
                    [mc[state]["signals"][g][var] for g in root["compared_signal"].values])
        assert root["static_centre_distance_change"].attrs["units"] == "m"
        units = dict(zip(root["compared_signal"].values, root["compared_signal_units"].values,
                         strict=True))
        assert units["v_yg"] == "m/s" and units["mesh_force"] == "N"
    # the report's section: the table's numbers and the sentences generated from them
    text = _text(out)
    assert "How much of the model II - model I difference the static shift explains" in text
    said = model_comparison_statements(mc, "pem")
    assert len(said) == 4  # cracked, healthy, where the rest sits, the PEM's handover steps
    for sentence in said:
        assert sentence in text
    worst = max(v["rms_ii_minus_i_static"] for v in mc["cracked"]["signals"].values())
    assert f"to within {100 * worst:.3g} % of each signal's STD" in said[0]
    assert "time-step effect" in said[3]
    s_figs = s["figures"]
    assert "fig_model_comparison.png" in s_figs and "fig10_stiffness.png" in s_figs
    assert "dashed: model I-static" in text


#: A user's case with unequal gears (the QA walkthrough's 25/31 pair): --quick's own record
#: length (long enough for the realistic-measurement stage, which SHORT's is not) and map.
OWN = ["--quick", "--stiffness", "pem", "--set", "diagnostics.samples_per_rev=1024"]


@pytest.fixture(scope="module")
def own_case_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("own") / "out"
    r = run_geardyn(["run", "--out", str(out), *OWN,
                     "--set", "pinion.teeth=25", "--set", "gear.teeth=31"],
                    capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr + r.stdout
    return out


def test_a_users_own_case_is_not_compared_with_the_paper(own_case_dir):
    out = own_case_dir
    s = json.loads((out / "summary.json").read_text())
    assert s["paper_case"] is False
    assert s["differences_from_paper"] == [{"key": "pinion.teeth", "paper": 23, "case": 25},
                                           {"key": "gear.teeth", "paper": 23, "case": 31}]
    assert s["comparisons"] == [] and s["validation"] == []
    assert s["checks"] and not any("paper" in r["source"] for r in s["checks"])
    p = _Html()
    p.feed((out / "report.html").read_text())
    text = " ".join(p.text)
    title = text.split("Contents")[0]
    assert "geardyn: case '" in title and "pinion.teeth = 25" in title
    for words in ("Xue & Howard (2018) case study:", "23/23", "reproduced", "Comparisons with the paper",
                  "paper, model I", "Where geardyn disagrees", "(paper:"):
        assert words not in text, words
    assert "What differs from the paper's case" in text and "pinion.teeth" in text
    with xr.open_dataset(out / "results.nc", engine="h5netcdf") as root:
        assert "paper_table2" not in root.data_vars and "table2" in root.data_vars


def test_own_case_realistic_record_is_reproduced_by_the_printed_commands(own_case_dir,
                                                                          tmp_path):
    """The report's geardyn measure / diagnose commands write this run's realistic records:
    its case (case.toml, with --set and --stiffness), its quick map and record length; diagnose
    reads the teeth from the file. Their FM4 is the report's."""
    import re
    import shlex

    from geardyn.config import load_case

    out = own_case_dir
    s = json.loads((out / "summary.json").read_text())
    written = load_case(out / "case.toml")
    assert written.pinion.teeth == s["differences_from_paper"][0]["case"] == 25
    assert written.gear.teeth == s["differences_from_paper"][1]["case"] == 31
    assert written.stiffness.method == "pem"
    text = _text(out)
    m = re.search(r"\): (geardyn measure .*?--out healthy\.nc) and (geardyn measure .*?--out "
                  r"faulty\.nc), then (geardyn diagnose .*?) and (geardyn diagnose .*?tach)\. ",
                  text)
    assert m, text[text.find("The same realistic records"):][:600]
    cmds = m.groups()
    assert all(f"-c {out / 'case.toml'}" in c for c in cmds)
    assert "--teeth" not in text
    for c in cmds:
        r = run_geardyn(shlex.split(c)[1:], cwd=tmp_path, timeout=600)
        assert r.returncode == 0, r.stderr + r.stdout
    real = s["measurement"]["indicators"]["errors+noise"]
    for name, state in (("healthy", "healthy"), ("faulty", "cracked")):
        got = json.loads((tmp_path / f"{name}-diagnose" / "metrics.json").read_text())
        fm4 = got["signals"]["acc"]["condition_metrics"]["FM4"]
        assert fm4 == pytest.approx(real[state]["FM4"], rel=1e-9), name
        assert f"{real[state]['FM4']:.4g} {state}" in text


def test_own_case_report_and_results_say_what_the_run_computed(own_case_dir):
    """Map grid from the map itself, the transmission error as the record defines it, the
    shipped case's notes marked, one word for a value not computed, units in results.nc."""
    out = own_case_dir
    s = json.loads((out / "summary.json").read_text())
    text = _text(out)
    with xr.open_dataset(out / "results.nc", group="stiffness/healthy", engine="h5netcdf") as g:
        dd = g["centre_distance_change"].values
    assert (f"changes {dd[0] * 1e3:g} to {dd[-1] * 1e3:g} mm on {dd.size} grid lines"
            in text)
    with xr.open_dataset(out / "runs" / "model_II_cracked.nc", engine="h5netcdf") as ds:
        te = ds["transmission_error"].attrs
    formula = "theta_p - (r_b2/r_b1) theta_g"
    assert formula in te["long_name"]
    assert f"transmission error {formula} [{te['units']}]" in text
    assert "theta_p - theta_g [" not in text
    p = _Tables()
    p.feed((out / "report.html").read_text())
    tooth = [c for c in p.rows if len(c) == 3 and c[0][0] == "crack.tooth"]
    assert tooth and tooth[0][2][0].endswith(
        "[note of the shipped case, for its pinion.teeth = 23, gear.teeth = 23: not about this "
        "case]")
    hd = s["measurement"]["housing_damping"]
    assert hd.get("not_computed")  # --quick's record is too short for the lightest damping
    for z in hd["not_computed"]:
        row = next(c for c in p.rows if len(c) == 7 and c[0][0] == f"{100 * float(z):g}")
        assert [c for c, _ in row[2:]] == ["not computed"] * 5
        assert f"{100 * float(z):g}%: not computed" in text
    with xr.open_dataset(out / "results.nc", engine="h5netcdf") as root:
        for name, v in root.variables.items():
            if name in root.coords:
                assert v.attrs.get("long_name"), name
            else:
                u = v.attrs.get("units")
                assert u is None or " " not in u, (name, u)  # a unit, not prose
                assert u is not None or v.attrs.get("units_coordinate") in root.coords, name
        t2 = root["table2"].sel(signal="transmission_error", model="II")
        assert t2.sel(statistic2="std")["statistic2_units"].item() == te["units"]
        assert t2.sel(statistic2="kurtosis")["statistic2_units"].item() == "1"
        t3 = root["table3"].sel(signal="transmission_error", model="II")
        assert t3.sel(statistic3="pm_mean_deg")["statistic3_units"].item() == "deg"
        assert t3.sel(statistic3="pm_mean_deg").item() == pytest.approx(
            s["table3"]["transmission_error"]["II"]["pm_mean_deg"], rel=1e-15)


def test_warm_rerun_uses_the_cache(run_dir, run_cache, tmp_path):
    """A second run of the same inputs reads the maps and records from the cache: it adds no
    cache entry (a record of what was built, not a wall-clock ratio)."""
    out, _ = run_dir
    cache = Path(run_cache)
    before = sorted(p.relative_to(cache) for p in cache.rglob("*.nc"))
    out2 = tmp_path / "again"
    r = run_geardyn(["run", "--out", str(out2), *SHORT],
                    capture_output=True, text=True, timeout=600,
                    env={**os.environ, "GEARDYN_CACHE_DIR": str(cache)})
    assert r.returncode == 0, r.stderr + r.stdout
    after = sorted(p.relative_to(cache) for p in cache.rglob("*.nc"))
    assert before and after == before
    # the CLI's record of cache lookups (geardyn.cache.record_lookups): every map and record hit
    cache_use = json.loads((out2 / "inputs.json").read_text())["cache"]
    assert cache_use["stiffness"] == {"hits": 2, "built": 0}
    assert cache_use["simulation"]["built"] == 0 and cache_use["simulation"]["hits"] >= 7
    a = json.loads((out / "summary.json").read_text())
    b = json.loads((out2 / "summary.json").read_text())
    assert a["table2"] == b["table2"] and a["centre_distance_change_mm"] == \
        b["centre_distance_change_mm"]


@pytest.mark.skipif(shutil.which("chromium") is None and shutil.which("chromium-browser") is None,
                    reason="headless Chromium not installed (apt-get install chromium)")
def test_report_renders_in_a_real_browser(run_dir, tmp_path):
    """Headless Chromium loads the report offline and paints it (a non-blank screenshot)."""
    import numpy as np
    from PIL import Image

    out, _ = run_dir
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    shot = tmp_path / "shot.png"
    subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1280,4000",
                    f"--screenshot={shot}", (out / "report.html").as_uri()],
                   capture_output=True, timeout=180)
    img = np.asarray(Image.open(shot).convert("L"))
    assert img.shape == (4000, 1280)
    dark = img < 128
    assert dark.mean() > 0.01  # text and figures were painted
    assert dark[:400].any()  # the title at the top


def test_progress_one_bar_per_stage_with_its_own_count(run_dir, run_cache, tmp_path,
                                                      monkeypatch):
    """The library's progress calls: stage announcements in order, then for every bar a count
    that runs from 0 to its own total without jumps to another bar's count (issue 13)."""
    from geardyn.config import paper_case
    from geardyn.studies.paper import STAGES, run_paper_study

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(run_cache))  # run_dir's maps and records

    calls = []
    sets = [a for a in SHORT[SHORT.index("--set"):] if a != "--set"]
    run_paper_study(paper_case(sets), tmp_path / "p", quick=True, stiffness="pem",
                    progress=lambda stage, done, total: calls.append((stage, done, total)))
    names = [n for n, _ in STAGES]
    announced = [c[0] for c in calls if c[0] in names + ["done"] and c[2] == len(names)]
    assert announced == names + ["done"]
    bars: dict[str, list[tuple[int, int]]] = {}
    for stage, done, total in calls:
        if stage in names + ["done"] and total == len(names):
            continue
        bars.setdefault(stage.partition(": ")[0], []).append((done, total))
    assert {"stiffness (healthy)", "stiffness (cracked)", "simulation", "diagnostics",
            "report"} <= set(bars)
    for bar, seq in bars.items():
        totals = {t for _, t in seq}
        assert len(totals) == 1, (bar, seq)
        dones = [d for d, _ in seq]
        assert dones == sorted(dones) and dones[-1] == seq[-1][1], (bar, seq)
    # seven records; six diagnosed (models I, I-static and II, both states: not II-start)
    assert bars["simulation"][-1] == (7, 7) and bars["diagnostics"][-1] == (6, 6)

"""``geardyn run``: the paper's case study end to end, as a user runs it.

A shortened configuration (short records, a coarse map) keeps this fast; the full-size run is
``geardyn run`` itself (and ``benchmarks/bench_run.py``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from html.parser import HTMLParser

import h5py
import pytest

SHORT = ["--quick", "--set", "simulation.record_time=0.2 s", "--set", "simulation.settle_time=0.05 s",
         "--set", "stiffness.centre_distances=11", "--set", "diagnostics.samples_per_rev=1024"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "out"
    r = subprocess.run([sys.executable, "-m", "geardyn", "run", "--out", str(out), *SHORT],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr + r.stdout
    return out, r


def test_summary_keys_and_paper_levels(run_dir):
    out, _ = run_dir
    s = json.loads((out / "summary.json").read_text())
    assert s["complete"] is True
    # dynamics.md "checked numbers": static balance 1.0852 mm, 21.194 deg, 1.4175 / 1.4286
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
            assert set(sig) == {"I", "II"}
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
    for m in ("I", "II"):
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
    for words in ("Table 2", "Table 3", "Paper vs geardyn", "Errata", "Citations",
                  "Where geardyn disagrees"):
        assert words in text
    assert len(list((out / "figures").glob("*.png"))) == len(p.imgs)


def test_results_netcdf_has_everything_with_units(run_dir):
    out, _ = run_dir
    with h5py.File(out / "results.nc", "r") as f:
        assert {"stiffness", "simulation", "diagnostics"} <= set(f)
        assert {"healthy", "cracked"} <= set(f["stiffness"])
        assert {"model_I_cracked", "model_II_cracked", "model_I_healthy",
                "model_II_healthy"} <= set(f["simulation"])
        v = f["simulation/model_II_cracked/centre_distance_change"]
        assert v.attrs["units"] in (b"m", "m")
        assert "summary_json" in f.attrs


def test_warm_rerun_uses_the_cache(run_dir, tmp_path):
    out, _ = run_dir
    out2 = tmp_path / "again"
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-m", "geardyn", "run", "--out", str(out2), *SHORT],
                       capture_output=True, text=True, timeout=600, env=env)
    assert r.returncode == 0
    a = json.loads((out / "summary.json").read_text())
    b = json.loads((out2 / "summary.json").read_text())
    assert a["table2"] == b["table2"] and a["centre_distance_change_mm"] == \
        b["centre_distance_change_mm"]
    # the stiffness and simulation stages read the cache: much faster than cold
    assert b["run_time_s"]["simulation"] < 0.5 * a["run_time_s"]["simulation"] + 0.5


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

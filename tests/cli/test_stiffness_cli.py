"""``geardyn stiffness`` as a user runs it: files, units, summary, errors."""

from __future__ import annotations

import os
import sys

import pytest
import xarray as xr

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
SMALL = ["--method", "pem", "--set", "stiffness.centre_distances=6",
         "--set", "stiffness.nodes_per_segment=8"]


def run(*args, cache):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache)}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       timeout=300)


@pytest.mark.slow
def test_stiffness_writes_maps_and_figures(tmp_path):
    out = tmp_path / "out"
    r = run("stiffness", "--out", str(out), *SMALL, cache=tmp_path / "c")
    assert r.returncode == 0, r.stderr
    for name in ("stiffness_healthy.nc", "stiffness_cracked.nc", "fig5_stiffness.png",
                 "fig5_load_sharing.png", "fig6_crack.png"):
        assert (out / name).stat().st_size > 1000, name
    assert "mean K_t" in r.stdout and "+1.00" in r.stdout
    assert "interpolated" not in r.stdout  # 0, 0.5 and 1 mm are on the 6-point grid
    # on a 3-point grid (-0.5, 0.75, 2 mm) the rows at 0, 0.5 and 1 mm are interpolated: marked
    r3 = run("stiffness", "--out", str(tmp_path / "out3"), *SMALL, "--set",
             "stiffness.centre_distances=3", cache=tmp_path / "c")
    assert r3.returncode == 0, r3.stderr
    assert r3.stdout.count(" * │") == 6 and "interpolated in the map" in r3.stdout, r3.stdout
    # map notes come once each as "note: ..." lines, never as Python's path-and-code warnings
    notes = [ln for ln in r.stderr.splitlines() if ln.startswith("note:")]
    assert len(notes) == len(set(notes)) and ".py:" not in r.stderr
    with xr.open_dataset(out / "stiffness_cracked.nc", engine="h5netcdf") as ds:
        assert ds["k_mb"].attrs["units"] == "N/m"
        assert ds["torsional_stiffness"].attrs["units"] == "N m/rad"
        assert ds.sizes["centre_distance_change"] == 6
        assert ds.attrs["method"] == "pem"
        healthy_min = float(xr.open_dataset(out / "stiffness_healthy.nc",
                                            engine="h5netcdf")["k_mb"].min())
        assert float(ds["k_mb"].min()) < healthy_min
    # a second run loads the maps from the cache and writes the same files
    again = run("stiffness", "--out", str(tmp_path / "out2"), *SMALL, cache=tmp_path / "c")
    assert again.returncode == 0, again.stderr
    with xr.open_dataset(out / "stiffness_healthy.nc", engine="h5netcdf") as a, \
            xr.open_dataset(tmp_path / "out2" / "stiffness_healthy.nc", engine="h5netcdf") as b:
        assert (a["k_mb"].values == b["k_mb"].values).all()


def _invoke(args, cache):
    """In process (typer's CliRunner): fast, same command function."""
    from typer.testing import CliRunner

    from geardyn.cli import app

    return CliRunner().invoke(app, args, env={"GEARDYN_CACHE_DIR": str(cache)})


@pytest.mark.slow
def test_stiffness_without_a_crack(tmp_path):
    out = tmp_path / "out"
    r = _invoke(["stiffness", "--out", str(out), "--set", "crack.enabled=false", *SMALL],
                tmp_path / "c")
    assert r.exit_code == 0, r.output
    assert (out / "stiffness_healthy.nc").exists() and (out / "fig5_stiffness.png").exists()
    assert not (out / "stiffness_cracked.nc").exists()
    assert "no enabled crack" in r.output


@pytest.mark.parametrize(("args", "words"), [
    (["--method", "magic"], "--method"),
    (["--set", "crack.depth=40mm"], "crack.depth"),
    (["--set", "stiffness.centre_distance_max=6mm"], "stiffness.centre_distance_max"),
])
def test_bad_input_exits_2(tmp_path, args, words):
    r = _invoke(["stiffness", "--out", str(tmp_path / "o"), *SMALL, *args], tmp_path / "c")
    assert r.exit_code == 2, r.output
    assert words in r.output
    assert "Traceback" not in r.output


def test_a_second_write_copies_every_file_and_draws_nothing(tmp_path, monkeypatch):
    """``geardyn stiffness`` writes its maps and figures through the output cache: into another
    folder the same maps give the same bytes, copied, with no figure drawn and (FE) no body
    meshed again; a map of other values is drawn anew."""
    import filecmp

    import geardyn.stiffness.fe as fe
    import geardyn.stiffness.plots as plots
    from geardyn import paper_case
    from geardyn.cache import record_lookups
    from geardyn.stiffness import build_map
    from geardyn.studies.stiffness_outputs import write_stiffness_outputs

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    case = paper_case(["stiffness.method=pem", "stiffness.centre_distances=3",
                       "stiffness.nodes_per_segment=8", "stiffness.fe.refinement=0.25"])
    maps = {"healthy": build_map(case, method="pem", cracked=False),
            "cracked": build_map(case, method="pem", cracked=True)}
    files = ["stiffness_healthy.nc", "stiffness_cracked.nc", "fig5_stiffness.png",
             "fig5_load_sharing.png", "fig6_crack.png", "fe_mesh.png"]
    with record_lookups() as first:
        assert write_stiffness_outputs(tmp_path / "a", case, maps, "fe", True) == files
    assert [r["hit"] for r in first if r["kind"] == "output"] == [False] * 6

    def never(*_a, **_k):
        raise AssertionError("drawn again")

    for name in ("fig_stiffness", "fig_load_sharing", "fig_crack"):
        monkeypatch.setattr(plots, name, never)
    monkeypatch.setattr(fe, "plot_mesh", never)
    with record_lookups() as second:
        assert write_stiffness_outputs(tmp_path / "b", case, maps, "fe", True) == files
    assert [r["hit"] for r in second if r["kind"] == "output"] == [True] * 6
    for name in files:
        assert filecmp.cmp(tmp_path / "a" / name, tmp_path / "b" / name, shallow=False), name
    # a cracked map of other values: its file and Fig. 6 anew (the healthy ones copied)
    other = {"healthy": maps["healthy"],
             "cracked": build_map(case.with_overrides({"crack.depth": "3 mm"}), method="pem",
                                  cracked=True)}
    with pytest.raises(AssertionError, match="drawn again"):
        write_stiffness_outputs(tmp_path / "c", case, other, "pem", True)
    assert filecmp.cmp(tmp_path / "a" / "fig5_stiffness.png", tmp_path / "c" / "fig5_stiffness.png",
                       shallow=False)
    assert not filecmp.cmp(tmp_path / "a" / "stiffness_cracked.nc",
                           tmp_path / "c" / "stiffness_cracked.nc", shallow=False)


def test_healthy_figures_drawn_ahead_are_the_ones_written_later(tmp_path, monkeypatch):
    """``healthy_figures_ahead`` (drawn while the FE bodies' second process still builds the
    faulty body) puts Fig. 5's two figures into the output cache under the keys that
    :func:`write_stiffness_outputs` looks up: the later write copies them, draws neither again,
    and its bytes are a plain write's; the run's record counts each entry once, as computed.
    Without the cache nothing is drawn ahead."""
    import filecmp

    import geardyn.stiffness.plots as plots
    from geardyn import paper_case
    from geardyn.cache import record_lookups
    from geardyn.cli._outputs import cache_summary
    from geardyn.stiffness import build_map
    from geardyn.studies.stiffness_outputs import healthy_figures_ahead, write_stiffness_outputs

    case = paper_case(["stiffness.method=pem", "stiffness.centre_distances=3",
                       "stiffness.nodes_per_segment=8"])
    maps = {"healthy": build_map(case, method="pem", cracked=False)}
    drawn = []
    real = {name: getattr(plots, name) for name in ("fig_stiffness", "fig_load_sharing")}
    for name, fn in real.items():
        monkeypatch.setattr(plots, name, lambda m, _n=name, _f=fn: (drawn.append(_n), _f(m))[1])
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    with record_lookups() as lookups:
        healthy_figures_ahead(maps["healthy"])
        assert sorted(drawn) == ["fig_load_sharing", "fig_stiffness"]
        assert list((tmp_path / "cache" / "output").glob("*.png"))  # in the cache only
        written = write_stiffness_outputs(tmp_path / "a", case, maps, "pem", False)
    assert written == ["stiffness_healthy.nc", "fig5_stiffness.png", "fig5_load_sharing.png"]
    assert len(drawn) == 2  # copied, not drawn again
    assert cache_summary(lookups)["output"] == {"hits": 0, "built": 3}
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "plain"))
    write_stiffness_outputs(tmp_path / "b", case, maps, "pem", False)
    for name in ("fig5_stiffness.png", "fig5_load_sharing.png"):
        assert filecmp.cmp(tmp_path / "a" / name, tmp_path / "b" / name, shallow=False), name
    drawn.clear()
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    healthy_figures_ahead(maps["healthy"])
    assert drawn == []

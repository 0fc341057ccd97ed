"""Optional extras (issue 17.6): the sweep needs the ``sweep`` extra and says so; nothing else
imports Dask or Zarr, so ``pip install . && geardyn run`` works without them."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import textwrap

import pytest
from typer.testing import CliRunner

from geardyn._optional import EXTRAS, MissingExtraError, missing_modules, require_extra
from geardyn.errors import GeardynError


@pytest.fixture
def without_zarr(monkeypatch):
    """Make ``zarr`` look uninstalled to ``importlib.util.find_spec``."""
    real = importlib.util.find_spec

    def fake(name, *args, **kwargs):
        return None if name.split(".")[0] == "zarr" else real(name, *args, **kwargs)

    monkeypatch.setattr(importlib.util, "find_spec", fake)


def test_sweep_extra_is_installed_in_the_test_environment():
    assert missing_modules("sweep") == []
    require_extra("sweep")  # no error
    assert EXTRAS["sweep"][0] == ("dask", "distributed", "zarr")


def test_missing_extra_error_names_the_extra(without_zarr):
    assert missing_modules("sweep") == ["zarr"]
    with pytest.raises(MissingExtraError, match=r"zarr: install them with pip install "
                                                r"'geardyn\[sweep\]'"):
        require_extra("sweep")
    assert issubclass(MissingExtraError, GeardynError)  # the CLI's exit-2 family


def test_sweep_entry_points_refuse_without_the_extra(without_zarr, tmp_path):
    from geardyn.studies.sweep import open_sweep, run_sweep, verify_store

    for call in (lambda: run_sweep(tmp_path / "none.toml", tmp_path / "out"),
                 lambda: open_sweep(tmp_path / "store"),
                 lambda: verify_store(tmp_path / "store")):
        with pytest.raises(MissingExtraError, match=r"geardyn\[sweep\]"):
            call()


def test_cli_sweep_without_the_extra_exits_2_with_one_line(without_zarr, tmp_path):
    from geardyn.cli import app

    res = CliRunner().invoke(app, ["sweep", str(tmp_path / "s.toml"), "--out",
                                   str(tmp_path / "out")])
    assert res.exit_code == 2
    text = res.output.strip()
    assert len(text.splitlines()) == 1 and "pip install 'geardyn[sweep]'" in text
    assert "Traceback" not in text


def test_run_path_does_not_import_dask_or_zarr():
    """Block dask/distributed/zarr and import what ``geardyn run`` and ``diagnose`` use."""
    code = textwrap.dedent("""
        import sys
        for name in ("dask", "distributed", "zarr"):
            sys.modules[name] = None  # any import of them now raises ImportError
        import geardyn.cli
        import geardyn.cli.run, geardyn.cli.diagnose, geardyn.cli.simulate
        import geardyn.studies.paper
        import geardyn.diagnostics
        loaded = sorted(m for m in ("dask", "distributed", "zarr") if sys.modules.get(m))
        print("loaded:", loaded)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "loaded: []" in out.stdout

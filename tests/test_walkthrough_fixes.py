"""Small things a researcher met in the QA walkthrough of the fault and static-TE commands, each
failing on the code before its fix."""

from __future__ import annotations

from pathlib import Path

import pytest

import geardyn
from geardyn.config import load_case
from geardyn.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "faults"


def test_a_misspelt_key_of_a_fault_lists_the_keys_a_fault_has():
    with pytest.raises(InputError) as exc:
        load_case(EXAMPLES / "spall.toml", ["faults.0.widht=3mm"])
    assert exc.value.field == "faults[0].widht"  # as the faults' own checks name entries
    assert "Allowed keys in faults[0]: angle, depth," in exc.value.allowed
    assert "width" in exc.value.allowed.split("faults[0]:")[1]


def test_the_wear_gap_of_a_map_has_its_unit_and_the_slot_dimension():
    from geardyn.stiffness import build_map

    case = load_case(EXAMPLES / "wear.toml", ['stiffness.method="pem"',
                                              "stiffness.centre_distances=4",
                                              "stiffness.nodes_per_segment=8"])
    ds = build_map(case, cracked=True).to_dataset()
    gap = ds["fault_gap"]
    assert gap.attrs["units"] == "m" and gap.attrs["long_name"] != "fault_gap"
    assert gap.dims == ("centre_distance_change", "node", "slot")
    assert gap.max() > 0


def test_an_unloaded_static_te_is_one_curve():
    from geardyn.static_te import static_te_curves

    case = geardyn.paper_case({"stiffness.method": "pem", "stiffness.centre_distances": 4,
                               "stiffness.nodes_per_segment": 8})
    ds = static_te_curves(case, 0.0, n=64)
    assert list(ds["torque"].values) == [0.0]
    assert list(static_te_curves(case, 50.0, n=64)["torque"].values) == [0.0, 50.0]


def test_config_validate_says_a_sweep_file_is_one():
    """It said "base: unknown key" of the shipped sweep files."""
    from typer.testing import CliRunner

    from geardyn.cli import app

    sweep = EXAMPLES / "sweep_spall_width.toml"
    r = CliRunner().invoke(app, ["config", "validate", str(sweep)])
    assert r.exit_code == 2
    assert "a sweep file (it has [base], [axes]" in r.output and "geardyn sweep FILE" in r.output


def test_config_show_says_what_validate_would_refuse(tmp_path):
    """It showed a crack deeper than the tooth without a word (exit 0) where validate refuses."""
    import os

    from ._cli_fork import run_geardyn

    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    r = run_geardyn(["config", "show", "--set", "crack.depth=20 mm"], capture_output=True,
                    text=True, env=env, timeout=120)
    assert r.returncode == 0 and "[crack.depth]" in r.stdout, r.stderr
    assert "does not pass 'geardyn config validate': crack.depth: got '20 mm" in r.stderr
    r = run_geardyn(["config", "show"], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0 and "does not pass" not in r.stderr

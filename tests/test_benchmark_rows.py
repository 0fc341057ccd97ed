"""The benchmark table says by how much each target is met or missed (issue 16: "the benchmark
table ... shows each target met or says by how much it misses")."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

_SPEC = importlib.util.spec_from_file_location(
    "bench_common", Path(__file__).resolve().parents[1] / "benchmarks" / "_common.py")
common = importlib.util.module_from_spec(_SPEC)
sys.modules.setdefault("bench_common", common)  # (dataclasses look the module up)
_SPEC.loader.exec_module(common)
Row = common.Row


def test_margin_of_a_time_target_met_and_missed():
    assert Row("quick", 12.48, "s", target="< 15 s (issue 16)", met=True).margin == "by 2.52 s"
    assert Row("quick", 18.67, "s", target="< 15 s (issue 16)", met=False).margin == "by 3.67 s"


def test_margin_in_the_rows_unit_only():
    assert Row("memory", 970.0, "MB", target="< 600 MB", met=False).margin == "by 370 MB"
    assert Row("rate", 1.1e7, "lookups/s", target="> 1e7 lookups/s", met=True).margin == \
        "by 1e+06 lookups/s"
    # a target in another unit, or relative to another figure: no margin rather than a wrong one
    assert Row("step", 0.147, "us/step", target="<= 1.5x the C step", met=True).margin == ""
    assert Row("scaling", 85.0, "%", target=">= 80 % of one worker", met=True).margin == "by 5 %"
    assert Row("memory", 0.97, "GB", target="< 600 MB", met=False).margin == ""
    assert Row("no target", 1.0, "s").margin == ""
    assert Row("skipped", math.nan, "s", target="< 1 s").margin == ""

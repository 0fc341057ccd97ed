"""Progress: one bar per stage with its own count, no line wrapping on an 80-column terminal
(issue 13)."""

from __future__ import annotations

import io
import os
import re

import pytest
from rich.console import Console

from geardyn.cli import _common
from geardyn.cli._common import StageProgress, progress_bar

from .._cli_fork import run_geardyn

ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _lines(text: str) -> list[str]:
    return [ln for ln in re.split(r"[\r\n]", ANSI.sub("", text)) if ln.strip()]


class _RecordingBar:
    """Stands in for rich's Progress: records every task's (completed, total) updates."""

    def __init__(self):
        self.history: dict[int, list[tuple]] = {}
        self.labels: dict[int, str] = {}
        self.removed: set[int] = set()

    def add_task(self, description, total=None, **fields):
        tid = len(self.labels)
        self.labels[tid] = description
        self.history[tid] = []
        return tid

    def update(self, tid, description=None, completed=None, total="keep", **fields):
        if description is not None:
            self.labels[tid] = description
        self.history[tid].append((completed, total, fields.get("count")))

    def stop_task(self, tid):
        pass

    def remove_task(self, tid):
        self.removed.add(tid)


PAPER_LIKE = [  # the calls studies/paper.py makes today (stage announcements, sub-stages)
    ("geometry", 0, 5), ("stiffness", 1, 5),
    *[("stiffness (healthy)", k, 34) for k in range(35)],
    *[("stiffness (cracked)", k, 34) for k in range(35)],
    ("simulation", 2, 5), ("simulation: model I, cracked", 0, 5),
    ("simulation: model II, cracked", 1, 5), ("simulation: model I, healthy", 2, 5),
    ("simulation: model II, healthy", 3, 5), ("simulation: model II, paper's scheme", 4, 5),
    ("diagnostics", 3, 5), *[(f"diagnostics: model {m}", i, 4) for i, m in
                             enumerate(["I, cracked", "II, cracked", "I, healthy", "II, healthy"])],
    ("report", 4, 5), ("done", 5, 5),
]


def test_one_bar_per_stage_with_its_own_count():
    bar = _RecordingBar()
    p = StageProgress(bar, "run: ", stages=("geometry", "stiffness", "simulation", "diagnostics",
                                            "report"))
    for call in PAPER_LIKE:
        p(*call)
    shown = {tid: bar.labels[tid] for tid in bar.labels if tid not in bar.removed}
    assert sorted(shown.values()) == sorted([
        "run: geometry", "run: stiffness (healthy)", "run: stiffness (cracked)",
        "run: simulation", "run: diagnostics", "run: report"])
    for tid in shown:
        counts = [(c, t) for c, t, _ in bar.history[tid] if c is not None]
        totals = {t for _, t in counts if t not in (None, "keep")}
        assert len(totals) <= 1, (bar.labels[tid], counts)  # one count per bar: no 34/34 -> 0/5
        done = [c for c, _ in counts]
        assert done == sorted(done), (bar.labels[tid], done)  # never goes back
    by_label = {bar.labels[t]: bar.history[t][-1][2] for t in shown}
    assert by_label["run: stiffness (healthy)"] == "34/34"
    assert by_label["run: simulation"] == "5/5"
    assert by_label["run: diagnostics"] == "4/4"
    assert by_label["run: geometry"] == "done"


def test_rendered_bars_fit_80_columns(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(_common, "err_console", Console(file=buf, width=80, force_terminal=True))
    monkeypatch.setenv("GEARDYN_PROGRESS", "1")
    with progress_bar() as bar:
        p = StageProgress(bar, "run: ", stages=("simulation",))
        p("simulation: model II with the paper's start-of-step scheme, cracked tooth", 3, 123456)
        p("simulation: model II", 123456, 123456)
        p.close()
    lines = _lines(buf.getvalue())
    assert lines and all(len(ln) <= 80 for ln in lines), lines
    assert any("123456/123456" in ln for ln in lines)


@pytest.mark.slow
def test_stiffness_progress_through_the_cli(tmp_path):
    env = {**os.environ, "GEARDYN_PROGRESS": "1", "COLUMNS": "80",
           "GEARDYN_CACHE_DIR": str(tmp_path / "c")}
    r = run_geardyn(["stiffness", "--method", "pem", "--out",
                     str(tmp_path / "k"), "--set", "stiffness.centre_distances=6", "--set",
                     "stiffness.nodes_per_segment=8"], env=env, capture_output=True,
                    text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = _lines(r.stderr)
    assert all(len(ln) <= 80 for ln in lines), [ln for ln in lines if len(ln) > 80]
    final = {ln.split("━")[0].strip(): ln for ln in lines if "━" in ln}
    assert "6/6" in final["pem map, healthy"] and "6/6" in final["pem map, cracked"]


def test_plain_tasks_still_render_their_count(monkeypatch):
    """Commands that add tasks themselves (sweep, measure) keep working: done/total is shown."""
    buf = io.StringIO()
    monkeypatch.setattr(_common, "err_console", Console(file=buf, width=80, force_terminal=True))
    monkeypatch.setenv("GEARDYN_PROGRESS", "1")
    with progress_bar() as bar:
        task = bar.add_task("sweep demo", total=54)
        bar.update(task, completed=3)
    assert any("3/54" in ln for ln in _lines(buf.getvalue()))

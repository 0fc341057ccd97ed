"""The study waits for the kernel a second process compiles (rather than compile it too), and
draws its held figures meanwhile (``geardyn.studies.paper._wait_for_the_kernel``)."""

from __future__ import annotations

import time

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from geardyn.dynamics import warm  # noqa: E402
from geardyn.studies import paper  # noqa: E402
from geardyn.studies.figure_process import FigureProcess  # noqa: E402
from geardyn.studies.paper_result import FigureStore, StudyResult, render_png  # noqa: E402

DRAWN: list = []


def draw(y, *, title):
    DRAWN.append(title)
    fig, ax = plt.subplots(figsize=(2.0, 1.6))
    ax.plot(np.asarray(y))
    ax.set_title(title)
    return fig


def _held_store(titles) -> FigureStore:
    """A store whose figure process may never start: every figure handed over stays held."""
    store = FigureStore(FigureProcess(ready=lambda: False))
    for t in titles:
        store.cached(t, draw, np.arange(5.0) * len(t), title=t)
    assert [j.key for j in store._held] == list(titles)
    return store


class FakeCompiler:
    """A kernel compiler that is alive until ``alive_for`` joins have passed."""

    def __init__(self, alive_for: int):
        self.alive_for, self.joins, self.timeouts = alive_for, 0, set()

    def is_alive(self) -> bool:
        return self.joins < self.alive_for

    def join(self, timeout=None):
        self.joins += 1
        self.timeouts.add(timeout)
        time.sleep(min(timeout or 0.0, 0.01))


@pytest.fixture(autouse=True)
def _no_cache(monkeypatch):
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    DRAWN.clear()


def test_draw_held_while_draws_the_last_first_and_stops_when_told():
    store = _held_store(["a", "bb", "ccc"])
    budget = iter([True, True, False])
    assert store.draw_held_while(lambda: next(budget)) == 2
    assert DRAWN == ["ccc", "bb"]                    # the last held first
    assert [j.key for j in store._held] == ["a"]
    got = store["ccc"].png                           # stored under its name: not drawn again
    assert DRAWN == ["ccc", "bb"]
    assert got == render_png(draw(np.arange(5.0) * 3, title="ccc"))  # as finish would draw it
    assert store.draw_held_while(lambda: True) == 1  # and none left after
    assert store.draw_held_while(lambda: True) == 0
    store.finish()


def test_no_compiler_no_wait():
    result = StudyResult(out=None, figures=_held_store(["a"]))
    assert paper._wait_for_the_kernel(result) == 0.0
    assert DRAWN == [] and len(result.figures._held) == 1


def test_a_compiled_kernel_or_an_ended_process_is_not_waited_for(monkeypatch):
    monkeypatch.setattr(warm, "kernels_compiled", lambda: True)
    result = StudyResult(out=None, figures=_held_store(["a"]), kernel_compiler=FakeCompiler(99))
    paper._wait_for_the_kernel(result)
    assert result.kernel_compiler.joins == 0 and DRAWN == []   # nothing drawn, no join
    monkeypatch.setattr(warm, "kernels_compiled", lambda: False)
    result.kernel_compiler = FakeCompiler(0)                   # ended (whatever it did)
    paper._wait_for_the_kernel(result)
    assert result.kernel_compiler.joins == 0 and DRAWN == []


def test_it_draws_the_held_figures_then_waits_until_numba_has_the_kernel(monkeypatch):
    asked = []

    def compiled() -> bool:  # in numba's cache from the 10th question on
        asked.append(1)
        return len(asked) >= 10

    monkeypatch.setattr(warm, "kernels_compiled", compiled)
    compiler = FakeCompiler(alive_for=10_000)                  # still alive afterwards
    result = StudyResult(out=None, figures=_held_store(["a", "bb"]), kernel_compiler=compiler)
    paper._wait_for_the_kernel(result)
    assert DRAWN == ["bb", "a"]                                # every held figure, meanwhile
    assert len(asked) == 10                                    # stopped when numba had it
    # asked before each held figure and once more to find none left (3), then joined between
    # the questions until the 10th said yes
    assert compiler.joins == 10 - 3 - 1
    assert compiler.timeouts == {0.1}        # short joins: numba's cache is asked in between
    assert compiler.is_alive()


def test_the_wait_is_bounded(monkeypatch):
    monkeypatch.setattr(warm, "kernels_compiled", lambda: False)
    monkeypatch.setattr(paper, "KERNEL_COMPILE_WAIT_S", 0.2)
    result = StudyResult(out=None, kernel_compiler=FakeCompiler(alive_for=10 ** 9))
    waited = paper._wait_for_the_kernel(result)
    assert 0.2 <= waited < 60.0                                # the time waited [s]
    assert result.kernel_compiler.is_alive()                   # given up, not ended


@pytest.mark.parametrize("quick", [False, True])
def test_a_full_runs_bodies_process_is_the_kernel_compiler(quick):
    from geardyn.stiffness.fe.background import BackgroundBodies

    result = StudyResult(out=None, quick=quick)
    paper._note_bodies_process(result, BackgroundBodies(None))   # none started
    assert result.background == [] and result.kernel_compiler is None
    proc = object()
    paper._note_bodies_process(result, BackgroundBodies(proc))
    assert result.background == [proc]
    assert result.kernel_compiler is (None if quick else proc)

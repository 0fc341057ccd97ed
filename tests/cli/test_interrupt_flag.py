"""A Ctrl-C that a ctypes callback swallowed (numba compiling: "Exception ignored on calling
ctypes callback function ... KeyboardInterrupt") is raised again at the next progress tick (or
by the unraisable hook's delivery to the main thread, whichever comes first, once), so the
command still stops with exit 130 instead of running on (seen once in CI)."""

from __future__ import annotations

import signal
import time

import pytest
import typer

from geardyn.cli import _common as C


class _Bar:
    def add_task(self, *a, **k):
        return 0

    def update(self, *a, **k):
        pass

    def stop_task(self, *a, **k):
        pass


def test_a_swallowed_interrupt_is_raised_at_the_next_tick_and_exits_130():
    ticks = []

    @C.handle_errors
    def command():
        progress = C.StageProgress(_Bar())
        progress("model II", 0, 10)
        ticks.append(0)
        try:  # what llvmlite's ctypes callback does with the handler's KeyboardInterrupt
            signal.raise_signal(signal.SIGINT)
        except KeyboardInterrupt:
            pass
        progress("model II", 5, 10)   # the next tick raises it again
        ticks.append(5)

    with pytest.raises(typer.Exit) as exc:
        command()
    assert exc.value.exit_code == 130 and ticks == [0]
    assert C._INTERRUPT["pending"] is False          # cleared for the next command
    assert signal.getsignal(signal.SIGINT) is not C._on_sigint  # handler restored


def test_an_interrupt_swallowed_by_a_ctypes_callback_prints_no_traceback(capsys):
    """What llvmlite does while numba compiles: the KeyboardInterrupt is raised inside a ctypes
    callback, which Python reports through sys.unraisablehook ("Exception ignored ..." and a
    traceback) and otherwise drops."""
    import ctypes

    def callback():
        raise KeyboardInterrupt

    fn = ctypes.CFUNCTYPE(None)(callback)
    ticks = []

    @C.handle_errors
    def command():
        progress = C.StageProgress(_Bar())
        fn()                          # swallowed by ctypes, reported to the hook
        ticks.append("after the callback")
        progress("model II", 1, 10)   # raised again here

    with pytest.raises(typer.Exit) as exc:
        command()
    try:  # the hook's delivery to the main thread, due 1 ms after it, must not come now
        time.sleep(0.05)
    except KeyboardInterrupt:
        pytest.fail("the Ctrl-C was raised again after the command had handled it")
    err = capsys.readouterr().err
    assert exc.value.exit_code == 130 and ticks == ["after the callback"]
    assert "Traceback" not in err and "Exception ignored" not in err
    assert "interrupted" in err


def test_a_ctrl_c_that_an_import_turned_into_a_type_error_still_exits_130(capsys, monkeypatch):
    """A Ctrl-C landing while Python builds a failing import's ImportError comes out as
    ``TypeError: expected a message argument`` (seen in CI during the PEM map's imports). With a
    Ctrl-C pending, the command reports the interruption, not an internal error."""

    @C.handle_errors
    def command():
        try:
            signal.raise_signal(signal.SIGINT)
        except KeyboardInterrupt:  # what CPython's import machinery did with it
            raise TypeError("expected a message argument") from None

    monkeypatch.delenv("GEARDYN_DEBUG", raising=False)
    with pytest.raises(typer.Exit) as exc:
        command()
    err = capsys.readouterr().err
    assert exc.value.exit_code == 130
    assert "interrupted" in err and "internal error" not in err


def test_a_type_error_without_a_ctrl_c_is_still_an_internal_error(capsys, monkeypatch):
    """The mutant guard for the test above: the rule is keyed on the pending Ctrl-C only."""

    @C.handle_errors
    def command():
        raise TypeError("expected a message argument")

    monkeypatch.delenv("GEARDYN_DEBUG", raising=False)
    with pytest.raises(typer.Exit) as exc:
        command()
    assert exc.value.exit_code == 1
    assert "internal error" in capsys.readouterr().err

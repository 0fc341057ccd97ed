"""Helpers: the real CLI, in-process (typer's CliRunner) or as a subprocess with a hang guard."""

from __future__ import annotations

import subprocess

from typer.testing import CliRunner

from geardyn.cli import app

from .._cli_fork import run_geardyn

runner = CliRunner()

#: Hang guard of the subprocess calls [s]: generous because the 2 test cores are shared; the
#: bound these tests protect is "does not hang" (the unit bomb hung for ever before the fix).
HANG_GUARD = 120


def cli(*args: str):
    """Run ``geardyn ARGS`` in-process; returns the click Result."""
    return runner.invoke(app, list(args))


def cli_proc(*args: str, cwd=None) -> subprocess.CompletedProcess:
    """Run ``python -m geardyn ARGS`` in a subprocess."""
    return run_geardyn([*args], capture_output=True,
                       text=True, timeout=HANG_GUARD, cwd=cwd)


def assert_clean_error(result, *words: str) -> str:
    """Exit 2, one line under 500 characters, no traceback; the line contains ``words``."""
    if isinstance(result, subprocess.CompletedProcess):
        code, err, out = result.returncode, result.stderr, result.stdout
    else:
        code, err, out = result.exit_code, result.stderr, result.stdout
    assert code == 2, (code, out, err)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    line = lines[0]
    assert line.startswith("error:"), line
    assert len(line) < 500, len(line)
    assert "Traceback" not in err + out
    for w in words:
        assert w in line, (w, line)
    return line

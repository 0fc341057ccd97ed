"""A full disk is the machine's problem, said as such: one line naming the file, what to do,
exit 1, no "a bug in geardyn" (a user audit of 2026-11-27 read that for ENOSPC)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

CODE = """
import errno, sys, typer
from geardyn.cli._common import handle_errors

@handle_errors
def write():
    raise OSError(errno.{name}, "No space left on device", "/data/out/runs/model_II_cracked.nc")

try:
    write()
except typer.Exit as exc:
    print("exit", exc.exit_code)
"""


@pytest.mark.parametrize("name", ["ENOSPC", "EIO"])
def test_a_full_disk_is_not_called_a_bug(name):
    r = subprocess.run([sys.executable, "-c", CODE.format(name=name)], capture_output=True,
                       text=True, timeout=120, env={**os.environ, "COLUMNS": "300"})
    assert r.stdout.strip() == "exit 1", r.stdout + r.stderr
    line = " ".join(r.stderr.split())
    if name == "ENOSPC":
        assert line.startswith("error: No space left on device (writing /data/out/runs/"
                               "model_II_cracked.nc): free some space"), line
        assert "bug" not in line and "Traceback" not in line
    else:  # any other OSError is still an internal error
        assert "internal error: OSError" in line and "a bug in geardyn" in line, line

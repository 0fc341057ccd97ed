"""``geardyn.processes.skip_collection_at_exit``: the exit skips the collector's last passes and
nothing else."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_exit_handlers_still_run_and_the_collector_is_frozen_at_exit(tmp_path):
    """A handler registered before (which runs after, atexit being last-in first-out) sees the
    objects frozen; a temporary folder is still removed, a handler registered later still runs,
    output is flushed and the exit status is kept."""
    code = textwrap.dedent(f"""
        import atexit, gc, sys, tempfile
        atexit.register(lambda: print("frozen at exit:", gc.get_freeze_count() > 0, flush=True))
        from geardyn.processes import skip_collection_at_exit
        skip_collection_at_exit()
        tmp = tempfile.TemporaryDirectory(dir={str(tmp_path)!r})
        atexit.register(lambda: print("later handler ran"))
        sys.stdout.write("unflushed line")
        print(" frozen now:", gc.get_freeze_count() > 0)
        sys.exit(3)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 3, out.stderr
    assert out.stdout.splitlines() == ["unflushed line frozen now: False", "later handler ran",
                                       "frozen at exit: True"]
    assert list(tmp_path.iterdir()) == []


def test_the_console_script_exits_cleanly_with_its_status(tmp_path):
    """``python -m geardyn`` (which skips the last collection) prints, exits 0 on success and 2
    on a user error, with no traceback and nothing on stderr from the exit."""
    ok = subprocess.run([sys.executable, "-m", "geardyn", "--version"], capture_output=True,
                        text=True, timeout=120)
    assert ok.returncode == 0 and ok.stdout.strip() and ok.stderr == ""
    bad = subprocess.run([sys.executable, "-m", "geardyn", "config", "show", "-c",
                          str(tmp_path / "missing.toml")], capture_output=True, text=True,
                         timeout=120)
    assert bad.returncode == 2, (bad.stdout, bad.stderr)
    assert "Traceback" not in bad.stderr + bad.stdout

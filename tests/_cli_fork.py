"""``geardyn`` command lines in a real, separate process, without paying the imports each time.

The suite runs the CLI a few hundred times; a fresh ``python -m geardyn`` spends 0.4-0.6 s of
each on importing NumPy, SciPy, xarray, numba, matplotlib, scikit-fem, dask and zarr before
geardyn starts (measured 2026-11-26: ``geardyn config validate`` 0.68 -> 0.22 s,
``geardyn diagnose`` 0.75 -> 0.31 s, a short ``geardyn simulate`` 1.48 -> 0.91 s; pint,
``dask.distributed`` and numba's registries, which each command still loaded again, were added
on 2026-11-27: four CLI-heavy test files 78 -> 60 s in one process). Here a
server process imports those third-party libraries (and geardyn's library modules, not its CLI)
once per test worker and *forks* one child per command line: the child is a separate process
that imports geardyn's CLI itself (its consoles see the child's environment), runs its entry
point as ``python -m geardyn`` would (``__main__`` is ``geardyn.__main__``, so spawned
helpers start the same way), with the test's arguments, environment, working folder and
standard streams, and exits with the CLI's own exit code after a normal interpreter shutdown.
Exit codes, output, tracebacks, files written and signals are the real ones; only the
imports were done before the fork.

:func:`run_geardyn` falls back to ``subprocess.run`` when the environment changes a variable
that a library reads when it is imported (``NUMBA_*``, ``DASK_*``, ``MPL*``, ``PYTHON*``,
``OMP_*``, ...), or with ``GEARDYN_CLI_FORK=0``. Tests that signal or kill a running command
keep using ``subprocess.Popen``.
"""

from __future__ import annotations

import atexit
import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Environment variables read at import time by a pre-imported library: a change falls back.
IMPORT_TIME_PREFIXES = ("NUMBA_", "DASK_", "MPL", "MATPLOTLIB", "PYTHON", "OMP_", "OPENBLAS_",
                        "MKL_", "MALLOC_", "LD_", "HDF5_", "ZARR_", "GMSH")
#: What the server imports before forking (third-party; geardyn's library modules follow in
#: PRELOAD_GEARDYN, its CLI is imported by each child, so its consoles see the child's
#: environment).
PRELOAD = ("numpy", "scipy.sparse", "scipy.sparse.linalg", "scipy.signal", "scipy.interpolate",
           "scipy.optimize", "scipy.stats", "xarray", "numba", "matplotlib.pyplot", "pydantic",
           "typer", "rich.console", "rich.progress", "skfem", "zarr", "dask", "dask.array",
           "h5netcdf",
           # imported by geardyn.units, and by xarray (its duck-array check); and
           # dask.distributed, which xarray imports on every to_netcdf where dask is installed
           # (its scheduler check): 0.3-0.5 s of each command that writes or converts units
           "pint", "distributed")
#: geardyn's library modules, imported by the server too (they read no environment variable
#: when imported, and create no console: ``geardyn.cli`` and its rich consoles, which read
#: COLUMNS and the terminal when created, are imported by each child); measured 0.1-0.2 s of
#: each command line (2026-11-26).
PRELOAD_GEARDYN = ("geardyn", "geardyn.config", "geardyn.geometry", "geardyn.cache", "geardyn.io",
                   "geardyn.stiffness", "geardyn.stiffness.map", "geardyn.dynamics",
                   "geardyn.diagnostics", "geardyn.measurement", "geardyn.studies.paper",
                   "geardyn.studies.paper_report")

_SERVER: dict[str, object] = {}


# --------------------------------------------------------------------------------- client
def _server():
    """The worker's server (started on first use, stopped at exit): (Popen, to, from)."""
    if _SERVER.get("proc") is not None and _SERVER["proc"].poll() is None:
        return _SERVER["proc"], _SERVER["to"], _SERVER["from"]
    req_r, req_w = os.pipe()
    rep_r, rep_w = os.pipe()
    env = dict(os.environ)
    proc = subprocess.Popen([sys.executable, __file__, str(req_r), str(rep_w)],
                            pass_fds=(req_r, rep_w), stdin=subprocess.DEVNULL, env=env)
    os.close(req_r)
    os.close(rep_w)
    _SERVER.update(proc=proc, to=req_w, env=env, buf=b"")
    _SERVER["from"] = rep_r
    atexit.register(_stop_server)
    return proc, req_w, rep_r


def _stop_server() -> None:
    proc = _SERVER.get("proc")
    if proc is not None and proc.poll() is None:
        os.close(_SERVER["to"])  # EOF: the server exits
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _read_line(fd: int, deadline: float | None) -> dict | None:
    """One JSON line from the server, or None at the deadline."""
    while b"\n" not in _SERVER["buf"]:
        wait = None if deadline is None else max(0.0, deadline - time.monotonic())
        ready, _, _ = select.select([fd], [], [], wait)
        if not ready:
            return None
        chunk = os.read(fd, 65536)
        if not chunk:
            raise RuntimeError("the geardyn CLI fork server exited")
        _SERVER["buf"] += chunk
    line, _SERVER["buf"] = _SERVER["buf"].split(b"\n", 1)
    return json.loads(line)


def _netcdf4_plugins() -> str | None:
    """The folder netCDF4 puts in ``HDF5_PLUGIN_PATH`` when it is imported (where unset), in the
    server and in this process alike once a test imports it; None without netCDF4."""
    import importlib.util

    spec = importlib.util.find_spec("netCDF4")
    if spec is None or spec.origin is None:
        return None
    return os.path.join(os.path.dirname(spec.origin), "plugins")


def _forkable(env: dict[str, str]) -> bool:
    if os.environ.get("GEARDYN_CLI_FORK", "1") == "0" or sys.platform == "win32":
        return False
    base = _SERVER.get("env") or os.environ
    for key in set(env) | set(base):
        if key == "PYTHONPATH":  # the child puts its entries on sys.path (_child)
            continue
        if key == "HDF5_PLUGIN_PATH" and {env.get(key), base.get(key)} <= {None,
                                                                            _netcdf4_plugins()}:
            continue  # set by netCDF4's import itself, not by the test
        if key.startswith(IMPORT_TIME_PREFIXES) and env.get(key) != base.get(key):
            return False
    return True


def run_geardyn(args, *, env: dict[str, str] | None = None, cwd=None, timeout: float | None = None,
                input: str | None = None, capture_output: bool = True, text: bool = True,
                stdin=None) -> subprocess.CompletedProcess:
    """``subprocess.run([sys.executable, "-m", "geardyn", *args], capture_output=True,
    text=True, env=env, cwd=cwd, timeout=timeout, input=input)``, in a forked child of the
    worker's server (see the module docstring). Raises ``subprocess.TimeoutExpired`` after
    killing the command's process group, as ``subprocess.run`` kills its child. ``stdin``
    may be ``subprocess.DEVNULL`` (the child's standard input is empty either way)."""
    if stdin not in (None, subprocess.DEVNULL):
        raise ValueError("run_geardyn: stdin is subprocess.DEVNULL or None (use input=)")
    args = [str(a) for a in args]
    env = dict(os.environ if env is None else env)
    cmd = [sys.executable, "-m", "geardyn", *args]
    if not (capture_output and text) or not _forkable(env):
        return subprocess.run(cmd, capture_output=capture_output, text=text, env=env, cwd=cwd,
                              timeout=timeout, input=input,
                              stdin=subprocess.DEVNULL if input is None else None)
    proc, to, frm = _server()
    with tempfile.TemporaryDirectory(prefix="geardyn-cli-") as tmp:
        out, err, inp = Path(tmp, "out"), Path(tmp, "err"), Path(tmp, "in")
        inp.write_text(input or "", encoding="utf-8")
        request = {"args": args, "env": env, "cwd": str(cwd or os.getcwd()), "stdout": str(out),
                   "stderr": str(err), "stdin": str(inp)}
        os.write(to, (json.dumps(request) + "\n").encode())
        started = _read_line(frm, time.monotonic() + 60)
        if started is None or "pid" not in started:
            raise RuntimeError(f"the geardyn CLI fork server did not start {args}: {started}")
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            done = _read_line(frm, deadline)
        except BaseException:  # e.g. pytest-timeout: as subprocess.run, kill the command
            _kill(started["pid"], frm)
            raise
        if done is None:  # timed out: kill the command and whatever it started
            _kill(started["pid"], frm)
            raise subprocess.TimeoutExpired(cmd, timeout, out.read_text(errors="replace"),
                                            err.read_text(errors="replace"))
        return subprocess.CompletedProcess(cmd, done["returncode"],
                                           out.read_text(encoding="utf-8", errors="replace"),
                                           err.read_text(encoding="utf-8", errors="replace"))


def _kill(pid: int, frm: int) -> None:
    """Kill a command's process group and wait for the server to reap it."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    _read_line(frm, time.monotonic() + 60)


# --------------------------------------------------------------------------------- server
def _child(request: dict) -> None:
    """In the forked child: become ``python -m geardyn`` with the request's arguments,
    environment, folder and streams; never returns (the interpreter exits normally)."""
    import importlib
    import io

    os.setpgid(0, 0)  # its own process group: a timeout kills it and its helpers
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    before = os.environ.get("PYTHONPATH", "")
    os.environ.clear()
    os.environ.update(request["env"])
    os.chdir(request["cwd"])
    sys.path[0] = os.getcwd()  # as ``python -m``: the working folder first, then PYTHONPATH
    if os.environ.get("PYTHONPATH", "") != before:
        extra = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
        sys.path[1:1] = [os.path.abspath(p) for p in extra]
    for fd, path, mode in ((0, request["stdin"], os.O_RDONLY),
                           (1, request["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC),
                           (2, request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC)):
        f = os.open(path, mode, 0o600)
        os.dup2(f, fd)
        os.close(f)
    sys.stdin = io.TextIOWrapper(io.FileIO(0, "r", closefd=False), encoding="utf-8")
    sys.stdout = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), encoding="utf-8",
                                  write_through=False)
    sys.stderr = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), encoding="utf-8",
                                  errors="backslashreplace", line_buffering=True)
    sys.__stdin__, sys.__stdout__, sys.__stderr__ = sys.stdin, sys.stdout, sys.stderr
    main = importlib.import_module("geardyn.__main__")
    sys.modules["__main__"] = main  # as with ``python -m geardyn`` (multiprocessing's spawn)
    sys.argv = [main.__file__, *request["args"]]
    main.main()  # SystemExit carries the exit code through a normal shutdown


def _exit_as_the_interpreter(request: dict) -> None:
    """Run the command in this (forked) process and exit as ``python -m geardyn`` would: the
    exit code of ``SystemExit``, or the traceback and 1; non-daemon threads joined, then the
    ``atexit`` handlers, then the streams flushed (the order of ``Py_FinalizeEx``)."""
    import atexit as _atexit
    import threading
    import traceback

    code, interrupted = 1, False
    try:
        _child(request)
        code = 0
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            code = exc.code or 0
        else:
            print(exc.code, file=sys.stderr)
    except KeyboardInterrupt:
        traceback.print_exc()
        interrupted = True
    except BaseException:
        traceback.print_exc()
    try:
        threading._shutdown()
        _atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        if interrupted:  # as CPython: die by SIGINT
            signal.signal(signal.SIGINT, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGINT)
        os._exit(code)


def _numba_registries() -> None:
    """numba's typing and lowering registries, which it loads on its first compile or cache
    load in a process (``numba.cpython.charseq``, ``listobj``, ``numbers``, ``arraymath``, ...:
    0.2-0.4 s of every command that runs a kernel), loaded once here. Nothing is compiled and
    no thread is started (a fork after that is as after the imports)."""
    import threading

    try:
        from numba.core.registry import cpu_target
    except ImportError:
        return
    cpu_target.typing_context.refresh()
    cpu_target.target_context.refresh()
    assert threading.active_count() == 1, "no thread before fork"


def _serve(req_fd: int, rep_fd: int) -> None:
    import importlib

    sys.path[0] = os.getcwd()  # not this script's folder (tests/): as ``python -m``
    for name in PRELOAD + PRELOAD_GEARDYN:
        try:
            importlib.import_module(name)
        except ImportError:  # an optional library missing: the child imports what it needs
            pass
    assert not [m for m in sys.modules if m.startswith("geardyn.cli")], "no console before fork"
    from geardyn.io import netcdf_engine

    netcdf_engine()  # imports netCDF4 where geardyn uses it (not where it clashes with h5py)
    _numba_registries()
    buf = b""
    while True:
        while b"\n" not in buf:
            chunk = os.read(req_fd, 65536)
            if not chunk:
                return
            buf += chunk
        line, buf = buf.split(b"\n", 1)
        request = json.loads(line)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            os.close(req_fd)
            os.close(rep_fd)
            _exit_as_the_interpreter(request)
        os.write(rep_fd, (json.dumps({"pid": pid}) + "\n").encode())
        _, status = os.waitpid(pid, 0)
        os.write(rep_fd, (json.dumps({"returncode": os.waitstatus_to_exitcode(status)}) + "\n")
                 .encode())


if __name__ == "__main__":
    _serve(int(sys.argv[1]), int(sys.argv[2]))

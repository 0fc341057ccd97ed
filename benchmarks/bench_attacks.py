"""Hostile and careless input through the CLI: exit 2, one short line, within 2 s (issue 19).

Each attack is a real ``geardyn`` command in a fresh process with a private cache. A row is met
when the command exits with code 2, prints exactly one non-empty line on stderr shorter than 500
characters, no traceback, and ends within 2 s of wall time. The baseline measured in the same run
is ``geardyn --version`` (the interpreter and CLI start-up every command pays).

The correctness of each message (field named, value, what is allowed) is asserted by the tests
named in the last column of :data:`ATTACKS`; this file measures only the time and the shape.
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tempfile
import time

from _common import Row

GEARDYN = [sys.executable, "-m", "geardyn"]
LIMIT_S = 2.0
MAX_CHARS = 500


def _files(d: pathlib.Path) -> dict[str, str]:
    """Write the attack inputs into ``d``; return their paths by name."""
    import numpy as np
    import scipy.io

    (d / "a-file").write_text("keep me")
    (d / "big.toml").write_text("# " + "x" * (16 * 2**20) + "\n")
    (d / "deep.toml").write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    (d / "del.toml").write_text('[case]\nname = "a\x7fb"\n', encoding="utf-8")
    (d / "latin1.toml").write_bytes(b'[case]\nname = "caf\xe9"\n')
    (d / "grid.toml").write_text(
        '[axes]\nmotor.torque = { start = "50 N m", stop = "150 N m", num = 1000000 }\n'
        'load.speed = { start = "80 rad/s", stop = "150 rad/s", num = 1000000 }\n')
    t = np.arange(1000) / 1000.0
    scipy.io.savemat(d / "short_tach.mat", {"accel": np.sin(2 * np.pi * 50 * t),
                                            "tach": (np.sin(2 * np.pi * 5 * t) > 0)[:900] * 1.0,
                                            "fs": 1000.0})
    return {"dir": str(d), **{k: str(d / k) for k in ("a-file", "big.toml", "deep.toml", "del.toml",
                                     "latin1.toml", "grid.toml", "short_tach.mat")}}


#: (name, argv builder, test that asserts the message)
ATTACKS = [
    ("simulate --out an existing file", lambda f: ["simulate", "--out", f["a-file"]],
     "tests/cli/test_user_errors.py"),
    ("run --out an existing file", lambda f: ["run", "--out", f["a-file"]],
     "tests/cli/test_user_errors.py"),
    ("stiffness --out an existing file", lambda f: ["stiffness", "--out", f["a-file"]],
     "tests/cli/test_user_errors.py"),
    ("simulate --out below a file (unwritable)",
     lambda f: ["simulate", "--out", f["a-file"] + "/o.nc"], "tests/cli/test_user_errors.py"),
    ("settle_time = 1e6 s", lambda f: ["simulate", "--set", "simulation.settle_time=1e6 s",
                                       "--out", f["dir"] + "/o1.nc"],
     "tests/cli/test_user_errors.py"),
    ("dt = 1e-12 s, decimation 1e6",
     lambda f: ["simulate", "--set", "simulation.dt=1e-12 s", "--set",
                "simulation.decimation=1000000", "--out", f["dir"] + "/o2.nc"],
     "tests/cli/test_user_errors.py"),
    ("sweep grid 1e6 x 1e6", lambda f: ["sweep", f["grid.toml"], "--out",
                                        f["dir"] + "/store.zarr"],
     "tests/sweep/test_spec.py"),
    ("config validate /dev/zero", lambda f: ["config", "validate", "/dev/zero"],
     "tests/config/test_limits.py"),
    ("16 MB case file", lambda f: ["config", "validate", f["big.toml"]],
     "tests/config/test_limits.py"),
    ("100k-deep array", lambda f: ["config", "validate", f["deep.toml"]],
     "tests/config/test_limits.py"),
    ("pair.module = 1e300", lambda f: ["simulate", "--out", "o.nc", "--set", "pair.module=1e300"],
     "tests/config/test_units.py"),
    ("100,000-digit number", lambda f: ["simulate", "--out", "o.nc", "--set",
                                        "pinion.teeth=" + "7" * 100_000],
     "tests/config/test_units.py"),
    ("unit bomb 10**10**10 mm", lambda f: ["simulate", "--out", "o.nc", "--set",
                                           'pair.module="10**10**10 mm"'],
     "tests/config/test_units.py"),
    ("crack.angle = 20 percent", lambda f: ["simulate", "--out", "o.nc", "--set",
                                           "crack.angle=20 percent"],
     "tests/config/test_units.py"),
    ("DEL character in a name", lambda f: ["config", "validate", f["del.toml"]],
     "tests/config/test_writer.py"),
    ("non-UTF-8 case file", lambda f: ["config", "validate", f["latin1.toml"]],
     "tests/config/test_limits.py"),
    (".mat signal and tach of different length",
     lambda f: ["diagnose", f["short_tach.mat"], "--signal", "accel", "--tach", "tach",
                "--out", f["dir"] + "/diag"], "tests/diagnostics/test_mat_reader.py"),
]


def _attack(argv: list[str], env: dict[str, str], cwd: str) -> tuple[float, int, list[str]]:
    t0 = time.perf_counter()
    r = subprocess.run(GEARDYN + argv, capture_output=True, text=True, env=env, cwd=cwd,
                       timeout=60)
    dt = time.perf_counter() - t0
    lines = [ln for ln in (r.stderr + r.stdout).splitlines() if ln.strip()]
    if "Traceback" in r.stderr:
        lines.append("Traceback")
    return dt, r.returncode, lines


def run(quick: bool = False) -> list[Row]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        files = _files(d)
        env = {**os.environ, "GEARDYN_CACHE_DIR": str(d / "cache"), "COLUMNS": "200"}
        base = min(_attack(["--version"], env, tmp)[0] for _ in range(3))
        for name, argv, _test in ATTACKS:
            dt, code, lines = _attack(argv(files), env, tmp)
            shape_ok = code == 2 and len(lines) == 1 and len(lines[0]) < MAX_CHARS
            rows.append(Row(name=f"attack: {name} (exit {code}, {len(lines)} line(s), "
                                 f"{max((len(x) for x in lines), default=0)} chars)",
                            value=dt, unit="s", baseline="geardyn --version",
                            baseline_value=base, target=f"< {LIMIT_S:g} s, exit 2, 1 line",
                            met=shape_ok and dt < LIMIT_S))
    return rows


if __name__ == "__main__":
    for r in run():
        print(f"{r.value:6.2f} s  {'ok ' if r.met else 'NO '} {r.name}")

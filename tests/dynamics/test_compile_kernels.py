"""``compile_kernels`` compiles what every simulation and diagnosis uses (issue 16: the
kernel's compiler process of a first ``geardyn run``).

It runs the steps of a 2 ms simulation of a constant-stiffness table map, then a TSA of a
synthetic signal. A fresh process that then simulates the paper's case on its PEM map (models
I, I-static and II) and a case with tooth errors, tip relief and runout, diagnoses a record as
``geardyn run`` does and averages a signal by tachometer pulses as its measurement stage does
must load every kernel function from numba's cache and compile none: a signature the
compiling calls missed (another array layout, a read-only array, a literal argument) would make
every first run compile the kernel a second time, about 7 s (the TSA's kernel 0.45 s).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

COMPILE = textwrap.dedent("""
    import sys
    from geardyn.dynamics.warm import compile_kernels
    compile_kernels()
    print(sorted(m for m in ("xarray", "geardyn.stiffness.pem") if m in sys.modules))
""")

SIMULATE = textwrap.dedent("""
    import collections
    from numba.core import event
    compiled = collections.Counter()

    class Listener(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            f = ev.data["dispatcher"].py_func
            compiled[f"{f.__module__}:{f.__qualname__}"] += 1

    event.register("numba:compile", Listener())
    import numpy as np
    import geardyn
    from geardyn.dynamics.newmark import simulate

    short = {"stiffness.method": "pem", "stiffness.centre_distances": 5,
             "simulation.record_time": "0.003 s", "simulation.settle_time": "0 s"}
    case = geardyn.paper_case().with_overrides(short)
    errors = case.with_overrides({"modifications.pinion.grade": 6,
                                  "modifications.pinion.tip_relief": "15 um",
                                  "modifications.pinion.runout": "10 um",
                                  "modifications.gear.grade": 6})
    steps = 0
    for c in (case, errors):
        for model in ("I", "I-static", "II"):
            ds = simulate(c, model=model)
            assert np.isfinite(ds["transmission_error"].values).all()
            steps += ds.sizes["time"]
    # the diagnosis of a record, with the inputs geardyn run gives it (two revolutions)
    from geardyn.diagnostics import diagnose
    from geardyn.diagnostics.tsa import tsa

    ds = simulate(case.with_overrides({"simulation.record_time": "0.15 s"}), model="II")
    d = diagnose(signals={k: ds[k].values for k in ("v_yg", "omega_p", "transmission_error")},
                 teeth=case.pinion.teeth, angle=ds["theta_p"].values, time=ds["time"].values,
                 samples_per_rev=256)
    assert np.isfinite(d.signals["v_yg"].tsa.average).all()
    # the measurement stage's TSA: one signal, by tachometer pulse times
    t = ds["time"].values
    theta = ds["theta_p"].values
    pulses = np.interp(np.arange(np.ceil(theta[0] / (2 * np.pi)),
                                 theta[-1] / (2 * np.pi)) * 2 * np.pi, theta, t)
    m = tsa(ds["v_yg"].values, tach_times=pulses, fs=1.0 / (t[1] - t[0]), samples_per_rev=256)
    assert np.isfinite(m.average).all()
    kernel = sorted(k for k in compiled if k.startswith(
        ("geardyn.dynamics", "geardyn.stiffness.map", "geardyn.stiffness._lookup_kernels",
         "geardyn.diagnostics")))
    print(steps > 0, kernel)
""")


@pytest.mark.slow
def test_compile_kernels_compiles_what_a_simulation_uses(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"),
               GEARDYN_CACHE_DIR=str(tmp_path / "cache"))
    first = subprocess.run([sys.executable, "-c", COMPILE], env=env, text=True,
                           capture_output=True, timeout=600)
    assert first.returncode == 0, first.stderr
    # the compiler process imports neither xarray nor the PEM code
    assert first.stdout.split("\n")[0] == "[]", first.stdout
    then = subprocess.run([sys.executable, "-c", SIMULATE], env=env, text=True,
                          capture_output=True, timeout=600)
    assert then.returncode == 0, then.stderr
    assert then.stdout.strip() == "True []", then.stdout

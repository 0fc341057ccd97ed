"""Measurement benchmark: a 10 s, 50 kHz, two-channel (acceleration + tachometer) measurement of
the paper case from a cached stiffness map, against the bare simulation of the same case.

Rows (all measured in this run):

* ``geardyn.studies.measure.measure()`` end to end: model II simulation of the record plus the
  chain's lead-in and tail (about 0.08 s), bearing forces, transfer path, anti-alias filter,
  sampling, noise, 24-bit ADC and tachometer; target under 5 s; the baseline is
  ``simulate()`` of the same 10 s record, and the ratio shows what the measurement adds;
* the chain alone (``MeasurementChain.measure`` on the simulated arrays).

The stiffness map (PEM, the paper's crack) comes from geardyn's cache (built once before timing).
A third row names the machine (CPU model, cores) and reports the 1-minute load average over the
timed part (before and after), since the machine may be shared: the ratio to the bare simulation
is the figure that travels between machines.

Run: ``python benchmarks/run.py measure`` (``--quick`` for a 1 s record).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from _common import Row, best_time, machine
from _common import load_average as _load

ROOT = Path(__file__).resolve().parents[1]


def run(quick: bool) -> list[Row]:
    sys.path.insert(0, str(ROOT))
    import geardyn
    from geardyn.dynamics import DynamicModel, simulate
    from geardyn.measurement import bearing_forces
    from geardyn.stiffness import build_map
    from geardyn.studies.measure import measure

    record = 1.0 if quick else 10.0
    case = geardyn.paper_case(['stiffness.method="pem"', f"simulation.record_time={record}"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        smap = build_map(case, cracked=True)  # cached after the first run
    # warm up (numba compilation, imports)
    short = case.with_overrides({"simulation.record_time": 0.01, "simulation.settle_time": 0.0})
    measure(short, smap)
    repeat = 1 if quick else 2
    load0 = _load()
    t_sim = best_time(lambda: simulate(case, smap), repeat=repeat)
    holder = {}

    def go():
        holder["r"] = measure(case, smap)

    t_meas = best_time(go, repeat=repeat)
    r = holder["r"]
    ds, chain = r.simulation, r.chain
    dyn = DynamicModel.from_case(case, smap)
    forces = np.vstack([
        bearing_forces(ds["y_p"].values, ds["v_yp"].values, dyn.K0[1, 1], dyn.damping["q_yp"]),
        bearing_forces(ds["y_g"].values, ds["v_yg"].values, dyn.K0[3, 3], dyn.damping["q_yg"])])
    t_chain = best_time(lambda: chain.measure(ds["time"].values, forces, ds["theta_p"].values,
                                              ds["omega_p"].values, record_time=record),
                        repeat=3)
    n = r.record.sizes["time"]
    load1 = _load()
    target = 5.0 if not quick else 0.5
    return [
        Row(f"measure(): {record:g} s at 50 kHz, acc + tach ({n} samples), model II, "
            "from a cached PEM map", t_meas, "s", f"bare simulate() of {record:g} s (ratio = "
            "simulate / measure)", t_sim, f"< {target:g} s", t_meas < target),
        Row(f"measurement chain alone on {forces.shape[1]} simulated samples", t_chain, "s",
            "measure() end to end", t_meas, "", None),
        Row(f"machine: {machine()}; 1-min load average before the timing (baseline column) "
            "and after it", load1, "load", "before", load0, "", None),
    ]


if __name__ == "__main__":  # python benchmarks/bench_measure.py [--quick]
    for row in run(quick="--quick" in sys.argv):
        base = "" if row.baseline_value is None else \
            f"; {row.baseline}: {row.baseline_value:.4g} {row.unit}"
        ratio = "" if row.ratio is None or row.unit == "load" else f"; ratio {row.ratio:.3g}x"
        met = "" if row.met is None else f"; target {row.target}: {'met' if row.met else 'NOT met'}"
        print(f"{row.name}: {row.value:.4g} {row.unit}{base}{ratio}{met}")

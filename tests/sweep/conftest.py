"""Shared pieces of the sweep tests: small sweep files (the in-process Dask cluster,
``client``, is in ``tests/conftest.py``)."""

from __future__ import annotations

import textwrap

#: A sweep of the closed-form evaluator: 3 torques x 2 bore radii x 2 sampled speeds = 12 runs.
#: The 70 mm bore is larger than the root radius (61.5 mm): those runs fail in the geometry;
#: torques above the evaluator's limit fail as a "divergence".
OSC_SWEEP = textwrap.dedent("""
    name = "oscillator"
    seed = 11
    [axes]
    motor.torque = { start = "50 N m", stop = "150 N m", num = 3 }
    pinion.bore_radius = ["20 mm", "70 mm"]
    [link]
    gear.bore_radius = "pinion.bore_radius"
    [sample]
    method = "sobol"
    n = 2
    [sample.dimensions]
    load.speed = { low = "80 rad/s", high = "150 rad/s" }
    [execution]
    batch_size = 5
""")

"""Shared pieces of the sweep tests: an in-process Dask cluster and small sweep files."""

from __future__ import annotations

import textwrap

import pytest

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


@pytest.fixture(scope="module")
def client():
    """An in-process Dask cluster (threads): the same scheduler and task code paths as a
    process cluster, without the start-up time."""
    import dask
    from distributed import Client, LocalCluster

    # without the workers' stack sampling every 10 ms, as geardyn's own local cluster
    # (geardyn.studies.sweep.local_workers): no dashboard shows it
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                               dashboard_address=None)
    cl = Client(cluster)
    yield cl
    cl.close()
    cluster.close()

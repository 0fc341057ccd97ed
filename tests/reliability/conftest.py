"""Shared pieces of the reliability tier: an in-process Dask cluster, private cache folders."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def client():
    """An in-process Dask cluster (threads): the scheduler and task code paths of a process
    cluster, without the start-up time."""
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

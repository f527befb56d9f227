"""Fixtures of the studies' tests: a local Dask cluster (two worker processes), started once; one without workers."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def dask_cluster():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        yield cluster


@pytest.fixture
def workerless_dask_cluster():
    """A Dask cluster in this process with no worker (``cluster.scale(n)`` adds some: threads of this process)."""
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=0, threads_per_worker=1, processes=False, dashboard_address=None,
                                  scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster:  # any free port
        yield cluster

"""Fixtures of the studies' tests: a local Dask cluster (two worker processes), started once."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def dask_cluster():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        yield cluster

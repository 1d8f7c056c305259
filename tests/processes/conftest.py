"""A Dask cluster in this process for the executor tests: in-process workers on inproc://, nothing leaves the process."""

import pytest


@pytest.fixture(scope="module")
def dask_cluster():
    from distributed import LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address="127.0.0.1:0")
    yield cluster
    cluster.close()


@pytest.fixture(scope="module")
def dask_client(dask_cluster):
    from distributed import Client

    client = Client(dask_cluster)
    yield client
    client.close()

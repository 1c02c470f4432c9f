"""A Dask cluster for the time of one command: a ``LocalCluster`` of processes on 127.0.0.1
(``--workers N``) or a running scheduler's (``--scheduler tcp://HOST:PORT``, probed first:
screwkin.parallel.scheduler), closed at the end; and a map over its workers (what synthesis spreads
its search's runs with)."""

from __future__ import annotations

import contextlib
import logging
import uuid
import warnings

from ..errors import UsageError, one_line, quote
from .scheduler import probe_scheduler, scheduler_address

__all__ = ["dask_client", "dask_map"]


@contextlib.contextmanager
def dask_client(scheduler, workers, timeout):
    """(client, workers, where): the cluster of the scheduler at ``scheduler`` (a usage error when it
    cannot be reached or has no worker within ``timeout`` s), or a LocalCluster of ``workers`` processes
    of one thread on 127.0.0.1 (no dashboard); closed (the local cluster shut down) on leaving."""
    from distributed import Client, LocalCluster  # 0.4-0.9 s to import: only the commands that ask

    cluster = client = None
    try:
        if scheduler is not None:
            address = scheduler_address(scheduler)
            probe_scheduler(address, timeout)
            try:
                client = Client(address, timeout=timeout)
                client.wait_for_workers(1, timeout=timeout)
            except (OSError, TimeoutError) as exc:
                what = "has no worker" if client is not None else "cannot be reached"
                raise UsageError(f"the dask scheduler at {quote(address)} {what} within {timeout:g} s "
                                 f"({one_line(str(exc) or type(exc).__name__, 160)})") from None
            used, where = len(client.scheduler_info().get("workers", {})) or 1, address
        else:
            with warnings.catch_warnings():  # "Port 8787 is already in use": its HTTP routes then take another
                warnings.filterwarnings("ignore", message="Port .* is already in use")
                # processes on 127.0.0.1 only (the scheduler's HTTP routes too: no dashboard address given)
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                       dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster, timeout=timeout)
            used, where = workers, "local cluster"
        yield client, used, where
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()


def dask_map(client, name: str = "screwkin"):
    """map(function, items) -> list over the client's workers, one task an item, results in order."""
    def mapped(function, items):
        items = list(items)
        token = uuid.uuid4().hex[:12]
        futures = [client.submit(function, item, key=f"{name}-{token}-{k}", pure=False) for k, item in enumerate(items)]
        try:
            return client.gather(futures)
        finally:
            client.cancel([f for f in futures if not f.done()])

    return mapped

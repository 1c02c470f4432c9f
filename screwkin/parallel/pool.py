"""A Dask cluster for the time of one command: a ``LocalCluster`` of processes on 127.0.0.1
(``--workers N``) or a running scheduler's (``--scheduler tcp://HOST:PORT``, probed first:
screwkin.parallel.scheduler), closed at the end; and a map over its workers.  ``process_pool``: a map
over N local processes forked from a fork server, what ``synthesize --workers N`` spreads its search's
few long runs with (a Dask LocalCluster cost more than it saved there: issue 43, README's synthesize)."""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import uuid
import warnings
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import forkserver

from ..errors import UsageError, one_line, quote
from .scheduler import probe_scheduler, scheduler_address

__all__ = ["dask_client", "dask_map", "process_pool"]


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


@contextlib.contextmanager
def process_pool(workers: int, preload=()):
    """(map(function, items) -> list, how): ``workers`` local processes, each item a task taken by the
    next free process (runs of uneven length balance themselves), results in order; shut down on leaving.

    For a few long tasks (a synthesis search's 4 to 8 runs of seconds each) on the cores of one machine.
    A Dask LocalCluster for them cost more than the runs it spread: 3.8 to 9 s to start its scheduler,
    nannies and workers (each importing distributed, numpy and scipy again) and 1.5 to 2.4 s to close,
    and its event loops and heartbeats took 15-25 % of each worker's CPU beside the task (measured on the
    2-core development machine, 2026-12-06).  Here the processes are forked from a fork server
    (multiprocessing's "forkserver", where the platform has it, else "spawn") that imports ``preload``
    once: a worker starts in milliseconds, and no thread of this process is forked."""
    method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
    context = mp.get_context(method)
    if method == "forkserver" and preload:
        context.set_forkserver_preload(list(preload))
    try:
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            yield (lambda function, items: list(pool.map(function, items))), f"local processes ({method})"
    finally:
        if method == "forkserver":  # the server goes with the command (waited for: no process left behind)
            stop = getattr(forkserver._forkserver, "_stop", None)  # CPython's own (its tests stop it so)
            if stop is not None:
                stop()

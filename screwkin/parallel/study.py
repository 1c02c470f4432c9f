"""Studies run in parallel: the designs of a study (screwkin.analysis.design.study: one design's
metrics from its values alone) in chunks, on a ``LocalCluster`` of processes on 127.0.0.1 by
default, an existing dask.distributed cluster (``scheduler="tcp://..."``, probed first:
screwkin.parallel.scheduler), or in this process (``workers=0``).  Results come back in design
order whatever the workers, chunks or scheduler; a chunk that stalls past the designs' time
limits and a grace is given up, its designs failed rows that say why.
"""

from __future__ import annotations

import asyncio
from collections import Counter
import math
import os
import time
import uuid
from pathlib import Path

from ..analysis.design.study import (
    StudyResult,
    apply_requirements,
    check_pareto,
    designs,
    failed_row,
    metric_columns,
    requirements,
    study_task,
)
from ..files.study import StudySpec
from ..analysis.design.family import FAMILY_CHUNK, chunk_rows, eligible
from ..errors import UsageError, one_line
from ..files.study import read_study_spec, study_spec
from .pool import dask_client
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.present.progress import Progress

__all__ = ["run_study", "default_workers", "STALL_GRACE"]


#: Seconds a Dask cluster may go without finishing any chunk beyond what its designs' timeouts allow
#: (starting workers, importing screwkin, moving the rows) before the unfinished chunks are given up.
STALL_GRACE = 60.0


def default_workers() -> int:
    """Workers of the local cluster by default: the cores, at most 4."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(1, min(cores, 4))


def _chunks(items: list, size: int) -> list:
    return [items[i:i + size] for i in range(0, len(items), size)]


def run_study(spec: StudySpec | dict, scheduler: str | None = None, workers: int | None = None, progress: Progress | None = None,
              timeout: float = 10.0, base: str | Path | None=None) -> StudyResult:
    """Run a study: ``spec`` a StudySpec, a spec file's path, or a dict (its ``file``
    relative to ``base``, default the current folder).

    scheduler: address of a running dask.distributed scheduler (``tcp://host:port``);
               None: a LocalCluster of ``workers`` processes (default :func:`default_workers`)
               on 127.0.0.1, closed at the end; ``workers=0``: in this process, no Dask.
    progress:  callable(done, total, failed) called as chunks complete.
    timeout:   seconds to reach the scheduler and its first worker (UsageError after).
    """
    if isinstance(spec, dict):
        spec = study_spec(spec, "<dict>", Path(base) if base is not None else None)
    elif not isinstance(spec, StudySpec):
        spec = read_study_spec(spec)
    check_pareto(spec)
    requirements(spec)  # a column the study does not have is a usage error before any design runs
    if scheduler is not None and workers is not None:
        raise UsageError("--workers is for the local cluster; a scheduler's cluster has its own workers")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 0):
        raise UsageError(f"workers must be a whole number, 0 or more (0: in this process), got {workers!r}")
    if not timeout > 0:
        raise UsageError(f"the timeout must be positive, got {timeout!r}")
    task = study_task(spec)
    values = designs(spec)
    n_workers = default_workers() if workers is None and scheduler is None else (workers or 1)
    size = spec.chunk or max(1, min(64, math.ceil(len(values) / (4 * max(n_workers, 1)))))
    if not spec.chunk and eligible(task) is None:  # the family path: a chunk expanded once pays from tens of designs
        size = max(1, min(FAMILY_CHUNK, math.ceil(len(values) / (2 * max(n_workers, 1)))))
    chunks = _chunks(list(enumerate(values)), size)
    t0 = time.perf_counter()
    if progress:
        progress(0, len(values), 0)
    if scheduler is None and workers == 0:
        results, failed = [], 0
        for k, chunk in enumerate(chunks):
            results.append(chunk_rows(task, chunk))
            failed += sum(r["error"] is not None for r in results[-1])
            if progress:
                progress(sum(len(c) for c in chunks[:k + 1]), len(values), failed)
        where, used = "in process", 1
    else:
        results, used, where = _on_dask(task, chunks, len(values), scheduler, workers or n_workers, timeout,
                                        progress)
    rows = tuple(r for got in results for r in got)
    paths, path_notes = Counter(), Counter()
    for got in results:
        paths.update(getattr(got, "paths", {"design": len(got)}))
        path_notes.update(getattr(got, "notes", ()))
    rows, column, unmet = apply_requirements(spec, rows)
    columns = metric_columns(spec.metrics) + ((column,) if column else ())
    notes = []
    if spec.transmission_steps is not None and "transmission_angle" in spec.metrics:
        notes.append(f"transmission: {{steps: {spec.transmission_steps}}} is not used: the transmission angle's "
                     "extremes over the input's motion are located in closed form, not sampled")
    why = eligible(task)
    return StudyResult(spec, task.parameters, columns, rows, time.perf_counter() - t0, used, where, len(chunks),
                       {"unmet": unmet, "notes": notes, "paths": dict(paths), "path_notes": _merged(path_notes),
                        "family": why})


def _merged(notes: Counter) -> list:
    """The chunks' notes, the same reason counted once with its designs added up ("3 designs evaluated
    alone: why" from several chunks)."""
    out = Counter()
    for note, times in notes.items():
        head, sep, why = note.partition(" evaluated alone: ")
        count = head.split()[0]
        if sep and count.isdigit():
            out[why] += int(count) * times
        else:
            out[note] += 0
    return [f"{c} design{'s' if c != 1 else ''} evaluated alone: {why}" if c else why for why, c in out.most_common()]


def _on_dask(task, chunks: list, total: int, scheduler: str | None, workers: int, timeout: float, progress: Progress | None) -> tuple:
    """Run the chunks on a LocalCluster or the scheduler's cluster: (results per chunk,
    workers, where)."""
    from distributed import as_completed  # 0.4-0.9 s to import: only studies need it

    with dask_client(scheduler, workers, timeout) as (client, used, where):
        futures = []
        try:
            token = uuid.uuid4().hex[:12]
            futures = [client.submit(chunk_rows, task, chunk, key=f"screwkin-study-{token}-{k}", pure=False)
                       for k, chunk in enumerate(chunks)]
            results, futures = _collect(client, task, chunks, futures, total, progress, as_completed), []
            return results, used, where
        finally:
            if futures:  # interrupted: take the study's tasks off the cluster
                try:
                    client.cancel(futures)
                except Exception:  # noqa: BLE001, S110 - closing anyway
                    pass


def _collect(client, task, chunks: list, futures: list, total: int, progress: Progress | None, as_completed, grace: float = STALL_GRACE,
             poll: float = 0.05) -> list:
    """The rows of every chunk's future, in chunk order.  A chunk whose task failed as a whole
    (its worker died) is rows with that reason.  When no chunk finishes for the longest
    chunk's designs' timeouts plus ``grace`` seconds, the chunks still running are past their
    timeouts (a design stuck where its checks cannot see it): every unfinished chunk is
    cancelled and its rows say so -- the study ends, it never hangs."""
    index = {f.key: k for k, f in enumerate(futures)}
    results = [None] * len(chunks)
    done = failed = 0
    stall = max((len(c) for c in chunks), default=1) * task.timeout + grace
    ac = as_completed(futures)
    last = time.perf_counter()
    while done < total:
        batch = [(f, None) for f in ac.next_batch(block=False)]
        if not batch:
            if time.perf_counter() - last <= stall:
                time.sleep(poll)
                continue
            reason = (f"timed out: no part of the study finished for {stall:g} s (timeout {task.timeout:g} s per "
                      "design); this design's task was cancelled unfinished")
            unfinished = [f for f in futures if results[index[f.key]] is None]
            client.cancel(unfinished)
            batch = [(f, reason) for f in unfinished]
        last = time.perf_counter()
        for fut, reason in batch:
            k = index[fut.key]
            if results[k] is not None:
                continue
            if reason is None:
                try:
                    results[k] = fut.result()
                except (Exception, asyncio.CancelledError) as exc:  # noqa: BLE001 - the task failed as a whole
                    reason = (f"the task of designs {chunks[k][0][0]}-{chunks[k][-1][0]} failed on its worker: "
                              f"{type(exc).__name__}: {one_line(str(exc), 200)}")
            if reason is not None:
                results[k] = [failed_row(task, i, v, reason) for i, v in chunks[k]]
            done += len(chunks[k])
            failed += sum(r["error"] is not None for r in results[k])
            if progress:
                progress(done, total, failed)
    return results

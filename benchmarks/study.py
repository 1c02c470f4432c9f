"""Study throughput: designs per second of ``screwkin study`` on a LocalCluster of 1 and of
2 worker processes, in one run (the ratio is what to read: the machines are shared).

    python benchmarks/study.py [--designs 48] [--repeat 2]

Each cluster is started first and its workers warmed (screwkin imported, one design run),
so the time is the study's alone, from submitting the chunks to the last row; the clusters
alternate, ``repeat`` rounds, best of each.  The family: robots/fourbar.urdf.xacro over crank,
coupler and rocker lengths, metrics mobility, grashof and transmission_angle (181 configurations
solved and checked per design), some designs that cannot close among them.  The same study in
this process (no Dask) is the reference for the overhead.  Run by benchmarks/run.py too.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def family(designs: int) -> dict:
    """A grid of about ``designs`` four-bars (3 couplers x 2 rockers x the crank lengths)."""
    cranks = max(1, round(designs / 6))
    return {"file": str(ROOT / "robots" / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
            "parameters": {"crank": {"min": 0.015, "max": 0.095, "samples": cranks},
                           "coupler": {"values": [0.06, 0.125, 0.21]}, "rocker": {"values": [0.075, 0.14]}},
            "metrics": ["mobility", "grashof", "transmission_angle"], "input": "crank_joint"}


def study_throughput(designs: int = 48, repeat: int = 2):
    """{label: (designs, best seconds, failed designs)}: in this process, on 1 and on 2 workers,
    the three in alternation, ``repeat`` rounds."""
    from distributed import Client, LocalCluster

    from screwkin.parallel.study import run_study

    spec = family(designs)
    clusters = {}
    try:
        for n in (1, 2):
            with warnings.catch_warnings():  # the second cluster's HTTP routes cannot have port 8787 too
                warnings.filterwarnings("ignore", message="Port .* is already in use")
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                                       dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster)
            warm = dict(spec, parameters={"crank": {"values": [0.05]}, "coupler": 0.125, "rocker": 0.075})
            run_study(warm, scheduler=cluster.scheduler_address)  # a worker imports screwkin
            client.run(_import)  # and every other one
            clusters[n] = (cluster, client)
        runs = {"in process (no Dask)": lambda: run_study(spec, workers=0)}
        for n, (cluster, _) in clusters.items():
            runs[f"LocalCluster, {n} worker{'s' if n > 1 else ''}"] = \
                lambda address=cluster.scheduler_address: run_study(spec, scheduler=address)
        best = {k: (float("inf"), None) for k in runs}
        for _ in range(repeat):
            for k, f in runs.items():
                t = time.perf_counter()
                res = f()
                t = time.perf_counter() - t
                if t < best[k][0]:
                    best[k] = (t, res)
        tables = [r.rows for _, r in best.values()]
        assert all(t == tables[0] for t in tables), "the tables differ"
        return {k: (len(r.rows), t, len(r.failed)) for k, (t, r) in best.items()}
    finally:
        for cluster, client in reversed(list(clusters.values())):  # (each restores the log levels it found)
            client.close()
            cluster.close()


def _import():
    import screwkin.analysis.design.study  # noqa: F401


def report(designs: int = 48, repeat: int = 2) -> list:
    rows = study_throughput(designs, repeat)
    lines = [(f"### 5. Study throughput ({designs} four-bar designs: mobility, grashof, transmission_angle; "
              f"{os.cpu_count()} cores)"), "",
             "| where | designs | failed | time [s] | designs per second |", "|---|---|---|---|---|"]
    for label, (n, t, failed) in rows.items():
        lines.append(f"| {label} | {n} | {failed} | {t:.2f} | {n / t:.1f} |")
    here, one, two = rows.values()
    lines += ["", (f"Throughput, 2 workers / 1 worker: {one[1] / two[1]:.2f}; 1 worker / in process: "
                   f"{here[1] / one[1]:.2f} (what Dask costs); the same table from each.")]
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=48)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    print("\n".join(report(args.designs, args.repeat)))


if __name__ == "__main__":  # (a LocalCluster's spawned workers import this file as __mp_main__)
    main()

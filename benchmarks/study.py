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


def lhs_family(designs: int) -> dict:
    """Latin-hypercube draws of the four-bar family (crank 10-100 mm, coupler 50-200 mm, rocker 30-200 mm,
    ground 0.1 m): mobility, grashof, transmission_angle, the family path's kind of study."""
    return {"file": str(ROOT / "robots" / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
            "parameters": {"crank": {"min": 0.01, "max": 0.1}, "coupler": {"min": 0.05, "max": 0.2},
                           "rocker": {"min": 0.03, "max": 0.2}},
            "sampling": "lhs", "designs": designs, "seed": 1, "metrics": ["mobility", "grashof", "transmission_angle"],
            "input": "crank_joint", "output": "rocker"}


def family_scaling(designs: int = 10_000, workers=(1, 2, 4), repeat: int = 1, alone: int = 200) -> list:
    """The family path on LocalClusters of each number of workers (started and warmed first, measured from
    the chunks' submission), in this process, and the per-design path on ``alone`` designs for the ratio;
    the rows checked against each design evaluated alone (every 50th) in degrees."""
    import math

    from distributed import Client, LocalCluster

    from screwkin.analysis.design.study import evaluate_design, study_task
    from screwkin.files.study import study_spec
    from screwkin.parallel.study import run_study

    spec = lhs_family(designs)
    out = [f"### 6. A family of {designs:,} four-bars (lhs; mobility, grashof, transmission_angle; {os.cpu_count()} "
           f"cores, load average {os.getloadavg()[0]:.1f} at the start)", "",
           "| where | designs | family path / alone | failed | time [s] | designs per second |", "|---|---|---|---|---|---|"]
    t = time.perf_counter()
    here = run_study(spec, workers=0)
    t = time.perf_counter() - t
    paths = here.extra["paths"]
    out.append(f"| in process | {designs:,} | {paths.get('family', 0)} / {paths.get('design', 0)} | {len(here.failed)} | "
               f"{t:.2f} | {designs / t:.0f} |")
    for n in workers:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Port .* is already in use")
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
        try:
            run_study(dict(spec, designs=40), scheduler=cluster.scheduler_address)  # warm: imports, first chunk
            client.run(_import)
            best = math.inf
            for _ in range(repeat):
                t = time.perf_counter()
                res = run_study(spec, scheduler=cluster.scheduler_address)
                best = min(best, time.perf_counter() - t)
            assert res.rows == here.rows, "the tables differ"
            out.append(f"| LocalCluster, {n} worker{'s' if n > 1 else ''} | {designs:,} | "
                       f"{res.extra['paths'].get('family', 0)} / {res.extra['paths'].get('design', 0)} | "
                       f"{len(res.failed)} | {best:.2f} | {designs / best:.0f} |")
        finally:
            client.close()
            cluster.close()
    task = study_task(study_spec(lhs_family(alone)))
    from screwkin.analysis.design.study import designs as design_values

    vals = design_values(study_spec(lhs_family(alone)))
    t = time.perf_counter()
    rows = [evaluate_design(task, i, v) for i, v in enumerate(vals)]
    t = time.perf_counter() - t
    out.append(f"| each design alone (the per-design path), in process | {alone} | 0 / {alone} | "
               f"{sum(r['error'] is not None for r in rows)} | {t:.2f} | {alone / t:.0f} |")
    worst = 0.0
    for r in here.rows[::50]:
        own = evaluate_design(task, r["design"], tuple(r[p] for p in task.parameters))
        for c in ("transmission_angle_min", "transmission_angle_max", "transmission_deviation"):
            if r[c] is not None:
                worst = max(worst, math.degrees(abs(r[c] - own[c])))
    out += ["", f"Rows of the family path against each design evaluated alone (every 50th): largest difference "
                f"{worst:.2g} deg in the transmission columns; the same table, value for value, from every cluster."]
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=48)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--family", type=int, default=0, help="designs of the family-path benchmark (0: not run)")
    ap.add_argument("--workers", default="1,2,4", help="the family benchmark's clusters")
    args = ap.parse_args()
    if args.family:
        print("\n".join(family_scaling(args.family, tuple(int(w) for w in args.workers.split(",")), args.repeat)))
        return
    print("\n".join(report(args.designs, args.repeat)))


if __name__ == "__main__":  # (a LocalCluster's spawned workers import this file as __mp_main__)
    main()

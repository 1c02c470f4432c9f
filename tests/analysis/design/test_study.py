"""Design-space studies (screwkin study): the four-bar family over its link lengths, on a
local Dask cluster and on a scheduler and workers started here as separate processes
(loopback only); every Grashof class checked against the closed-form inequality, failing
designs kept as rows with their reason, the same table whatever runs it, and bad specs as
one-line usage errors."""

import dataclasses
import io
import itertools
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import ROBOTS, no_hang

import screwkin
import screwkin.analysis.design.study as st
from screwkin.analysis.design.family import chunk_rows
from screwkin.analysis.design.study import (
    _GRASHOF,
    StudyResult,
    design_args,
    designs,
    pareto_front,
    run_chunk,
    study_task,
)
from screwkin.cli import main
from screwkin.parallel.study import _collect, run_study
from screwkin.files.study import study_spec
from screwkin.files.xacro import expand
from screwkin.present.study import study_csv, study_text
from screwkin.present.progress import Progress

ROOT = Path(__file__).resolve().parents[3]
GROUND = 0.1
CRANKS, COUPLERS, ROCKERS = [0.021, 0.047, 0.093, 0.152], [0.052, 0.117, 0.198], [0.032, 0.081, 0.187]
FAMILY = {
    "file": str(ROBOTS / "fourbar.urdf.xacro"),
    "args": {"ground": GROUND},
    "parameters": {"crank": {"values": CRANKS}, "coupler": {"values": COUPLERS}, "rocker": {"values": ROCKERS}},
    "metrics": ["mobility", "grashof"],
    "input": "crank_joint",
}


def expected_class(g, a, b, c):
    """Grashof's inequality on the lengths, and which link is shortest."""
    lengths = {"ground": g, "input": a, "coupler": b, "output": c}
    s, l = min(lengths.values()), max(lengths.values())
    p_q = sum(lengths.values()) - s - l
    if abs(s + l - p_q) < 1e-9 * l:
        return "change-point"
    if s + l > p_q:
        return "non-Grashof"
    return {"input": "crank-rocker", "ground": "double-crank", "coupler": "double-rocker",
            "output": "rocker-crank"}[min(lengths, key=lengths.get)]


def closes(g, a, b, c):
    """B D (crank end to rocker pivot) ranges over [|g - a|, g + a] and must lie in [|b - c|, b + c]."""
    return max(abs(b - c), abs(g - a)) <= min(b + c, g + a)


@pytest.fixture(scope="module")
def local():
    """The family on a LocalCluster of 2 worker processes."""
    return run_study(FAMILY, workers=2)


def test_grashof_classes_match_the_closed_form(local):
    rows = local.rows
    assert len(rows) == 36 and [r["design"] for r in rows] == list(range(36))
    assert [(r["crank"], r["coupler"], r["rocker"]) for r in rows] == list(itertools.product(CRANKS, COUPLERS,
                                                                                              ROCKERS))
    seen = set()
    for r in rows:
        g, a, b, c = GROUND, r["crank"], r["coupler"], r["rocker"]
        if not closes(g, a, b, c):
            assert r["error"] is not None and "cannot assemble" in r["error"], r
            assert r["grashof"] is None and r["mobility"] is None
            continue
        assert r["error"] is None, r
        assert r["grashof"] == expected_class(g, a, b, c), r
        lengths = sorted((g, a, b, c))
        assert r["grashof_margin"] == pytest.approx(lengths[1] + lengths[2] - lengths[0] - lengths[3], abs=1e-12)
        assert (r["mobility"], r["mobility_count"], r["motion_space"], r["idle_dofs"]) == (1, 1, "planar", 0)
        seen.add(r["grashof"])
    assert seen == {"crank-rocker", "double-crank", "double-rocker", "rocker-crank", "non-Grashof"}
    assert len(local.failed) == 3
    assert local.workers == 2 and local.scheduler == "local cluster"


def _wait_for(path, proc, timeout=60):
    t = time.perf_counter()
    while time.perf_counter() - t < timeout:
        if path.exists() and path.stat().st_size:
            return json.loads(path.read_text())
        if proc.poll() is not None:
            raise RuntimeError(f"the scheduler exited: {proc.stderr.read()[-2000:]}")
        time.sleep(0.1)
    raise TimeoutError("no scheduler file")


def test_a_separate_scheduler_and_workers_give_the_same_table(local, tmp_path):
    """dask scheduler + 2 dask workers as processes of their own, on 127.0.0.1 only."""
    env = dict(os.environ, PYTHONPATH=str(ROOT),  # the workers import this checkout's screwkin
               OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")  # as a nanny sets them
    sched_file = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(sched_file)], env=env, cwd=tmp_path, stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True))
        address = _wait_for(sched_file, procs[0])["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "dask", "worker", address, "--host", "127.0.0.1", "--no-nanny",
                 "--nthreads", "1", "--no-dashboard"], env=env, cwd=tmp_path, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL))
        import distributed

        with distributed.Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
        remote = run_study(FAMILY, scheduler=address, timeout=30)
    finally:
        for p in reversed(procs):  # workers, then the scheduler they report to (no nanny: one process each)
            p.terminate()
            try:
                p.wait(timeout=3)
            except subprocess.TimeoutExpired:  # a graceful close that waits on its peers: no need here
                p.kill()
                p.wait()
    assert remote.scheduler == address and remote.workers == 2
    assert remote.rows == local.rows  # the same values, to the last bit
    assert study_csv(remote) == study_csv(local)


def test_in_process_gives_the_same_rows(local):
    """A chunk run here (no Dask) gives the rows the local cluster's workers gave (the family path's
    rows do not depend on the chunk a design falls in); each design evaluated alone gives them to
    round-off."""
    spec = study_spec(FAMILY)
    chunk = [(i, v) for i, v in enumerate(designs(spec)) if i in (0, 3, 4, 35)]  # 0 does not close
    assert chunk_rows(study_task(spec), chunk) == [local.rows[i] for i, _ in chunk]
    for alone, r in zip(run_chunk(study_task(spec), chunk), [local.rows[i] for i, _ in chunk]):
        assert alone.keys() == r.keys() - {"meets_requirements"}
        for k, v in alone.items():
            assert v == pytest.approx(r[k], rel=1e-12, abs=1e-15) if isinstance(v, float) else v == r[k], k


def test_failing_designs_are_rows_with_their_reason():
    spec = dict(FAMILY, parameters={"crank": {"values": [0.0, 0.04, -0.01]}, "ground": {"values": [0.1, 0.5]}},
                args={}, metrics=["mobility", "grashof", "transmission_angle"], transmission={"steps": 12})
    res = run_study(spec, workers=0)
    by = {(r["crank"], r["ground"]): r for r in res.rows}
    assert len(res.rows) == 6
    assert "division by zero" in by[(0.0, 0.1)]["error"]  # the xacro file's own arithmetic
    assert "not a plausible value" in by[(-0.01, 0.1)]["error"]  # a negative length
    assert "cannot assemble" in by[(0.04, 0.5)]["error"]  # 0.5 > 0.04 + 0.12 + 0.08: the loop cannot close
    ok = by[(0.04, 0.1)]
    assert ok["error"] is None and ok["grashof"] == "crank-rocker"
    for r in res.failed:
        assert all(r[c] is None for c in res.columns)
        assert "\n" not in r["error"] and not r["error"].startswith(str(ROBOTS))
    table = res.table
    assert table["error"][2] is None and table["design"] == list(range(6))


def test_not_a_fourbar_is_an_error_row():
    spec = {"file": str(ROBOTS / "delta.urdf.xacro"), "parameters": {"rod": {"values": [0.4, 0.1]}},
            "metrics": ["mobility", "grashof"], "input": "arm1"}
    res = run_study(spec, workers=0)
    assert "not a planar four-bar" in res.rows[0]["error"]
    assert "math domain error" in res.rows[1]["error"]  # rods too short to reach the platform


def mu_range(g, a, b, c):
    """Transmission angles at the ends of the reachable B D range (mu grows with B D)."""
    lo, hi = max(abs(b - c), abs(g - a)), min(b + c, g + a)

    def mu(d):
        return math.degrees(math.acos(max(-1.0, min(1.0, (b * b + c * c - d * d) / (2 * b * c)))))

    return mu(lo), mu(hi)


def test_transmission_angles_match_the_closed_form():
    spec = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
            "parameters": {"crank": {"values": [0.04, 0.05]}, "coupler": {"values": [0.12, 0.11]},
                           "rocker": {"values": [0.08, 0.19]}},
            "metrics": ["transmission_angle"], "transmission": {"steps": 360}}
    res = run_study(spec, workers=0)
    for r in res.rows:
        assert r["error"] is None, r
        lo, hi = mu_range(0.1, r["crank"], r["coupler"], r["rocker"])
        full_turn = expected_class(0.1, r["crank"], r["coupler"], r["rocker"]) == "crank-rocker"
        # located in closed form, not sampled: the extremes to round-off (an input that rocks ends at its
        # limit positions, where mu is 0 or 180 deg exactly)
        # (acos near 1 halves the digits: the reference's own round-off at a limit is up to 1e-6 deg)
        tol = 1e-9 if full_turn else 1e-5
        assert math.degrees(r["transmission_angle_min"]) == pytest.approx(lo, abs=tol), r
        assert math.degrees(r["transmission_angle_max"]) == pytest.approx(hi, abs=tol), r
        if not full_turn:  # its ends are limit positions: the output dyad folded (0) or stretched (180 deg)
            assert r["transmission_angle_min"] == 0.0 or r["transmission_angle_max"] == math.pi, r
        assert r["input_turns"] == full_turn and r["dead_points"] == (0 if full_turn else 2), r
        assert r["transmission_deviation"] == pytest.approx(max(math.pi / 2 - r["transmission_angle_min"],
                                                                r["transmission_angle_max"] - math.pi / 2), abs=1e-15)


# ------------------------------------------------------------------ designs and the front
def test_sampling_is_seeded_and_in_range():
    base = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "metrics": ["mobility"],
            "parameters": {"crank": {"min": "20mm", "max": "60mm"}, "coupler": {"values": [0.1, 0.12, 0.14]}}}
    for sampling in ("random", "lhs"):
        spec = study_spec(dict(base, sampling=sampling, designs=12, seed=3))
        d = designs(spec)
        assert d == designs(spec) and len(d) == 12
        assert all(0.02 <= a <= 0.06 and b in (0.1, 0.12, 0.14) for a, b in d)
        assert d != designs(study_spec(dict(base, sampling=sampling, designs=12, seed=4)))
    lhs = [a for a, _ in designs(study_spec(dict(base, sampling="lhs", designs=8)))]
    assert sorted(int((a - 0.02) / 0.005) for a in lhs) == list(range(8))  # one in each eighth of the range
    grid = study_spec(dict(base, parameters={"crank": {"min": "20mm", "max": "60mm", "samples": 3}}))
    assert designs(grid) == [(0.02,), (0.04,), (0.06,)]


def test_pareto_front():
    spec = study_spec({"file": str(ROBOTS / "fourbar.urdf.xacro"), "metrics": ["transmission_angle"],
                       "parameters": {"crank": {"values": [1, 2, 3, 4, 5]}},
                       "pareto": {"maximize": ["transmission_angle_min_deg"], "minimize": ["transmission_angle_max"]}})
    pts = [(0.5, 2.0), (0.6, 2.5), (0.4, 1.5), (0.3, 2.0), (None, None)]
    rows = tuple({"design": k, "crank": k + 1, "transmission_angle_min": a, "transmission_angle_max": b,
                  "error": None if a is not None else "x"} for k, (a, b) in enumerate(pts))
    res = StudyResult(spec, ("crank",), ("transmission_angle_min", "transmission_angle_max"), rows, 0.0, 1, "x")
    assert pareto_front(res) == [2, 0, 1]  # (0.3, 2.0) is beaten by (0.5, 2.0); ordered by the first column


def test_the_shipped_example_recommends_only_linkages_that_work():
    """examples/fourbar_study.yaml: design 4 (crank 20 mm, coupler 160 mm, rocker 75 mm) is a non-Grashof
    triple rocker whose crank rocks between two limit positions where mu = 0 (its dead points); it, the
    other triple rockers and the change point (design 20: mu = 0 once a turn) are marked and left off
    the Pareto front, which holds crank-rockers only; the transmission deviation is max(90 - mu_min,
    mu_max - 90) of the located range."""
    res = run_study(ROOT / "examples" / "fourbar_study.yaml", workers=0)
    rows = res.rows
    assert rows[4]["grashof"] == "non-Grashof" and rows[4]["dead_points"] == 2 and rows[4]["input_turns"] is False
    assert rows[4]["transmission_angle_min"] == 0.0 and rows[4]["meets_requirements"] is False
    assert rows[20]["grashof"] == "change-point" and rows[20]["input_turns"] and rows[20]["dead_points"] == 1
    unmet = {r["design"] for r in rows if r["meets_requirements"] is False}
    assert unmet == {r["design"] for r in rows if r["grashof"] in ("non-Grashof", "change-point")} and 4 in unmet
    front = pareto_front(res)
    assert front and all(rows[k]["grashof"] == "crank-rocker" and rows[k]["dead_points"] == 0 for k in front)
    for r in rows:
        assert r["transmission_deviation"] == max(math.pi / 2 - r["transmission_angle_min"],
                                                  r["transmission_angle_max"] - math.pi / 2)
    text = study_text(res)
    assert "requirements: input_turns = true; dead_points = 0: 17 of 24 analysed designs meet them" in text
    assert "design 4: input_turns = true (has false); dead_points = 0 (has 2)" in text


def test_requirements_default_none_and_bounds():
    """No require with transmission_angle: dead_points = 0 is required, said so; require: {} requires
    nothing; a bound on a _deg column takes degrees, one with a unit SI."""
    base = dict(SMALL, parameters={"crank": {"values": [0.02, 0.05]}, "coupler": {"values": [0.125]},
                                   "rocker": {"values": [0.075]}}, pareto=None, transmission=None)
    res = run_study(base, workers=0)  # design 1 is a change point (one dead point)
    assert [r["meets_requirements"] for r in res.rows] == [True, False]
    assert "(the default of transmission_angle" in study_text(res) and not res.extra["notes"]
    free = run_study(dict(base, require={}), workers=0)
    assert "meets_requirements" not in free.columns and "requirements:" not in study_text(free)
    dev = math.degrees(res.rows[0]["transmission_deviation"])
    for bound in (dev - 1e-6, f"{dev - 1e-6}deg", math.radians(dev - 1e-6)):
        name = "transmission_deviation" if isinstance(bound, float) and bound < 2 else "transmission_deviation_deg"
        r = run_study(dict(base, require={name: {"max": bound}}), workers=0)
        assert r.rows[0]["meets_requirements"] is False, bound
        r = run_study(dict(base, require={name: {"min": bound}}), workers=0)
        assert r.rows[0]["meets_requirements"] is True, bound
    old = run_study(dict(base, transmission={"steps": 24}), workers=0)  # an earlier spec: the steps are said unused
    assert "not used" in old.extra["notes"][0] and "note: transmission: {steps: 24} is not used" in study_text(old)


def test_python_api():
    res = screwkin.study({"file": "fourbar.urdf.xacro", "parameters": {"crank": {"values": [0.03, 0.04]}},
                          "metrics": ["grashof"]}, workers=0, base=ROBOTS)
    assert isinstance(res, screwkin.StudyResult)
    assert res.table["grashof"] == ["crank-rocker", "crank-rocker"]
    assert res.columns == ("linkage", "grashof", "grashof_margin")


def test_progress_bar_only_on_a_terminal():
    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty, plain = Tty(), io.StringIO()
    for stream in (tty, plain):
        p = Progress(stream)
        p(3, 10, 1)
        p(10, 10, 1)
        p.finish("study: done")
    assert "\rstudy [" in tty.getvalue() and "10/10 designs, 1 failed" in tty.getvalue()
    assert plain.getvalue() == "study: done\n"


# ------------------------------------------------------------------ the command line
def write_spec(tmp_path, data, name="study.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data) if not isinstance(data, str) else data)
    return str(path)


SMALL = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
         "parameters": {"crank": {"min": "20mm", "max": "40mm", "samples": 2}, "rocker": {"values": [0.08, 0.1]}},
         "metrics": ["mobility", "grashof", "transmission_angle"], "transmission": {"steps": 24}, "output": "rocker",
         "pareto": {"maximize": ["transmission_angle_min_deg", "grashof_margin"]}}


def test_cli_study(tmp_path, capsys):
    spec = write_spec(tmp_path, SMALL)
    out_csv, prefix = tmp_path / "r.csv", tmp_path / "fig"
    assert main(["study", spec, "--workers", "0", "-o", str(out_csv), "--plot", str(prefix)]) == 0
    cap = capsys.readouterr()
    assert "4 designs, 4 analysed, 0 failed" in cap.out and "Pareto front" in cap.out
    assert cap.err.count("\n") == 1 and cap.err.startswith("study: 4 designs in ")  # no bar: not a terminal
    text = out_csv.read_text().splitlines()
    assert text[0].split(",")[:3] == ["design", "crank", "rocker"]
    assert "transmission_angle_min_deg" in text[0] and "grashof_margin_m" in text[0]
    assert len(text) == 5
    assert (tmp_path / "fig-metrics.png").stat().st_size > 1000
    assert (tmp_path / "fig-pareto.png").stat().st_size > 1000
    assert main(["study", spec, "--workers", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["designs"] == 4 and d["rows"][0]["crank"] == 0.02 and "pareto" in d
    assert d["rows"][0]["transmission_angle_min"] < math.pi  # radians in JSON (SI), degrees in the CSV


def test_cli_all_designs_failing_is_exit_1(tmp_path, capsys):
    spec = write_spec(tmp_path, dict(SMALL, parameters={"crank": {"values": [0.0]}}, pareto=None))
    assert main(["study", spec, "--workers", "0"]) == 1
    assert "1 x xacro: float division by zero" in capsys.readouterr().out


BAD_SPECS = {
    "unknown_metric": (dict(SMALL, metrics=["mobility", "speed"]), "unknown metric 'speed'"),
    "missing_file": (dict(SMALL, file="nowhere.urdf.xacro"), "does not exist"),
    "bad_range": (dict(SMALL, parameters={"crank": {"min": 0.3, "max": 0.1, "samples": 3}}), "bad range"),
    "unknown_key": (dict(SMALL, sampler="grid"), "unknown key 'sampler'"),
    "unknown_parameter": (dict(SMALL, parameters={"crankk": {"values": [0.1]}}), "not an argument"),
    "bad_unit": (dict(SMALL, parameters={"crank": {"values": ["3 parsecs"]}}), "unknown unit"),
    "no_samples": (dict(SMALL, parameters={"crank": {"min": 0.1, "max": 0.2}}), "needs samples"),
    "random_without_designs": (dict(SMALL, sampling="random"), "needs designs"),
    "bad_sampling": (dict(SMALL, sampling="sobol"), "sampling must be one of"),
    "pareto_column": (dict(SMALL, pareto={"maximize": ["speed", "grashof_margin"]}), "not a column"),
    "workspace_without_output": ({k: v for k, v in dict(SMALL, metrics=["conditioning"]).items() if k != "output"},
                                 "need output"),
    "not_a_mapping": ("- a\n- b\n", "a study is a mapping"),
    "malformed": ("file: [unclosed\n", "malformed YAML"),
    "alias": ("a: &x [1]\nb: *x\n", "aliases"),
    "too_many": (dict(SMALL, parameters={"crank": {"min": 0.01, "max": 0.1, "samples": 1000},
                                         "rocker": {"min": 0.01, "max": 0.1, "samples": 1001}}), "at most"),
    "require_column": (dict(SMALL, require={"dead_point": 0}), "require: 'dead_point' is not a column"),
    "require_bounds": (dict(SMALL, require={"dead_points": {"most": 1}}), "bounds are min and/or max"),
    "require_text_bound": (dict(SMALL, require={"transmission_deviation_deg": {"max": "small"}}), "require"),
}


@pytest.mark.parametrize("case", sorted(BAD_SPECS))
def test_bad_specs_are_usage_errors(tmp_path, capsys, case):
    data, word = BAD_SPECS[case]
    spec = write_spec(tmp_path, data)
    assert main(["study", spec, "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"screwkin: error: {spec}: "), err
    assert word in err[0], err[0]


def test_cli_usage_errors(tmp_path, capsys):
    spec = write_spec(tmp_path, SMALL)
    cases = [
        (["study", str(tmp_path / "absent.yaml")], "no such file"),
        (["study", spec, "--scheduler", "127.0.0.1:8786"], "tcp://HOST:PORT"),
        (["study", spec, "--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers is for the local cluster"),
        (["study", spec, "--workers", "-1"], "between 0 and 64"),
        (["study", spec, "-o", str(tmp_path / "r.xlsx")], ".csv or .parquet"),
        (["study", spec, "-o", str(tmp_path / "no" / "r.csv")], "does not exist"),
        (["study", spec, "--pareto", "max:a"], "--pareto expects"),
    ]
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        cases.append((["study", spec, "-o", str(tmp_path / "r.parquet")], "needs pyarrow"))
    for argv, word in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and word in err[0], (argv, err)


def test_unreachable_scheduler_fails_fast(tmp_path, capsys):
    spec = write_spec(tmp_path, SMALL)
    with no_hang(15):  # a guard against a hang, not a speed measurement
        assert main(["study", spec, "--scheduler", "tcp://127.0.0.1:9", "--timeout", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot be reached" in err[0], err


def test_study_table_is_plain_numbers():
    res = run_study(dict(SMALL, pareto=None), workers=0)
    lines = study_csv(res).splitlines()
    k = lines[0].split(",").index("transmission_angle_max_deg")
    for line in lines[1:]:
        cells = line.split(",")
        assert float(cells[1]) in (0.02, 0.04)
        assert np.isfinite(float(cells[k]))
        assert cells[-2] in ("true", "false")  # meets_requirements, before error


# ------------------------------------------------------------------ traceable rows
def _json(capsys, argv):
    assert main(argv) == 0, argv
    return json.loads(capsys.readouterr().out)


def test_rows_equal_the_single_commands_on_the_expanded_file(local, tmp_path, capsys):
    """A study's row is what mobility and sweep say of that design: given --arg with the row's
    values, or run on the URDF the xacro file expands to with them."""
    task = study_task(study_spec(FAMILY))
    text = (ROBOTS / "fourbar.urdf.xacro").read_text()
    checked = 0
    for r in local.rows:
        if r["error"] is not None or r["design"] % 4:
            continue
        args = design_args(task, (r["crank"], r["coupler"], r["rocker"]))
        urdf = tmp_path / f"design{r['design']}.urdf"
        urdf.write_text(expand(ROBOTS / "fourbar.urdf.xacro", text, args))
        by_arg = [str(ROBOTS / "fourbar.urdf.xacro")] + [x for n, v in args.items() for x in ("--arg", f"{n}={v}")]
        for target in (by_arg, [str(urdf)]):
            m = _json(capsys, ["mobility", *target, "--json"])
            assert (m["mobility"], m["motion_space"], m["overconstraint"], m["idle_dofs"]) == \
                (r["mobility"], r["motion_space"], r["overconstraint"], r["idle_dofs"])
            s = _json(capsys, ["sweep", *target, "--input", "crank_joint", "--from", "0", "--to", "1turn",
                               "--steps", "72", "--json"])
            assert next(short for prefix, short in _GRASHOF if s["linkage"]["grashof"].startswith(prefix)) \
                == r["grashof"]
        checked += 1
    assert checked >= 5


def test_transmission_angles_are_those_of_sweep(capsys):
    """A crank-rocker's transmission range is what sweep --json locates for that --arg
    (linkage.transmission_range), and it holds every angle sweep samples along a turn, the sampled
    extremes within the grid's reach of it (720 steps of 0.5 deg: mu moves by at most 1e-3 deg
    off an extreme, where its slope is zero)."""
    spec = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "args": {"ground": 0.1},
            "parameters": {"crank": {"values": [0.035]}}, "metrics": ["transmission_angle"]}
    res = run_study(spec, workers=0)
    r = res.rows[0]
    assert not res.extra["notes"]  # no transmission steps given: nothing said about them
    s = _json(capsys, ["sweep", str(ROBOTS / "fourbar.urdf.xacro"), "--arg", "ground=0.1", "--arg", "crank=0.035",
                       "--input", "crank_joint", "--from", "0", "--to", "1turn", "--steps", "720", "--json"])
    tr = s["linkage"]["transmission_range"]
    # (the study's family path takes the lengths from the file's placements, sweep from the assembled
    # configuration: the same numbers to round-off)
    for key, col in (("min", "transmission_angle_min"), ("max", "transmission_angle_max"),
                     ("deviation", "transmission_deviation")):
        assert r[col] == pytest.approx(tr[key], rel=0, abs=1e-14), key
    assert (r["input_turns"], r["dead_points"]) == (tr["turns"], tr["dead_points"]) == (True, 0)
    mus = np.array(s["transmission_angles"])
    assert tr["min"] <= mus.min() <= tr["min"] + math.radians(1e-3)
    assert tr["max"] - math.radians(1e-3) <= mus.max() <= tr["max"]
    assert r["transmission_restarts"] == 0


def test_workspace_metrics_equal_screwkin_workspace(capsys):
    """The workspace columns of a Delta design are screwkin workspace's numbers for it, to the bit."""
    spec = {"file": str(ROBOTS / "delta.urdf.xacro"), "parameters": {"rod": {"values": [0.45, 0.1]}},
            "metrics": ["workspace_volume", "singularity_free_volume", "conditioning"], "output": "platform",
            "workspace": {"resolution": "60mm"}}
    res = run_study(spec, workers=0)
    r, bad = res.rows
    assert r["error"] is None and r["workspace_dimension"] == 3
    assert "math domain error" in bad["error"] and bad["workspace_volume"] is None
    w = _json(capsys, ["workspace", str(ROBOTS / "delta.urdf.xacro"), "--arg", "rod=0.45", "--output", "platform",
                       "--resolution", "60mm", "--json"])
    assert (r["workspace_volume"], r["singularity_free_volume"], r["conditioning_min"], r["conditioning_mean"]) == \
        (w["volume"], w["free_volume"], w["conditioning_min"], w["conditioning_mean"])
    assert r["workspace_truncated"] is w["truncated"] is False
    assert "grid of step 0.06 m" in study_text(res)


# ------------------------------------------------------------------ a study never hangs
def test_a_design_past_its_timeout_is_a_failed_row(monkeypatch):
    calls = []

    def slow(d):
        calls.append(d)
        time.sleep(30 if len(calls) == 2 else 0)  # the second design: interrupted by the alarm
        return {"linkage": "four-bar", "grashof": "x", "grashof_margin": 1.0}

    monkeypatch.setitem(st.METRICS, "grashof", slow)
    monkeypatch.setattr("screwkin.analysis.design.family.family_rows", lambda task, chunk: None)  # each design alone
    spec = {"file": str(ROBOTS / "fourbar.urdf.xacro"), "parameters": {"crank": {"values": [0.03, 0.04]}},
            "metrics": ["grashof"], "timeout": 1.5}
    t = time.perf_counter()
    res = run_study(spec, workers=0)
    assert time.perf_counter() - t < 10
    ok, late = res.rows
    assert ok["error"] is None and ok["grashof"] == "x"
    assert late["error"].startswith("timed out") and late["grashof"] is None and late["grashof_margin"] is None


def _stuck_chunk(task, chunk):
    time.sleep(4)
    return [{"design": i} for i, _ in chunk]


def test_a_stalled_cluster_gives_failed_rows_not_a_hang():
    """No chunk finishing within the designs' timeouts (plus a grace) ends the study: every
    unfinished chunk is cancelled and its rows are failures that say so."""
    import distributed  # (as above: only these tests start a cluster)

    task = dataclasses.replace(study_task(study_spec(FAMILY)), timeout=0.2)
    chunks = [[(0, (0.021, 0.052, 0.032))], [(1, (0.021, 0.052, 0.081))]]
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None) as client:
        futures = [client.submit(_stuck_chunk, task, c, pure=False) for c in chunks]
        t = time.perf_counter()
        results = _collect(client, task, chunks, futures, 2, None, distributed.as_completed, grace=0.5)
        assert time.perf_counter() - t < 3
    rows = [r for rs in results for r in rs]
    assert [r["design"] for r in rows] == [0, 1]
    assert all(r["error"].startswith("timed out") and r["grashof"] is None for r in rows)


def test_spec_timeout_and_workspace_resolution_are_checked(tmp_path, capsys):
    for data, word in ((dict(SMALL, timeout=0), "timeout must be"),
                       (dict(SMALL, metrics=["workspace_volume"]), "need workspace: {resolution: H}")):
        spec = write_spec(tmp_path, data)
        assert main(["study", spec, "--workers", "0"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and word in err[0], err

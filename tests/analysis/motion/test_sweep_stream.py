"""Sweeps computed and written in chunks (analysis.motion.stream, sweep --chunk, --csv/--parquet
over 100,000 steps) give the in-memory sweep's motion, row for row."""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import fourbar
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.stream import sweep_chunks
from screwkin.analysis.motion.sweep import sweep
from screwkin.cli import main


@pytest.fixture
def mech(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    return screwkin.load(p)


def joined(pieces):
    return {k: np.concatenate([getattr(p, k) for p in pieces]) for k in ("values", "q", "rates", "accelerations")}


def same_motion(model, a, b, tol=1e-12):
    """Values, rates, accelerations equal; q equal up to whole turns (pin.difference: each chunk
    starts from a configuration with its angles in (-pi, pi], as sweep's start)."""
    for k in ("values", "rates", "accelerations"):
        x, y = np.asarray(getattr(a, k)), np.asarray(b[k])
        assert x.shape == y.shape, k
        assert np.max(np.abs(x - y) / np.maximum(1.0, np.abs(y))) < tol, k
    assert a.q.shape == b["q"].shape
    assert max(np.max(np.abs(pin.difference(model, qa, qb))) for qa, qb in zip(a.q, b["q"])) < tol


def test_chunks_of_the_closed_form_are_the_whole_sweep(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    whole = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 3000)
    assert whole.method == "closed form"
    pieces = list(sweep_chunks(solver, "crank_joint", 0.0, 2 * np.pi, 3000, chunk=700))
    assert len(pieces) == 5 and [len(p.values) for p in pieces] == [701, 700, 700, 700, 200]
    assert all(p.method == "closed form" for p in pieces)
    same_motion(mech.model, whole, joined(pieces))
    # the grid: start + k h, continuous across the chunks' seams
    assert np.allclose(np.diff(joined(pieces)["values"]), 2 * np.pi / 3000, rtol=0, atol=1e-12)


def test_chunks_of_the_tracker_are_the_whole_sweep(mech):
    solver = PositionSolver(mech, ["crank_joint"])
    whole = sweep(solver, "crank_joint", 0.0, 1.0, 60, closed_form=False)
    pieces = list(sweep_chunks(solver, "crank_joint", 0.0, 1.0, 60, chunk=25, closed_form=False))
    assert [len(p.values) for p in pieces] == [26, 25, 10]
    same_motion(mech.model, whole, joined(pieces), tol=1e-9)  # the seams are re-closed: within the closure tolerance


def test_a_limit_position_ends_the_stream_where_the_sweep_stops(mech):
    solver = PositionSolver(mech, ["rocker_joint"])
    whole = sweep(solver, "rocker_joint", 0.0, -1.5, 150)
    assert whole.stopped_at is not None
    pieces = list(sweep_chunks(solver, "rocker_joint", 0.0, -1.5, 150, chunk=40))
    assert pieces[-1].stopped_at == pytest.approx(whole.stopped_at, abs=1e-9)
    assert pieces[-1].stop_reason == whole.stop_reason and len(pieces[-1].limits) == 1
    same_motion(mech.model, whole, joined(pieces))


def read_csv(path):
    lines = path.read_text().splitlines()
    return lines[0], np.array([[float(c) for c in line.split(",")] for line in lines[1:]])


def test_cli_streamed_csv_equals_the_in_memory_csv(mech, tmp_path, capsys):
    base = ["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "2500",
            "--point", "P=coupler:0.06,0.02"]
    memory, streamed = tmp_path / "m.csv", tmp_path / "s.csv"
    assert main(base + ["--csv", str(memory)]) == 0
    capsys.readouterr()
    assert main(base + ["--csv", str(streamed), "--chunk", "600"]) == 0
    out = capsys.readouterr().out
    assert "in 5 chunks of at most 600 steps (closed form): 2,501 rows written" in out
    (h1, a), (h2, b) = read_csv(memory), read_csv(streamed)
    assert h1 == h2 and "P x" in h1 and a.shape == b.shape == (2501, len(h1.split(",")))
    assert np.array_equal(a[:, 0], np.arange(2501))
    d = np.abs(a - b)
    d = np.minimum(d, np.abs(d - 2 * np.pi))  # an angle at +-pi (the crank at half a turn) may show as either
    # 12 significant digits in the file: a value on a rounding edge differs in its last digit
    assert np.max(d / np.maximum(1.0, np.abs(a))) < 2e-11


def test_cli_parquet_has_the_csv_columns(mech, tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    csv, par = tmp_path / "s.csv", tmp_path / "s.parquet"
    assert main(["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "50",
                 "--csv", str(csv), "--parquet", str(par), "--chunk", "20"]) == 0
    head, a = read_csv(csv)
    t = pq.read_table(par)
    assert t.column_names == head.split(",") and t.num_rows == 51
    b = np.column_stack([t.column(n).to_numpy() for n in t.column_names])
    assert np.max(np.abs(a - b) / np.maximum(1.0, np.abs(a))) < 1e-11  # (the CSV has 12 digits)


@pytest.mark.parametrize("extra,words", [
    ([], ["--steps", "100,000", "--csv or --parquet"]),
    (["--csv", "x.csv", "--json"], ["--json", "not available"]),
    (["--csv", "x.csv", "--turn"], ["--turn", "not available"]),
    (["--steps", "20000000", "--csv", "x.csv"], ["2,000,000"]),
])
def test_streamed_sweeps_refuse_what_they_cannot_do(mech, tmp_path, monkeypatch, capsys, extra, words):
    monkeypatch.chdir(tmp_path)
    argv = ["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "200000", *extra]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own refusal
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and all(w in err[0] for w in words), err
    assert not (tmp_path / "x.csv").exists()


# ---------------------------------------------------------------- batched continuation (issue 26 item 2)

def tight(path):
    """The robot with the closure solved to 1e-13: the tracker and the batched corrector then each
    land within 1e-13 of the same curve, so their answers can be compared to 1e-9 (at the default
    1e-10 the two differ by the solvers' stopping points: rates by ~1e-9, accelerations ~1e-7)."""
    from dataclasses import replace

    from conftest import ROBOTS
    from screwkin.tolerances import DEFAULT

    return screwkin.load(ROBOTS / path, tolerances=replace(DEFAULT, closure=1e-13))


def relative(a, b):
    return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(a)))) if np.size(a) else 0.0


def test_batched_bennett_is_the_tracker():
    mech = tight("bennett.urdf")
    solver = PositionSolver(mech, list(mech.actuated))
    tracker = sweep(solver, "joint1", 0.0, 2 * np.pi, 300, closed_form=False, batch=False)
    batched = sweep(solver, "joint1", 0.0, 2 * np.pi, 300)
    assert (tracker.method, batched.method, batched.notes) == ("tracker", "batched", ())
    assert batched.completed and len(batched.values) == len(tracker.values) == 301
    assert relative(tracker.values, batched.values) < 1e-12
    assert max(np.abs(pin.difference(mech.model, a, b)).max() for a, b in zip(tracker.q, batched.q)) < 1e-9
    assert relative(tracker.rates, batched.rates) < 1e-9
    assert relative(tracker.accelerations, batched.accelerations) < 1e-9


def test_batched_rssr_meets_its_limit_position_as_the_tracker_and_says_so():
    """The RSSR's crank stops at a limit position: the batched corrector fails next to it and hands
    that chunk to the tracker (a note), which locates the limit.  The coupler's spin about its own
    axis is idle (the balls' three angles are not determined by the input): compared are the input
    and the rocker, which are."""
    mech = tight("rssr.urdf")
    solver = PositionSolver(mech, list(mech.actuated))
    tracker = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 400, closed_form=False, batch=False)
    batched = sweep(solver, "crank_joint", 0.0, 2 * np.pi, 400)
    assert batched.method == "batched" and tracker.stopped_at is not None
    assert len(batched.notes) == 1 and "per-step tracker" in batched.notes[0]
    assert batched.stopped_at == pytest.approx(tracker.stopped_at, abs=1e-9)
    assert batched.stop_reason == tracker.stop_reason and len(batched.limits) == len(tracker.limits) == 1
    assert relative(tracker.values, batched.values) < 1e-12
    cols = [mech.coordinate_names.index(n) for n in ("crank_joint", "rocker_joint")]
    for what in ("q", "rates", "accelerations"):
        assert relative(getattr(tracker, what)[:, cols], getattr(batched, what)[:, cols]) < 1e-9, what


@pytest.mark.parametrize("robot", ["bennett.urdf", "rssr.urdf", "gough_stewart_6ups.urdf"])
def test_batched_rates_are_the_solvers_rates(robot):
    """motion_rates at a batched sweep's configurations: PositionSolver.rates and .accelerations of
    each configuration (minimum norm where the coupler spins idle)."""
    from conftest import ROBOTS
    from screwkin.analysis.motion.batch_sweep import batch_closure, motion_rates

    mech = screwkin.load(ROBOTS / robot)
    inputs = list(mech.actuated)
    solver = PositionSolver(mech, inputs)
    res = sweep(solver, inputs[0], 0.0, 0.05, 10, fixed={n: 0.0 for n in inputs[1:]}, rate=2.0)
    assert res.method == "batched"
    V, A = motion_rates(solver, batch_closure(mech), res.q, {inputs[0]: 2.0})
    for q, v, a in zip(res.q, V, A):
        K = mech.closure.jacobian(q)
        qd = solver.rates(q, K, {inputs[0]: 2.0})
        assert relative(qd, v) < 1e-10
        assert relative(solver.accelerations(q, K, qd, {}), a) < 1e-10


@pytest.mark.parametrize("robot", ["fourbar_crank_rocker.urdf", "slider_crank_offset.urdf", "bennett.urdf",
                                   "gough_stewart_6ups.urdf"])
def test_frame_motions_on_stacks_are_pinocchios(robot):
    """TreeKinematics.motions (what motion_along uses for a tree of 1-DOF joints) against Pinocchio's
    forwardKinematics a configuration at a time (links._frame_motions) at random joint positions,
    rates and accelerations: placements, velocities, classical accelerations of every frame."""
    from conftest import ROBOTS
    from screwkin.model.kernel.stacks import TreeKinematics
    from screwkin.analysis.motion.links import _frame_motions

    mech = screwkin.load(ROBOTS / robot)
    model = mech.model
    rng = np.random.default_rng(7)
    Q, V, A = rng.uniform(-3, 3, (50, model.nq)), rng.normal(size=(50, model.nv)), rng.normal(size=(50, model.nv))
    frames = list(range(model.nframes))
    ref = _frame_motions(model, model.createData(), frames, Q, V, A)
    ours = TreeKinematics(mech).motions(Q, V, A, frames)
    for name, a, b in zip(("R", "t", "velocity", "acceleration"), ref, ours):
        assert np.max(np.abs(a - b)) < 1e-12, name


def test_parquet_without_pyarrow_is_a_usage_error(mech, tmp_path, monkeypatch, capsys):
    import screwkin.present.streamout as streamout

    monkeypatch.setattr(streamout, "parquet_available", lambda: False)
    out = tmp_path / "s.parquet"
    code = main(["sweep", mech.path, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "5",
                 "--parquet", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "needs pyarrow" in err[0] and not out.exists()

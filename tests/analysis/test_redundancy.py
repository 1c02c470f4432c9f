"""Redundant constraints by name (analysis.redundancy): the statically indeterminate wrenches against
what screw theory says by hand, the rows a pivoted QR names against the rank of what is left, and the
suggested exactly constrained model against the Kutzbach count of its joints."""

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.linalg import null_space as scipy_null_space

import screwkin
from screwkin.analysis.redundancy import redundancy
from screwkin.cli import main
from screwkin.model.state import KinematicState
from screwkin.analysis.screws import cut_twists

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = ROOT / "robots"
MJCF = Path(__file__).resolve().parents[1] / "data" / "mjcf" / "fourbar.xml"


def loop_twists(mech, q):
    """Every joint twist of the (single) loop at q, (v at the world origin, w): the tree joints' WORLD
    Jacobian columns and the cut joint's own freedoms."""
    st = KinematicState(mech, q)
    cut = mech.cuts[0]
    J = st.frame_jacobian(cut.frame2, pin.ReferenceFrame.WORLD) - st.frame_jacobian(cut.frame1, pin.ReferenceFrame.WORLD)
    cols = [J[:, k] for k in range(mech.nv) if np.linalg.norm(J[:, k]) > 0]
    return np.array(cols + [t for _, t, _ in cut_twists(mech, cut, st)]).T


def reciprocal(w, t):
    """The work of a wrench (f, m about the origin) on a twist (v at the origin, w): f . v + m . w."""
    return w[:3] @ t[:3] + w[3:] @ t[3:]


def test_planar_fourbar_closed_by_a_revolute_carries_fz_mx_my():
    """A planar four-bar closed by a revolute B: every joint twist is a rotation about z through a point p
    of the plane, (-z x p, z) = (p_y, -p_x, 0, 0, 0, 1).  A wrench (f, m) about the origin is a self-stress
    of the loop when it does no work on every joint twist: f . v + m . w = f_x p_y - f_y p_x + m_z = 0 for the
    four joint points p, which (points not on one line) forces f_x = f_y = m_z = 0 and leaves f_z, m_x, m_y
    free: the redundant wrenches span {F_z, M_x, M_y}, 3 of the revolute's 5 rows (F_z at B has the moment
    B x z about the origin).  Checked: each reported wrench is reciprocal to every joint twist Pinocchio
    gives, and together with F_z at B, M_x, M_y they still span 3 dimensions."""
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    q = mech.generic_configurations()[1][0]
    r = redundancy(mech, q)
    assert r.count == 3 and len(r.joints) == 1
    j = r.joints[0]
    assert (j.joint, j.rows, j.count, j.why) == ("coupler_rocker", 5, 3, "planar")
    assert set(j.named) == {"force along the axis (z)", "moment about x", "moment about y"}
    assert j.words == "3 of its 5 rows, the force along the axis (z) and the moments about x and y"
    W = np.array(j.wrenches)
    T = loop_twists(mech, q)
    assert np.abs([[reciprocal(w, t) for t in T.T] for w in W]).max() < 1e-12
    B = np.array(j.at)
    expected = np.array([np.r_[0, 0, 1, np.cross(B, [0, 0, 1])], [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0]])
    both = np.vstack([W, expected])
    assert np.linalg.matrix_rank(both, 1e-9) == 3


def test_mjcf_connect_carries_only_fz():
    """The same four-bar as MuJoCo writes it, closed by a <connect> (a ball: 3 position rows).  The ball
    frees every rotation, so only forces remain: f with f_x p_y - f_y p_x = 0 for every joint point p
    (in-plane rotations) and, the ball turning about x and y too, no moment at its centre: F_z alone, 1 of
    its 3 rows -- "connect 'ground_pivot': 1 of its 3 rows, the force along z"."""
    mech = screwkin.load(MJCF)
    q = mech.generic_configurations()[1][0]
    r = redundancy(mech, q)
    assert r.count == 1
    j = r.joints[0]
    assert (j.what, j.joint, j.words, j.why) == ("connect", "ground_pivot", "1 of its 3 rows, the force along z", "planar")
    assert r.qr_redundant_rows == ("ground_pivot:pos2",)


@pytest.mark.parametrize("name", ["bennett.urdf", "sarrus.urdf", "watt_sixbar.urdf", "gear_train_idler.urdf"])
def test_redundant_rows_by_qr_against_the_rank_of_what_is_left(name):
    """A spatial check as Chrono does it: the pivoted QR of K^T puts rank(K) independent rows first; the rows
    it names as redundant are as many as the left null space's dimension (SciPy's SVD of K^T), and K without
    them keeps its rank with every row independent.  Each basis vector's wrenches are a self-stress:
    lambda^T K = 0 with lambda in the left null space SciPy finds."""
    mech = screwkin.load(ROBOTS / name)
    q = mech.generic_configurations()[1][0]
    K = mech.closure.jacobian(q)
    r = redundancy(mech, q)
    labels = mech.closure.row_labels()
    left = scipy_null_space(K.T, rcond=1e-9)
    assert r.count == left.shape[1] == len(r.qr_redundant_rows) == K.shape[0] - r.qr_rank
    kept = [i for i, lab in enumerate(labels) if lab not in r.qr_redundant_rows]
    assert np.linalg.matrix_rank(K[kept], 1e-9) == len(kept) == np.linalg.matrix_rank(K, 1e-9)
    for rows in r.rows:
        lam = np.array([rows.get(lab, 0.0) for lab in labels])
        assert np.linalg.norm(lam @ K) <= 1e-9 * np.linalg.norm(lam) * max(1.0, np.abs(K).max())
        assert np.linalg.norm(lam - left @ (left.T @ lam)) <= 1e-8 * np.linalg.norm(lam)


def test_suggestion_makes_the_fourbar_exactly_constrained():
    """The Adams way: B spherical frees the moments about x and y, the rocker's pivot universal (a second
    axis across z) frees the force along z at B (a rotation about an in-plane axis through the pivot moves B
    along z).  The changed linkage RRSU: Kutzbach 6(4 - 1 - 4) + 1 + 1 + 3 + 2 = 1 = its mobility, so its
    overconstraint is 0: the suggestion, built and analysed, says so, and so does the count by hand."""
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    r = redundancy(mech, mech.generic_configurations()[1][0], suggest_fix=True)
    s = r.suggestion
    assert [(n, t) for n, t, _ in s.changes] == [("coupler_rocker", "spherical"), ("rocker_joint", "universal")]
    assert s.words.startswith("make coupler_rocker spherical and rocker_joint universal")
    assert (s.mobility, s.overconstraint) == (1, 0)
    assert 6 * (4 - 1 - 4) + 1 + 1 + 3 + 2 == 1


def test_suggestion_for_bennett_is_checked_too():
    """Bennett's three redundant rows: a ball at the cut joint frees two, a universal at a ground pivot the
    third.  By hand, the changed loop U R R S: Kutzbach 6(4 - 1 - 4) + 2 + 1 + 1 + 3 = 1 = its mobility, so
    overconstraint 0 -- which the built model gives too."""
    mech = screwkin.load(ROBOTS / "bennett.urdf")
    r = redundancy(mech, mech.generic_configurations()[1][0], suggest_fix=True)
    assert (r.suggestion.mobility, r.suggestion.overconstraint) == (1, 0)
    assert sorted(t for _, t, _ in r.suggestion.changes) == ["spherical", "universal"]
    assert 6 * (4 - 1 - 4) + 2 + 1 + 1 + 3 == 1


def test_mobility_and_statics_name_the_redundant_wrenches(capsys):
    """mobility --json carries redundant_wrenches (each a 6-vector about the world origin) and the checked
    suggestion; statics names the reactions it leaves as '?'."""
    assert main(["mobility", str(ROBOTS / "fourbar_crank_rocker.urdf"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["redundant_wrenches"]) == 3 and all(len(w["wrench"]) == 6 for w in d["redundant_wrenches"])
    assert d["exactly_constrained_by"]["overconstraint"] == 0
    assert main(["statics", str(MJCF), "--gravity", "--explain"]) == 0  # the reactions named: an explanation
    out = capsys.readouterr().out
    assert "connect 'ground_pivot': 1 of its 3 rows, the force along z -- the loop is planar" in out
    assert main(["statics", str(MJCF), "--gravity", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["redundant_joints"][0]["words"] == "1 of its 3 rows, the force along z"

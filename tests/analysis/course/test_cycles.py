"""analysis.course.cycles.fundamental_cycles: L = J - N + 1 loops (Euler's count for a connected
graph), each a closed walk whose joints join consecutive links, every joint outside the
tree closing exactly one of them."""

import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.course.cycles import fundamental_cycles


@pytest.mark.parametrize("name, loops", [("fourbar_crank_rocker.urdf", 1), ("stephenson_sixbar.urdf", 2),
                                         ("watt_sixbar.urdf", 2), ("planar_3rrr.urdf", 2)])
def test_cycle_count_and_walks(name, loops):
    mech = screwkin.load(ROBOTS / name)
    topo = mech.topology()
    cycles = fundamental_cycles(topo)
    assert len(cycles) == topo.n_joints - topo.n_links + 1 == loops
    closing = []
    for links, joints in cycles:
        for i, j in enumerate(joints):  # joints[i] joins links[i] and links[i + 1], cyclically
            assert set(j.links) == {links[i], links[(i + 1) % len(links)]}
        closing.append(joints)
    # the cycles are independent: each holds a joint no other cycle holds
    names = [{j.name for j in js} for js in closing]
    for k, mine in enumerate(names):
        assert mine - set().union(*(n for i, n in enumerate(names) if i != k))


def test_parallel_joints_and_a_self_loop():
    """Two joints between the same links make a loop of two links; a joint of a link with itself
    a loop of one."""
    from types import SimpleNamespace as NS

    j = [NS(name="a", links=("g", "x")), NS(name="b", links=("x", "g")), NS(name="c", links=("x", "x"))]
    topo = NS(links=("g", "x"), joints=j, ground="g")
    cycles = fundamental_cycles(topo)
    assert [(links, [jj.name for jj in joints]) for links, joints in cycles] == [(["g", "x"], ["a", "b"]),
                                                                                 (["x"], ["c"])]

"""The independent loops of a mechanism: the fundamental cycles of the joint graph (links as
nodes, joints as edges) for its breadth-first spanning tree from the ground.  Each joint
outside the tree closes one loop, L = J - N + 1 of them (for a connected mechanism).
"""

from __future__ import annotations
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.topology import Topology

__all__ = ["fundamental_cycles"]


def fundamental_cycles(topo: Topology) -> list:
    """The fundamental cycles of ``topo`` (screwkin.model.topology.Topology): a list of
    (links, joints), one per joint outside the breadth-first spanning tree from the ground
    (in the topology's joint order), with joints[i] between links[i] and links[i + 1]
    (cyclically).  Each cycle starts at the link of the loop nearest the ground, goes down the
    tree to one end of the closing joint, crosses it and comes back up.  The tree takes, of
    the joints that join a link to its parent, the first in the topology's order; a joint
    joining a link to itself is a loop of that link alone; links the ground does not reach
    are in no cycle."""
    import networkx as nx

    graph = nx.MultiGraph()
    graph.add_nodes_from(topo.links)
    joints = {j.name: j for j in topo.joints}
    for j in topo.joints:
        graph.add_edge(*j.links, key=j.name)
    parent = {topo.ground: None}
    depth = {topo.ground: 0}
    for link, other in nx.bfs_edges(graph, topo.ground):
        parent[other] = (link, joints[next(iter(graph[link][other]))])
        depth[other] = depth[link] + 1
    tree = {p[1].name for p in parent.values() if p is not None}
    cycles = []
    for j in topo.joints:
        a, b = j.links
        if j.name in tree or a not in parent or b not in parent:
            continue  # a tree joint, or a part not connected to the ground
        up_a, up_b = [a], [b]
        ja, jb = [], []
        x, y = a, b
        while x != y:  # up to the lowest common ancestor, the deeper side first
            if depth[x] >= depth[y]:
                x, jj = parent[x]
                ja.append(jj)
                up_a.append(x)
            else:
                y, jj = parent[y]
                jb.append(jj)
                up_b.append(y)
        # links: lca ... a, b ... (child of lca); joints between consecutive ones, then back to lca
        cycles.append((list(reversed(up_a)) + up_b[:-1], list(reversed(ja)) + [j] + jb))
    return cycles

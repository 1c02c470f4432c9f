"""Type and number synthesis: the planar kinematic chains of N links and F degrees of freedom
with simple one-DOF joints, and their mechanisms (inversions).

A chain is a graph: links are nodes, joints edges.  Gruebler's count 3 (N - 1) - 2 J = F
fixes the number of joints, J = (3 (N - 1) - F) / 2.  A chain is kept when

- it has no separable part: the graph is 2-connected (so every link carries two joints at
  least: no link hangs on one joint);
- it has no degenerate sub-chain: no set of k >= 2 of its links joined by j of its joints
  forms a structure, 3 (k - 1) - 2 j <= 0 (a triangle of links, a pair of links with two
  joints between them);
- it is not isomorphic to one kept already (networkx's isomorphism test).

Graphs are grown one joint at a time from N bare links, each level reduced to one graph per
isomorphism class, a graph dropped as soon as it holds a structure (more joints only make it
stiffer) or its links short of two joints outnumber what the remaining joints can give them.
Published counts: one 4-link chain (the four-bar), two 6-link chains (Watt: the two ternary
links joined; Stephenson: not), sixteen 8-link chains, all with F = 1.  The six-bars' inversions
are named by their graphs (Watt I, II; Stephenson I, II, III: screwkin.model.six_bar).

With K prismatic joints, every way of making K of the joints prismatic is taken up to the
chain's automorphisms; an assignment is dropped when a loop of the chain has fewer than two
revolute joints (the loop could not turn: its one revolute joint, or all, would be locked).

The mechanisms of a chain are its inversions: a choice of ground link, up to the chain's
automorphisms (links in one orbit make the same mechanism).  A prismatic joint has two
different elements, as textbooks draw them: the guide (a slot or rod) and the block sliding in
it; the automorphisms keep each block a block, so the slider-crank chain has its four
inversions (frame, crank, coupler or block grounded) and the double-slider chain with adjacent
sliders its three (elliptical trammel: the guide of both blocks grounded; Scotch yoke: a
block; Oldham coupling: the link joining the blocks).  Each guide is the end of its joint with
more prismatic joints on it (then more joints, then the lower link number): the link that
carries two slides is their common guide.

Each mechanism is described for a file (screwkin.files.writer) with generic proportions:
the links placed by a seeded spring layout of the graph, each joint near the middle of the
two links it joins, moved by a seeded random amount (so that no special geometry, such as
a parallelogram, changes the mobility); a link is the rigid body through its joint centres,
so the description is closed as placed.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ....errors import UsageError
from ....files.writer import PlanarJoint, PlanarLink, PlanarLinkage, PlanarLoopJoint
from ....model.six_bar import INVERSIONS, six_bar_chain, six_bar_inversion
from .designs import Chain, ChainsResult
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["enumerate_chains", "chain_linkage", "guides_of", "MAX_LINKS"]

#: The largest chain enumerated (10 links, F = 1: 230 chains, already some seconds).
MAX_LINKS = 10


def _joints_for(links: int, dof: int) -> int:
    twice = 3 * (links - 1) - dof
    if links < 2 or dof < 1:
        raise UsageError(f"--links must be at least 2 and --dof at least 1 (got {links} links, {dof} DOF)")
    if links > MAX_LINKS:
        raise UsageError(f"--links: at most {MAX_LINKS} links")
    if twice < 0 or twice % 2:
        raise UsageError(f"no planar chain of {links} links has {dof} DOF with one-DOF joints: "
                         f"3 (N - 1) - F = {twice} must be even and not negative (Gruebler)")
    return twice // 2


def _graph(n: int, edges: Sequence[tuple[int, int]]):
    import networkx as nx

    g = nx.Graph()
    g.add_nodes_from(range(n))
    g.add_edges_from(edges)
    return g


def _revolute_graphs(links: int, joints: int) -> tuple:
    """Edge lists of the non-isomorphic chains (see the module docstring); and how many
    graphs were looked at."""
    import networkx as nx

    n = links
    masks = np.array([[(s >> v) & 1 for v in range(n)] for s in range(1 << n)], bool)
    size = masks.sum(axis=1)
    limit = 1.5 * (size - 1)  # a subset with this many joints inside is a structure
    limit[size < 2] = np.inf
    inside = {(u, v): (masks[:, u] & masks[:, v]).astype(np.int16) for u, v in itertools.combinations(range(n), 2)}
    level = [((), np.zeros(1 << n, np.int16), (0,) * n)]
    looked = 0
    for e in range(joints):
        remaining = joints - e - 1
        buckets = {}
        out = []
        for edges, counts, degree in level:
            have = set(edges)
            for uv in itertools.combinations(range(n), 2):
                if uv in have:
                    continue
                new_counts = counts + inside[uv]
                if np.any(new_counts >= limit):
                    continue
                deg = list(degree)
                deg[uv[0]] += 1
                deg[uv[1]] += 1
                if sum(max(0, 2 - d) for d in deg) > 2 * remaining:
                    continue
                looked += 1
                new_edges = tuple(sorted(have | {uv}))
                g = _graph(n, new_edges)
                key = _invariant(g)
                bucket = buckets.setdefault(key, [])
                if any(nx.is_isomorphic(g, h) for h in bucket):
                    continue
                bucket.append(g)
                out.append((new_edges, new_counts, tuple(deg)))
        level = out
    chains = [edges for edges, _, _ in level if nx.is_biconnected(_graph(n, edges))]
    return chains, looked


def _invariant(g) -> tuple:
    """Equal for isomorphic graphs: each link's joints and its neighbours' joints, sorted."""
    deg = dict(g.degree())
    return tuple(sorted((deg[v], tuple(sorted(deg[u] for u in g[v]))) for v in g.nodes))


def _automorphisms(g, kinds=None, guides=None) -> list:
    """Every automorphism of chain g (node permutations as dicts), keeping joint kinds and, with
    ``guides`` (prismatic joint -> its guide link), which element of each prismatic joint is the
    guide and which the block."""
    import networkx as nx
    from networkx.algorithms.isomorphism import DiGraphMatcher, GraphMatcher, categorical_edge_match

    if guides is not None:
        d = nx.DiGraph()
        d.add_nodes_from(g.nodes)
        for (u, v), k in kinds.items():
            if k == "P":
                guide = guides[(u, v)]
                d.add_edge(guide, v if guide == u else u, kind="P")  # guide -> block
            else:
                d.add_edge(u, v, kind="R")
                d.add_edge(v, u, kind="R")
        return list(DiGraphMatcher(d, d, edge_match=categorical_edge_match("kind", "R")).isomorphisms_iter())
    if kinds is not None:
        for (u, v), k in kinds.items():
            g.edges[u, v]["kind"] = k
        matcher = GraphMatcher(g, g, edge_match=categorical_edge_match("kind", "R"))
    else:
        matcher = GraphMatcher(g, g)
    return list(matcher.isomorphisms_iter())


def guides_of(links: int, joints) -> dict:
    """Prismatic joint (u, v) -> its guide link (the module docstring's rule)."""
    slides, degree = [0] * links, [0] * links
    for u, v, k in joints:
        degree[u] += 1
        degree[v] += 1
        if k == "P":
            slides[u] += 1
            slides[v] += 1
    return {(u, v): max((u, v), key=lambda x: (slides[x], degree[x], -x)) for u, v, k in joints if k == "P"}


def _orbits(n: int, autos) -> tuple:
    seen, orbits = set(), []
    for v in range(n):
        if v in seen:
            continue
        orbit = sorted({a[v] for a in autos})
        seen.update(orbit)
        orbits.append(tuple(orbit))
    return tuple(orbits)


def _name(links: int, degrees: tuple, edges: Sequence[tuple[int, int]], kinds) -> str:
    prismatic = sum(1 for k in kinds.values() if k == "P")
    counts = {}
    for d in degrees:
        counts[d] = counts.get(d, 0) + 1
    words = {2: "binary", 3: "ternary", 4: "quaternary", 5: "pentagonal", 6: "hexagonal"}
    makeup = ", ".join(f"{counts[d]} {words.get(d, f'{d}-joint')}" for d in sorted(counts))
    if links == 4 and prismatic == 0:
        base = "four-bar chain"
    elif links == 4 and prismatic == 1:
        base = "slider-crank chain"
    elif links == 4 and prismatic == 2:
        p = [e for e, k in kinds.items() if k == "P"]
        adjacent = bool(set(p[0]) & set(p[1]))
        base = "double-slider chain, sliders adjacent (RRPP)" if adjacent else \
            "double-slider chain, sliders opposite (RPRP)"
    elif six_bar_chain(edges):
        base = f"{six_bar_chain(edges)} chain"
    else:
        base = f"{links}-link chain"
    return f"{base} ({makeup})"


def enumerate_chains(links: int, dof: int, prismatic: int = 0) -> ChainsResult:
    """The distinct planar chains of ``links`` links and ``dof`` DOF with ``prismatic`` of
    their joints prismatic, with their inversions (see the module docstring)."""
    import networkx as nx

    joints = _joints_for(links, dof)
    if prismatic < 0 or prismatic > joints:
        raise UsageError(f"--prismatic: between 0 and the number of joints ({joints}), got {prismatic}")
    graphs, looked = _revolute_graphs(links, joints)
    chains = []
    for edges in graphs:
        g = _graph(links, edges)
        degrees = tuple(d for _, d in sorted(g.degree()))
        if prismatic == 0:
            assignments = [dict.fromkeys(edges, "R")]
        else:
            autos = _automorphisms(g)
            cycles = [list(c) for c in nx.simple_cycles(g)]
            cycle_edges = [{tuple(sorted((c[i], c[(i + 1) % len(c)]))) for i in range(len(c))} for c in cycles]
            seen, assignments = set(), []
            for chosen in itertools.combinations(edges, prismatic):
                canon = min(tuple(sorted(tuple(sorted((a[u], a[v]))) for u, v in chosen)) for a in autos)
                if canon in seen:
                    continue
                seen.add(canon)
                p = set(chosen)
                if any(len(ce - p) < 2 for ce in cycle_edges):
                    continue
                assignments.append({e: ("P" if e in p else "R") for e in edges})
        for kinds in assignments:
            guides = guides_of(links, [(u, v, kinds[(u, v)]) for u, v in edges]) if prismatic else None
            autos = _automorphisms(_graph(links, edges), kinds if prismatic else None, guides)
            orbits = _orbits(links, autos)
            chains.append(Chain(len(chains) + 1, _name(links, degrees, edges, kinds), links,
                                tuple((u, v, kinds[(u, v)]) for u, v in edges), degrees, len(autos),
                                tuple(o[0] for o in orbits), orbits,
                                tuple(six_bar_inversion(edges, o[0]) for o in orbits)))
    return ChainsResult(links, dof, prismatic, joints, tuple(chains), (), looked)


def _drawing_numbers(ground: int, joints) -> dict:
    """Chain link -> the number screwkin's drawings give it (analysis.course.skeleton.numbering: the
    ground 1, then a depth-first walk from it over the joints in their order -- inputs first,
    then tree joints, then loop joints)."""
    number = {ground: 1}

    def visit(link: str | int) -> None:
        for u, v in joints:
            if link in (u, v):
                other = v if link == u else u
                if other not in number:
                    number[other] = len(number) + 1
                    visit(other)

    visit(ground)
    return number


def chain_linkage(chain: Chain, ground: int, size: float = 0.1, seed: int = 0, dof: int = 1) -> PlanarLinkage:
    """The file description of ``chain`` with link ``ground`` fixed (see the module docstring):
    links 'link1' ... numbered as screwkin draw numbers them (the ground link1), tree joints
    'j<u>_<v>' (chain link numbers) from a breadth-first spanning tree from the ground, loop joints
    for the other joints; the first ``dof`` joints on the ground are actuated; each prismatic
    joint's block drawn as a block around it."""
    import networkx as nx

    n = chain.links
    g = _graph(n, [(u, v) for u, v, _ in chain.joints])
    kinds = {(u, v): k for u, v, k in chain.joints}
    rng = np.random.default_rng(seed)
    layout = nx.spring_layout(g, seed=seed + 1, iterations=200)
    centres = {v: np.asarray(layout[v], float) * size for v in g.nodes}
    points, axes = {}, {}
    for u, v, _k in chain.joints:
        mid = (centres[u] + centres[v]) / 2
        span = float(np.hypot(*(centres[u] - centres[v]))) or size
        points[(u, v)] = mid + rng.normal(scale=0.2 * span, size=2)
        a = rng.uniform(0, np.pi)
        axes[(u, v)] = (math.cos(a), math.sin(a), 0.0)
    origin = {ground: np.zeros(2)}
    parent_joint = {}
    order = [ground]
    tree = set()
    for u, v in nx.bfs_edges(g, ground):
        e = (min(u, v), max(u, v))
        tree.add(e)
        origin[v] = points[e]
        parent_joint[v] = (u, e)
        order.append(v)
    tree_order = [parent_joint[v][1] for v in order[1:]]
    on_ground = sorted((e for e in tree_order if ground in e), key=lambda e: kinds[e] != "R")
    actuated_edges = on_ground[:dof]
    number = _drawing_numbers(ground, actuated_edges + [e for e in tree_order if e not in actuated_edges]
                              + [e for e in sorted(points) if e not in tree])
    name = lambda v: f"link{number[v]}"  # noqa: E731 - the number screwkin draw gives the link
    guides = guides_of(n, chain.joints)
    blocks = {}  # link -> the point of a prismatic joint it is the block of
    for e, guide in guides.items():
        block = e[1] if guide == e[0] else e[0]
        blocks.setdefault(block, e)
    link_points = {v: [] for v in g.nodes}
    for v, e in blocks.items():  # a block is drawn around its first point: its slide's
        link_points[v].append(tuple(points[e] - origin[v]))
    for v in g.nodes:
        if v != ground:
            q = tuple(points[parent_joint[v][1]] - origin[v])
            if q not in link_points[v]:
                link_points[v].append(q)
    for e, p in points.items():
        for v in e:
            q = tuple(p - origin[v])
            if q not in link_points[v]:
                link_points[v].append(q)
    links = [PlanarLink(name(v), tuple(link_points[v]), slider=v in blocks) for v in order]
    joints, loops = [], []
    for v in order[1:]:
        u, e = parent_joint[v]
        jt = "prismatic" if kinds[e] == "P" else "revolute"
        lo, hi = (-10 * size, 10 * size) if jt == "prismatic" else (-2 * math.pi, 2 * math.pi)
        joints.append(PlanarJoint(f"j{e[0]}_{e[1]}", jt, name(u), name(v), tuple(points[e] - origin[u]), 0.0,
                                  axes[e] if jt == "prismatic" else (0.0, 0.0, 1.0), lo, hi))
    for e in sorted(points):
        if e in tree:
            continue
        u, v = e
        jt = "prismatic" if kinds[e] == "P" else "revolute"
        loops.append(PlanarLoopJoint(f"j{u}_{v}", jt, name(u), tuple(points[e] - origin[u]), name(v),
                                     tuple(points[e] - origin[v]), 0.0, 0.0,
                                     axes[e] if jt == "prismatic" else (0.0, 0.0, 1.0)))
    actuated = tuple(f"j{e[0]}_{e[1]}" for e in actuated_edges)
    slides = "; ".join(f"j{u}_{v}: {name(guides[(u, v)])} is the guide, {name(v if guides[(u, v)] == u else u)} "
                       "the block" for u, v, k in chain.joints if k == "P")
    names = dict(zip(chain.inversions, chain.inversion_names))
    named = f": {names[ground]}, {INVERSIONS[names[ground]]}" if names.get(ground) else ""
    comment = (f"{chain.name}: {n} links, {len(chain.joints)} joints "
               f"({', '.join(f'{u}-{v} {k}' for u, v, k in chain.joints)}), written by screwkin synthesize chains\n"
               f"with chain link {ground} as the ground (one of its {len(chain.inversions)} inversions{named}) and generic "
               f"proportions (seed {seed}), drawn closed.\nLinks are named by the numbers screwkin draw gives them "
               f"(the ground link1): " + ", ".join(f"chain link {v} = {name(v)}" for v in sorted(number))
               + (f".\nSlides: {slides}." if slides else "."))
    return PlanarLinkage(f"chain{chain.index}_ground{ground}", tuple(links), tuple(joints), tuple(loops), actuated,
                         comment)

"""The six-bar chains and their inversions, named by the graph (links as nodes, joints as edges).

A six-bar of one freedom has 6 links and 7 one-freedom joints: 4 binary links (two joints each)
and 2 ternary links (three).  Watt's chain joins the two ternary links directly; Stephenson's
joins them through binary links only, by three paths of 1, 1 and 2 binary links.  The
inversions (which link is the ground), after E. Constans and K. Dyer, *Introduction to Mechanism
Design with Computer Applications* (CRC Press 2018), the six-bar chapter (and its MATLAB
exercises, github.com/ziolkowskid06/Introduction_to_Mechanism_Design_with_Computer_Application):

- Watt I: a binary link is the ground (ground pins A and D only; the coupler and the rocker are
  the ternary links);
- Watt II: a ternary link is the ground (ground pins A, D and F);
- Stephenson I: the ground is a binary link joined to both ternary links (it carries the crank's
  and the rocker's triangles);
- Stephenson II: the ground is a binary link joined to one ternary link (a binary link of the
  two-binary path between the ternary links);
- Stephenson III: a ternary link is the ground (ground pins A, D, F; the ternary coupler B, C, E
  and the dyad E-G-F).

Plain graphs only (no Pinocchio): ``screwkin.model.topology`` names a mechanism's six-bar with it
and ``synthesize chains`` its enumerated inversions.
"""

from __future__ import annotations

__all__ = ["six_bar_chain", "six_bar_inversion", "INVERSIONS"]

#: Each inversion in words (what the graph says of its ground).
INVERSIONS = {
    "Watt I": "Watt's chain (its ternary links jointed together), the ground a binary link",
    "Watt II": "Watt's chain (its ternary links jointed together), the ground a ternary link",
    "Stephenson I": "Stephenson's chain (its ternary links apart), the ground a binary link jointed to both ternary "
                    "links",
    "Stephenson II": "Stephenson's chain (its ternary links apart), the ground a binary link jointed to one ternary "
                     "link",
    "Stephenson III": "Stephenson's chain (its ternary links apart), the ground a ternary link",
}


def _neighbours(edges: list):
    """link -> the links it is jointed to, or None when two joints join the same two links (or a
    link to itself: not a six-bar's graph)."""
    out, seen = {}, set()
    for u, v in edges:
        key = frozenset((u, v))
        if u == v or key in seen:
            return None
        seen.add(key)
        out.setdefault(u, set()).add(v)
        out.setdefault(v, set()).add(u)
    return out


def six_bar_chain(edges: list) -> str | None:
    """"Watt" or "Stephenson" for the graph of a six-bar chain (6 links, 7 joints, 4 binary and 2
    ternary links; ``edges`` the joints as (link, link) pairs), else None."""
    nb = _neighbours(list(edges))
    if nb is None or len(nb) != 6 or sum(len(s) for s in nb.values()) != 14:
        return None
    if sorted(len(s) for s in nb.values()) != [2, 2, 2, 2, 3, 3]:
        return None
    t1, t2 = (v for v, s in nb.items() if len(s) == 3)
    return "Watt" if t2 in nb[t1] else "Stephenson"


def six_bar_inversion(edges: list, ground: str) -> str | None:
    """The inversion of a six-bar with link ``ground`` fixed: "Watt I", "Watt II", "Stephenson I",
    "Stephenson II" or "Stephenson III" (the module docstring); None when the graph is not a
    six-bar chain or ``ground`` is not one of its links."""
    edges = list(edges)
    chain = six_bar_chain(edges)
    nb = _neighbours(edges)
    if chain is None or ground not in nb:
        return None
    ternary = {v for v, s in nb.items() if len(s) == 3}
    if chain == "Watt":
        return "Watt II" if ground in ternary else "Watt I"
    if ground in ternary:
        return "Stephenson III"
    return "Stephenson I" if nb[ground] <= ternary else "Stephenson II"

"""MJCF actuators and fixed tendons as screwkin's inputs.

MuJoCo's actuator acts through a transmission: a joint (``joint``, ``jointinparent``), a tendon,
a site, a slider-crank or a body.  A fixed tendon is a linear combination of joint values,
L = sum coef_i q_i; a joint coupled by an ``<equality><joint>`` moves as m q_p + o of its primary.
So a joint or fixed-tendon actuator drives a linear combination of screwkin's coordinates; when
that combination is one coordinate (``scale * q + offset``: the Robotiq 2F-85's ``split`` tendon
over two coupled driver joints, WidowX's gripper actuator on the coupled finger) that coordinate
is the input, named by the tendon or the joint the file names.  A combination of several
independent coordinates (an under-actuated finger's tendon), a spatial tendon, a site, a
slider-crank or a body transmission is read and named, once, in one line, and is not an input.
"""

from __future__ import annotations

from ..errors import quote, shorten
from ..tolerances import DEFAULT
from .description import LIMITS, Transmission
from .urdf import numbers

__all__ = ["ACTUATORS", "read_tendons", "read_actuators"]

#: Actuator elements (MuJoCo's shortcuts and <general>).
ACTUATORS = ("motor", "position", "velocity", "general", "intvelocity", "damper", "cylinder", "muscle", "adhesion")
#: Transmission attributes of an actuator, and what each is called in a message.
_TARGETS = (("joint", "joint"), ("jointinparent", "joint"), ("tendon", "tendon"), ("site", "site"),
            ("cranksite", "slider-crank"), ("body", "body"))


def read_tendons(r, mjoints: dict) -> dict:
    """Fixed tendon name -> ((joint, coef), ...); spatial tendons -> None (not linear in the joints)."""
    p = r.problems
    out = {}
    unnamed = 0
    for section in r.root.findall("tendon"):
        for t in section:
            if t.tag not in ("fixed", "spatial"):
                p.append(f"<tendon><{shorten(str(t.tag), 30)}> is not a MuJoCo tendon (fixed or spatial)")
                continue
            unnamed += not t.get("name")
            name = t.get("name") or f"tendon{unnamed}"
            if name in out:
                p.append(f"tendon {quote(name)} is defined twice")
                continue
            if t.tag == "spatial":
                out[name] = None
                continue
            terms = []
            for j in t.findall("joint"):
                jn = j.get("joint")
                what = f"tendon {quote(name)} joint {quote(jn or '')}"
                if jn not in mjoints:
                    p.append(f"{what} is not a joint of the file")
                    continue
                if mjoints[jn][0] not in ("hinge", "slide"):
                    p.append(f"{what} is a {mjoints[jn][0]} joint: a fixed tendon takes hinge and slide joints")
                    continue
                (coef,) = numbers(j.get("coef"), 1, f"{what} coef", p, (None,), 1e9, "")
                if coef is None:  # missing, or invalid (numbers() said why)
                    if j.get("coef") is None:
                        p.append(f"{what} has no coef (MuJoCo requires it)")
                    continue
                terms.append((jn, float(coef)))
            out[name] = tuple(terms)
    return out


def _resolve(terms: tuple, couplings: dict) -> tuple:
    """(coordinate -> coefficient, offset) of sum coef * joint with coupled joints replaced by
    m * primary + o (couplings: joint -> Coupling, chains already resolved to the primary)."""
    coefs, offset = {}, 0.0
    for j, c in terms:
        if j in couplings:
            cp = couplings[j]
            coefs[cp.mimics] = coefs.get(cp.mimics, 0.0) + c * cp.multiplier
            offset += c * cp.offset
        else:
            coefs[j] = coefs.get(j, 0.0) + c
    scale = max([abs(v) for v in coefs.values()] + [1.0])
    return {j: v for j, v in coefs.items() if abs(v) > DEFAULT.zero * scale}, offset


def read_actuators(r, mjoints: dict, tendons: dict, couplings: dict) -> tuple:
    """(input joints in file order, Transmission of each actuator that is not a plain joint's,
    one line naming the actuators that are not inputs or None)."""
    p = r.problems
    names, inputs, unused = [], [], []
    count = 0
    for section in r.root.findall("actuator"):
        for e in section:
            if e.tag == "plugin":  # an actuator computed by an engine plugin
                count += 1
                unused.append(f"{quote(e.get('name') or 'plugin' + str(count))} (a plugin actuator)")
                continue
            if e.tag not in ACTUATORS:
                p.append(f"<actuator><{shorten(str(e.tag), 30)}> is not a MuJoCo actuator")
                continue
            count += 1
            a = r.actuator_attrs(e)
            name = a.get("name") or f"{e.tag}{count}"
            what = f"actuator {quote(name)}"
            given = [(k, word) for k, word in _TARGETS if a.get(k)]
            if len(given) != 1:
                p.append(f"{what} names {'no' if not given else 'more than one'} transmission "
                         f"(one of {', '.join(k for k, _ in _TARGETS)})")
                continue
            key, word = given[0]
            target = a[key]
            gear = numbers(a.get("gear"), len((a.get("gear") or "1").split()), f"{what} gear", p, (1.0,), 1e9, "")
            gear = float(gear[0]) if gear else 1.0
            if key in ("joint", "jointinparent"):
                if target not in mjoints:
                    p.append(f"{what} names joint {quote(target)}, which is not in the file")
                    continue
                if mjoints[target][0] not in ("hinge", "slide"):
                    unused.append(f"{quote(name)} ({mjoints[target][0]} joint {quote(target)})")
                    continue
                terms, kind = ((target, 1.0),), "coupled joint" if target in couplings else "joint"
            elif key == "tendon":
                if target not in tendons:
                    p.append(f"{what} names tendon {quote(target)}, which is not in the file")
                    continue
                if tendons[target] is None:
                    unused.append(f"{quote(name)} (spatial tendon {quote(target)})")
                    continue
                terms, kind = tendons[target], "tendon"
            else:
                unused.append(f"{quote(name)} ({word} {quote(target)})")
                continue
            coefs, offset = _resolve(terms, couplings)
            if not gear:
                unused.append(f"{quote(name)} (gear 0: it exerts nothing)")
                continue
            if len(coefs) != 1:
                combo = " + ".join(f"{c:g} {j}" for j, c in coefs.items()).replace("+ -", "- ") or "0"
                unused.append(f"{quote(name)} ({word} {quote(target)} = {combo}, "
                              f"{'a combination of ' + str(len(coefs)) + ' independent joints' if coefs else 'no motion'})")
                continue
            ((joint, scale),) = coefs.items()
            t = Transmission(target, name, kind, tuple(terms), joint, scale, offset, gear)
            if joint in names:
                r.warnings.append(f"{what} drives {t.text()}, which another actuator drives already: one input")
                continue
            names.append(joint)
            if not t.plain:
                inputs.append(t)
    if len(names) + len(unused) > LIMITS.joints:
        p.append(f"more than {LIMITS.joints} actuators")
    line = None
    if unused:
        line = (f"{len(unused)} actuator{'s are' if len(unused) > 1 else ' is'} not an input here (screwkin's inputs "
                f"are joint coordinates): {', '.join(unused[:6])}{', ...' if len(unused) > 6 else ''}")
    return names, inputs, line

"""URDF ``<transmission>`` elements as screwkin's inputs, with their mechanical reductions.

A ROS ``transmission_interface/SimpleTransmission`` joins one actuator to one joint through a
reduction n: the actuator's effort is the joint's / n and its position the joint's x n
(transmission_interface's SimpleTransmission) -- MuJoCo's ``gear`` exactly, so a reduction is a
:class:`~screwkin.files.description.Transmission` with ``gear`` n, and ``statics``/``dynamics``
give the actuator's effort beside the joint's as they do for an MJCF gear.  The reduction is read
where the ROS formats write it: ``<actuator><mechanicalReduction>`` (ROS 1), a
``<mechanicalReduction>`` directly under ``<transmission>`` (the older PR2 form), or a
``<mechanical_reduction>`` of the actuator or joint (the ros2_control spelling).  Transmissions of
other types (differential, four-bar) with reductions are named in one warning, a reduction of 0
and a joint ``<offset>`` in one each, and not used; the joints are still inputs.
"""

from __future__ import annotations

from ..errors import quote
from .description import Transmission
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["read_transmissions"]

#: Where a SimpleTransmission's reduction is written, in the order looked for.
_REDUCTION = ("actuator/mechanicalReduction", "mechanicalReduction", "actuator/mechanical_reduction",
              "joint/mechanical_reduction")


def _kind(t) -> str:
    """The transmission's type as written (``<type>``, ``type=``, ros2_control's ``<plugin>``)."""
    for tag in ("type", "plugin"):
        e = t.find(tag)
        if e is not None and (e.text or "").strip():
            return e.text.strip()
    return t.get("type") or ""


def read_transmissions(root, joints: list, loop_names: set, warnings: list, mimics: dict, numbers: Callable) -> tuple:
    """(joint names of the ``<transmission>`` elements in order, Transmission of each with a
    reduction other than 1).  ``numbers``: files.urdf's reader of numbers (passed in: that module
    calls this one).  A transmission naming a fixed joint, a loop joint, a joint that
    mimics another (it moves with that one) or a joint not in the file is a warning, and is
    ignored (ROS files often carry transmissions of fixed or removed joints: PR2, Kinova, TALOS)."""
    types = {j.name: j.type for j in joints}
    names, inputs, others = [], [], []
    for t in root.findall("transmission"):
        tname = t.get("name") or "?"
        what = f"transmission {quote(tname)}"
        gear = None  # read once, for the first joint it drives
        for j in t.findall("joint"):
            jn = j.get("name")
            why = None
            if not jn:
                why = "a joint without a name"
            elif jn in loop_names:
                why = f"joint {quote(jn)}, which is a loop joint (not an input)"
            elif jn not in types:
                why = f"joint {quote(jn)}, which is not in the file"
            elif types[jn] == "fixed":
                why = f"joint {quote(jn)}, which is fixed"
            elif jn in mimics:
                why = f"joint {quote(jn)}, which mimics {quote(mimics[jn])} (it moves with it)"
            if why:
                warnings.append(f"{what} names {why}: ignored")
            elif jn not in names:
                names.append(jn)
                gear = _reduction(t, what, warnings, numbers, others) if gear is None else gear
                if gear != 1.0:
                    a = t.find("actuator")
                    actuator = (a.get("name") if a is not None else None) or tname
                    inputs.append(Transmission(jn, actuator, "joint", ((jn, 1.0),), jn, gear=gear,
                                               word="mechanicalReduction"))
    if others:
        kinds = sorted({k.rsplit("/", 1)[-1] for _, k in others})
        warnings.append(f"the reductions of {len(others)} transmission{'s' if len(others) > 1 else ''} of other types "
                        f"than SimpleTransmission ({', '.join(kinds)}: {', '.join(quote(n, 30) for n, _ in others[:3])}"
                        f"{', ...' if len(others) > 3 else ''}) are not read: their joints are inputs, driven one to one")
    return names, inputs


def _reduction(t, what: str, warnings: list, numbers: Callable, others: list) -> float:
    """The SimpleTransmission's reduction (1 when none is written or it cannot be used, said)."""
    found = [(path, e) for path in _REDUCTION for e in t.findall(path)]
    for e in t.findall("joint/offset"):
        if (e.text or "0").strip() not in ("0", "0.0"):
            warnings.append(f"{what}: the joint <offset> is not read (it shifts the actuator's position only)")
    if not found:
        return 1.0
    path, e = found[0]
    problems = []
    (value,) = numbers((e.text or "").strip() or None, 1, f"{what} <{path}>", problems, (1.0,), 1e9, "")
    kind = _kind(t)
    if kind and "SimpleTransmission" not in kind:
        if any((x.text or "").strip() not in ("1", "1.0") for _, x in found):
            others.append((t.get("name") or "?", kind))
        return 1.0
    if problems:
        warnings.append(f"{problems[0]}: not read (reduction 1)")
        return 1.0
    if len(found) > 1 and any((x.text or "").strip() != (e.text or "").strip() for _, x in found[1:]):
        warnings.append(f"{what} writes {len(found)} different reductions: the <{path}> one ({value:g}) is read")
    if value == 0.0:
        warnings.append(f"{what} has a reduction of 0 (it would exert nothing): not read (reduction 1)")
        return 1.0
    return float(value)

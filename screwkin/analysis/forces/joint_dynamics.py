"""The joints' own dynamics a file gives, as MuJoCo applies them to each degree of freedom: an MJCF
joint's armature (a motor's reflected inertia, added to the mass matrix's diagonal), damping (a
viscous force -damping * v), frictionloss (a dry friction of that magnitude opposing the motion:
at rest anywhere within +-frictionloss) and a hinge's or slide's spring (-stiffness * (x -
springref)); a URDF joint's <dynamics damping friction>.  The generalized force that overcomes them
at (q, v, a) is

    Q = armature a + damping v + frictionloss sign(v) + stiffness (x - springref)

per degree of freedom (sign(v) taken 0 where the joint stands still, which the callers say), and a
mimic joint's, at multiplier x its leader's rate, reaches its leader's coordinate times the
multiplier.  statics (v = a = 0: the springs) and dynamics add Q to the tree's generalized forces.

Units: SI (kg m^2 or kg, N m s/rad or N s/m, N m or N, N m/rad or N/m).
"""

from __future__ import annotations

import numpy as np

from ...errors import quote
from ...model.geometry import wrap_angle
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from collections.abc import Sequence

__all__ = ["JointDynamics", "joint_dynamics", "left_out_note", "names_text"]


class JointDynamics(dict):
    """The joints' own dynamics a file gives (MJCF armature, damping, frictionloss, a hinge's or slide's
    spring), as MuJoCo applies them to each degree of freedom; name -> the joint's velocity indices (a
    mimic joint's: its leader's).  Arrays over the model's velocity coordinates: ``armature``,
    ``damping``, ``frictionloss``; ``springs`` and ``coupled`` (the mimic joints') by name."""

    def __init__(self, mech: Mechanism, joints: list, coupled: list) -> None:
        super().__init__()
        nv = mech.model.nv
        self.armature, self.damping, self.frictionloss = np.zeros(nv), np.zeros(nv), np.zeros(nv)
        self.springs = {}  # name -> (velocity index, stiffness, springref) of a hinge's or slide's spring
        for j in joints:
            idx = mech.velocity_indices([j.name])
            self[j.name] = idx
            self.armature[idx], self.damping[idx], self.frictionloss[idx] = j.armature, j.damping, j.frictionloss
            if j.stiffness:
                self.springs[j.name] = (int(idx[0]), j.stiffness, j.springref)
        self._values = lambda q: {**mech.joint_values(q), **(mech.coupled_values(q) if coupled else {})}
        # a mimic joint moves at multiplier x its leader's rate: its own terms reach the leader through it
        self.coupled = {c.joint: (c.multiplier, int(mech.coordinate(c.mimics).idx_v), j) for c, j in coupled}
        for name, (_, iv, j) in self.coupled.items():
            self[name] = np.array([iv])
            if j.stiffness:
                self.springs[name] = (iv, j.stiffness, j.springref)
        self._zero = mech.tolerances.equal
        # a hinge's angle is known modulo a turn (a solve gives it in (-pi, pi]): its spring's stretch too
        self._angular = lambda name: (self.coupled[name][2].type in ("revolute", "continuous") if name in self.coupled
                                      else not mech.translational[mech.coordinate(name).idx_v])

    def _terms(self, arm, damp, fl, v: np.ndarray, a: np.ndarray):
        return arm * a + damp * v + fl * np.where(np.abs(v) > self._zero, np.sign(v), 0.0)

    def coupled_forces(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> dict:
        """Each mimic joint's own force at (q, v, a) (its rate and acceleration: multiplier x its leader's),
        its spring's with it."""
        stretch = self.spring_stretch(q) if any(n in self.springs for n in self.coupled) else {}
        return {name: float(self._terms(j.armature, j.damping, j.frictionloss, m * v[iv], m * a[iv])
                            + j.stiffness * stretch.get(name, 0.0))
                for name, (m, iv, j) in self.coupled.items()}

    def spring_stretch(self, q: np.ndarray) -> dict:
        """Each spring's stretch x - springref [rad or m] at q; a hinge's within half a turn of springref
        (its angle is known modulo a turn: a spring wound further than half a turn is not represented)."""
        values = self._values(q)
        return {n: (wrap_angle(values[n] - ref) if self._angular(n) else values[n] - ref)
                for n, (_, _, ref) in self.springs.items()}

    def forces(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> tuple:
        """(the generalized force that drives them at (q, v, a), each mimic joint's own force): armature a +
        damping v + frictionloss sign(v) + stiffness (x - springref), sign(v) 0 where the joint stands
        still (|v| within the tolerance ``equal``); a mimic joint's, times its multiplier, on its leader's
        coordinate."""
        out = self._terms(self.armature, self.damping, self.frictionloss, v, a)
        for name, x in self.spring_stretch(q).items():
            if name not in self.coupled:  # a mimic joint's spring is among its coupled forces, below
                iv, k, _ = self.springs[name]
                out[iv] += k * x
        coupled = self.coupled_forces(q, v, a)
        for name, f in coupled.items():
            m, iv, _ = self.coupled[name]
            out[iv] += m * f
        return out, coupled

    def friction_at_rest(self, v: np.ndarray) -> set:
        """The joints with friction loss that stand still at v (their dry friction not determined)."""
        fl = {n: self.coupled[n][2].frictionloss if n in self.coupled else self.frictionloss[idx].max()
              for n, idx in self.items()}
        return {n for n, idx in self.items() if fl[n] > 0 and np.any(np.abs(v[idx]) <= self._zero)}

    def potential(self, q: np.ndarray) -> float:
        """The springs' energy 1/2 sum stiffness (x - springref)^2 [J]."""
        return 0.5 * sum(self.springs[n][1] * x * x for n, x in self.spring_stretch(q).items())

    def kinetic(self, v: np.ndarray) -> float:
        """The armature's kinetic energy 1/2 sum armature v^2 [J] (MuJoCo's mass matrix holds it)."""
        return 0.5 * (float(self.armature @ (v * v))
                      + sum(j.armature * (m * v[iv]) ** 2 for m, iv, j in self.coupled.values()))


def joint_dynamics(mech: Mechanism) -> tuple:
    """(JointDynamics of the tree and mimic joints with armature, damping or friction loss; names of
    those it cannot hold: loop joints, which have no coordinate of their own in the tree)."""
    given = [j for j in mech.spec.joints if j.dynamics]
    names = {c.joint for c in mech.coordinates}
    couplings = {c.joint: c for c in mech.couplings}
    coupled = [(couplings[j.name], j) for j in given if j.name in couplings]
    return (JointDynamics(mech, [j for j in given if j.name in names], coupled),
            [j.name for j in given if j.name not in names and j.name not in couplings])


def names_text(names: Sequence[str]) -> str:
    """Up to three names, quoted, and ', ...' for more."""
    return f"{', '.join(quote(n, 30) for n in names[:3])}{', ...' if len(names) > 3 else ''}"


def left_out_note(left: Sequence[str]) -> str | None:
    """The note naming the loop joints whose own dynamics no balance holds (joint_dynamics' second part)."""
    if not left:
        return None
    return (f"the armature, damping, friction loss and springs of {len(left)} loop joints ({names_text(left)}) are "
            "not in these efforts: they have no coordinate of their own in the tree")

"""What the vector-loop equations of a planar mechanism are made of, as plain results: the symbols
(angles, lengths, slider coordinates; constants, inputs, unknowns), the link vectors, each loop's
equation, and the whole set with A, B, c and det A (analysis.course.vector_loops builds them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Symbol", "Vector", "LoopEquation", "PlanarEquations", "GREEK", "spelled"]

#: The symbols' Greek words and the letters the text writes them with (theta3 is written θ3).
GREEK = (("theta", "θ"), ("alpha", "α"), ("beta", "β"), ("rho", "ρ"))


def spelled(name: str) -> str:
    """A symbol as the equations name it, from either spelling a person may type: ``θ3`` (as the text
    writes it) -> ``theta3``; ``theta3`` stays."""
    for word, letter in GREEK:
        if name.startswith(letter):
            return word + name[len(letter):]
    return name


@dataclass(frozen=True)
class Symbol:
    """A quantity of the equations: ``kind`` "angle" [rad], "length" [m] or "slider" [m]
    (a slider coordinate); ``role`` "constant", "input" or "unknown"; ``value`` at the
    configuration analysed; ``meaning`` in words."""

    name: str
    link: str
    kind: str
    value: float
    role: str
    meaning: str


@dataclass(frozen=True)
class Vector:
    """A link vector of the loops: its name, the link, the joint centres it joins, its
    length and angle as expressions (sympy syntax)."""

    name: str
    link: str
    start: str
    end: str
    length: str
    angle: str


@dataclass(frozen=True)
class LoopEquation:
    """One independent loop: the links and joints walked, the vector equation (terms summed
    to zero) and its x and y components (sympy expressions equal to zero)."""

    links: tuple
    joints: tuple
    terms: tuple  # e.g. ("r2", "r3", "-x4*u4", "-e4*n4")
    equations: tuple  # (x component, y component)


@dataclass(frozen=True)
class PlanarEquations:
    path: str
    normal: tuple
    numbers: dict  # link name -> textbook number (ground 1)
    loops: tuple  # LoopEquation
    vectors: tuple  # Vector
    symbols: dict  # name -> Symbol
    inputs: tuple  # input symbols, in the order of the input joints
    input_joints: dict  # input symbol -> (joint name, d symbol / d joint value: +1 or -1)
    unknowns: tuple
    A: tuple  # rows of strings
    B: tuple
    acceleration_terms: tuple  # c, strings (rates as NAME_d)
    det_A: str | None
    singular_conditions: tuple  # strings: "sin(theta3 - theta4) = 0: theta3 = theta4 or theta4 + pi"
    singular_words: tuple  # the same in words
    A_value: np.ndarray  # A and B at the configuration
    B_value: np.ndarray
    det_A_value: float | None
    rates: np.ndarray | None  # A^-1 B: unknown rates per unit input rate (columns: inputs); None when A is singular
    notes: tuple
    pairs: tuple = ()  # RollingPair: the no-slip laws of rolling and gear pairs

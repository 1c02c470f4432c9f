"""Dynamics results (screwkin.analysis.forces.dynamics) as text, JSON-ready dictionaries, CSV and a plot
of the effort against the input."""

from __future__ import annotations

import math

import numpy as np

from ..analysis.forces.dynamics import COMPONENTS, DynamicsResult
from ..units import in_unit
from .plots import pyplot
from .report import sweep_rows
from .tables import column_text, csv_text, table
from .outfile import write_figure

__all__ = ["dynamics_dict", "dynamics_text", "dynamics_csv", "dynamics_plot", "REACTION_POINT", "SHAKING_POINT"]

REACTION_POINT = ("what the parent side (link1 of a cut joint) exerts on the child side (link2), "
                  "(force, moment) at the joint's origin (a cut joint's F2 origin), world axes")
SHAKING_POINT = "what the moving links exert on the ground: force, and moment about the world origin, world axes"


def _input_values(r: DynamicsResult, shown: str | None) -> tuple:
    """(the input's values, their unit) as shown: in ``shown`` (a unit of the input's kind as a person
    typed it: deg, mm, in; units.in_unit converts), else in SI."""
    if shown:
        return in_unit(r.values, shown), shown
    return r.values, r.unit


def _list(a: np.ndarray) -> list:
    """A flat list of numbers, NaN where the analysis leaves a value undetermined (an effort of
    redundant actuation: null in the JSON, by present/jsonout.py's rule)."""
    return np.asarray(a, float).ravel().tolist()


def dynamics_dict(r: DynamicsResult) -> dict:
    rate = "rad/s" if r.unit == "rad" else "m/s"
    fly = r.flywheel
    return {
        "input": r.input, "inputs": list(r.inputs), "speed": r.speed, "values": _list(r.values),
        "efforts": {k: _list(v) for k, v in r.efforts.items()},
        "reactions": {k: [_list(row) for row in v] for k, v in r.reactions.items()},
        "reaction_kinds": dict(r.reaction_kinds), "reaction_point": REACTION_POINT,
        "undetermined_components": {k: list(v) for k, v in r.open_components.items() if v},
        "indeterminate": r.indeterminate,
        "shaking": {"force": [_list(x) for x in r.shaking_force], "moment": [_list(x) for x in r.shaking_moment],
                    "point": SHAKING_POINT},
        "kinetic_energy": _list(r.kinetic_energy), "potential_energy": _list(r.potential_energy),
        "input_power": _list(r.input_power), "load_power": _list(r.load_power), "unbalanced": _list(r.unbalanced),
        "peak": r.peak, "mean": r.mean, "rms": r.rms,
        "flywheel": {"cs": fly.cs, "omega": fly.omega, "energy_fluctuation": fly.energy_fluctuation,
                     "inertia": fly.inertia, "reason": fly.reason},
        "gravity": list(r.gravity),
        "loads": [{"link": ld.link, "point": None if ld.point is None else list(ld.point), "name": ld.name,
                   "wrench": list(ld.wrench)} for ld in r.loads],
        "completed": r.completed, "notes": list(r.notes),
        "actuator_efforts": {k: _list(v) for k, v in r.actuator_efforts.items()},
        "coupled_efforts": {k: _list(v) for k, v in r.coupled_efforts.items()},
        "transmissions": [t.text() for t in r.transmissions],
        "units": {"values": r.unit, "speed": rate, "efforts": dict(r.effort_units), "reactions": "N, N m",
                  "shaking": "N, N m", "kinetic_energy": "J", "potential_energy": "J", "input_power": "W",
                  "load_power": "W", "gravity": "m/s^2", "flywheel_energy_fluctuation": "J",
                  "flywheel_inertia": "kg m^2", "flywheel_omega": "rad/s"},
    }


def _effort_header(r: DynamicsResult, name: str) -> str:
    return f"{name} [{r.effort_units[name].replace(' ', '*')}]"


def dynamics_text(r: DynamicsResult, shown: str | None = None, speed_text: str | None = None) -> str:
    x, u = _input_values(r, shown)
    rate = "rad/s" if r.unit == "rad" else "m/s"
    speed = f"{speed_text} ({r.speed:.6g} {rate})" if speed_text else f"{r.speed:.6g} {rate}"
    lines = [f"{r.input} driven at the constant speed {speed}, {len(r.values)} configurations"]
    g = "none" if not any(r.gravity) else "(" + ", ".join(f"{x:.6g}" for x in r.gravity) + ") m/s^2"
    lines.append(f"gravity: {g}")
    for ld in r.loads:
        at = "its frame's origin" if ld.point is None else \
            f"point {ld.name or ''} (" + ", ".join(f"{x:.6g}" for x in ld.point) + ") m in its frame"
        lines.append(f"load on '{ld.link}' at {at}: force ({', '.join(f'{x:.6g}' for x in ld.wrench[:3])}) N, "
                     f"moment ({', '.join(f'{x:.6g}' for x in ld.wrench[3:])}) N*m, world axes")
    rows = sweep_rows(len(r.values))
    cols = [column_text(x[rows])]
    headers = [f"{r.input} [{u}]"]
    for name in r.inputs:
        cols.append([("nan" if not np.isfinite(x) else c) for x, c in zip(r.efforts[name][rows],
                                                                           column_text(np.nan_to_num(r.efforts[name][rows])))])
        headers.append(_effort_header(r, name))
    cols.append(column_text(r.kinetic_energy[rows]))
    headers.append("kinetic energy [J]")
    cols.append(column_text(np.linalg.norm(r.shaking_force[rows], axis=1)))
    headers.append("|shaking force| [N]")
    cols.append(column_text(np.linalg.norm(r.shaking_moment[rows], axis=1)))
    headers.append("|shaking moment| [N*m]")
    lines += ["", table(headers, list(zip(*cols)))]
    if len(rows) < len(r.values):
        lines.append(f"({len(rows)} of {len(r.values)} steps shown; --csv or --json for all)")
    lines.append("")
    for name in r.inputs:
        unit = r.effort_units[name].replace(" ", "*")
        if r.peak[name] is None:
            lines.append(f"{name}: effort not determined (redundant actuation)")
        else:
            lines.append(f"{name}: peak |effort| {r.peak[name]:.6g} {unit}, mean {r.mean[name]:.6g} {unit}, "
                         f"RMS {r.rms[name]:.6g} {unit}")
    for t in r.transmissions:
        y = r.actuator_efforts[t.actuator]
        if np.all(np.isfinite(y)):
            lines.append(f"actuator {t.actuator!r}: peak |effort| {np.max(np.abs(y)):.6g} (the effort on {t.joint} / "
                         f"{t.scale * t.gear:g}: {t.text()})")
        else:
            lines.append(f"actuator {t.actuator!r}: effort not determined (redundant actuation)")
    for name, y in r.coupled_efforts.items():
        lines.append(f"coupled joint {name!r}: peak |effort| {np.max(np.abs(y)):.6g} "
                     f"{r.effort_units[name].replace(' ', '*')} (what its coupling exerts along it)")
    fly = r.flywheel
    if fly.inertia is not None:
        at = f"{fly.omega:.6g} rad/s"  # the speed as typed first (120rpm), as the first line says it
        at = f"{speed_text} ({at})" if speed_text and math.isclose(fly.omega, r.speed) else at
        lines.append(f"flywheel: energy fluctuation {fly.energy_fluctuation:.6g} J over the turn; for Cs = {fly.cs:g} "
                     f"at {at} it takes I = dE / (Cs omega^2) = {fly.inertia:.6g} kg*m^2")
    else:
        lines.append(f"flywheel: not given ({fly.reason})")
    lines += ["", "joint reactions: " + REACTION_POINT, "largest magnitude over the motion:"]
    rrows = []
    for name, w in r.reactions.items():
        open_ = r.open_components.get(name, ())
        fmask = [c not in open_ for c in COMPONENTS[:3]]
        mmask = [c not in open_ for c in COMPONENTS[3:]]
        fpk = float(np.max(np.linalg.norm(w[:, :3][:, fmask], axis=1))) if any(fmask) else 0.0
        mpk = float(np.max(np.linalg.norm(w[:, 3:][:, mmask], axis=1))) if any(mmask) else 0.0
        rrows.append([name, r.reaction_kinds[name], fpk, mpk, " ".join(open_) or "-"])
    for c in (2, 3):  # round-off (1e-15 N m in a pin) is not a value
        for row, text in zip(rrows, column_text([row[c] for row in rrows])):
            row[c] = text
    lines.append(table(["joint", "kind", "|force| [N]", "|moment| [N*m]", "not determined (left out)"], rrows))
    if r.notes:
        lines.append("")
        lines += [f"note: {n}" for n in r.notes]
    return "\n".join(lines)


def dynamics_csv(r: DynamicsResult, shown: str | None = None) -> str:
    x, u = _input_values(r, shown)
    header = [f"{r.input} [{u}]"] + [_effort_header(r, n) for n in r.inputs] + [
        "kinetic energy [J]", "potential energy [J]", "input power [W]"]
    header += [f"shaking {c} [{'N' if c[0] == 'f' else 'N*m'}]" for c in COMPONENTS]
    for name in r.reactions:
        header += [f"{name} {c} [{'N' if c[0] == 'f' else 'N*m'}]" for c in COMPONENTS]
    rows = []
    for k in range(len(r.values)):
        row = [x[k]] + [r.efforts[n][k] for n in r.inputs]
        row += [r.kinetic_energy[k], r.potential_energy[k], r.input_power[k]]
        row += list(r.shaking_force[k]) + list(r.shaking_moment[k])
        for w in r.reactions.values():
            row += list(w[k])
        rows.append([float(x) for x in row])
    return csv_text(header, rows)


def dynamics_plot(r: DynamicsResult, path: str, shown: str | None = None, title: str | None = None) -> None:
    """The input efforts against the input (one curve per actuator, the mean dashed) into a PNG."""
    plt = pyplot("--plot")
    x, u = _input_values(r, shown)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for name in r.inputs:
        y = r.efforts[name]
        ax.plot(x, y, label=f"{name}")
        if r.mean[name] is not None and len(x) > 1:
            ax.axhline(r.mean[name], linestyle="--", linewidth=0.8, color=ax.lines[-1].get_color(),
                       label=f"{name} mean")
    units = sorted({r.effort_units[n] for n in r.inputs})
    what = "torque" if units == ["N m"] else ("force" if units == ["N"] else "effort")
    ax.set_xlabel(f"{r.input} [{u}]")
    ax.set_ylabel(f"input {what} [{', '.join(x.replace(' ', '*') for x in units)}]")
    ax.grid(True, linewidth=0.5)
    ax.legend(loc="best", fontsize=8)
    rate = "rad/s" if r.unit == "rad" else "m/s"
    ax.set_title(title or f"{r.input} at {r.speed:.6g} {rate}")
    fig.tight_layout()
    try:
        write_figure(fig, path, dpi=100)
    finally:
        plt.close(fig)

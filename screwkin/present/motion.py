"""Absolute motion in the user's quantities as text and JSON: links, named points, loop joints
(the results of analysis/motion/links.py and the solutions of analysis/position/position.py)."""

from __future__ import annotations

import numpy as np

from ..tolerances import DEFAULT
from ..units import in_unit
from .tables import RateUnits, column_text, fmt_vec, table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.motion.links import MotionAlong
    from screwkin.analysis.motion.sweep import SweepResult

__all__ = ["along_text", "along_line", "strokes_text", "strokes_dict", "motion_rows_text", "links_rows", "links_table", "points_rows",
           "points_table", "motion_dict", "linkage_construction_text"]


def links_rows(links: dict, units: RateUnits = RateUnits()) -> tuple:
    """(title, headers, rows) of absolute link motion -- the moving links only, never the ground: a
    planar mechanism's angle, omega, alpha about the plane's normal (signed: counterclockwise positive),
    or a spatial one's omega and alpha vectors (world axes); the frame origin's velocity and acceleration
    as vectors in world axes (signed components, never magnitudes alone); rates in ``units`` (those typed,
    each column's unit in its header).  The one links table of ``solve``'s text and ``report``'s document."""
    planar = any(isinstance(m.get("omega", m.get("angle")), float) for m in links.values())
    rated = any("omega" in m for m in links.values())
    names = list(links)
    cols = []
    w, al, v, a = units.rate(False), units.acceleration(False), units.rate(True), units.acceleration(True)

    def column(key, unit: str):
        return column_text([in_unit(links[n][key], unit) for n in names])

    def vectors(key, unit: str) -> list:
        return [fmt_vec(in_unit(np.asarray(links[n][key], float), unit), 0) for n in names]

    if planar:
        head = ["link", "angle [deg]"] + ([f"omega [{w}]", f"alpha [{al}]"] if rated else [])
        cols.append(column_text([np.degrees(links[n].get("angle", np.nan)) for n in names], absolute=1e-9))
        if rated:
            cols += [column("omega", w), column("alpha", al)]
    else:
        head = ["link"] + ([f"omega x y z [{w}]", f"alpha x y z [{al}]"] if rated else ["position [m]"])
        if rated:
            cols += [vectors("omega", w), vectors("alpha", al)]
        else:
            cols.append([fmt_vec(links[n]["position"], 0) for n in names])
    if rated:
        head += [f"v origin x y z [{v}]", f"a origin x y z [{a}]"]
        cols += [vectors("velocity", v), vectors("acceleration", a)]
    along = planar and any("angle_along" in m for m in links.values())
    if along:  # which side of a ternary link its angle is (the Watt rocker's O4 -> C, not O4 -> B)
        head.append("angle of the line")
        cols.append([along_text(links[n].get("angle_along")) for n in names])
    rows = [[n] + [("" if c[i] == "nan" else c[i]) for c in cols] for i, n in enumerate(names)]
    title = (f"absolute link motion (angles from the ground's x axis{' to the line named' * along}; "
             "omega and alpha about the plane's normal, counterclockwise positive; vectors in world axes)" if planar
             else "absolute link motion (vectors in world axes)")
    return title, head, rows


def along_text(along: list) -> str:
    """The two points a link's angle is measured along (LinkAngles.along): ``rocker_joint to joint_F``."""
    return "" if not along else f"{along[0]} to {along[1]}" if along[1] != "x axis" else "its frame's x axis"


def along_line(links: dict) -> str:
    """One line naming the points each turning link's angle is measured along (a sweep's table), '' for none."""
    parts = [f"{n}: {along_text(m['angle_along'])}" for n, m in links.items() if m.get("angle_along")]
    return "each link's angle is that of the line " + "; ".join(parts) if parts else ""


def links_table(links: dict, units: RateUnits = RateUnits()) -> str:
    """:func:`links_rows` as a text table under its title."""
    title, head, rows = links_rows(links, units)
    return title + "\n" + table(head, rows)


def points_rows(points: dict, units: RateUnits = RateUnits()) -> tuple:
    """(title, headers, rows) of named points: position [m], velocity, acceleration (m/s, m/s^2 or the
    units typed), world axes (the one points table of ``solve``'s text and ``report``'s document)."""
    v, a = units.rate(True), units.acceleration(True)
    rows = []
    for name, m in points.items():
        row = [name, m["link"], fmt_vec(m["position"], 0)]
        if "velocity" in m:
            row += [fmt_vec(in_unit(np.asarray(m["velocity"], float), v), 0),
                    fmt_vec(in_unit(np.asarray(m["acceleration"], float), a), 0)]
        rows.append(row)
    head = ["point", "link", "position [m]"] + ([f"velocity [{v}]", f"acceleration [{a}]"]
                                                 if any("velocity" in m for m in points.values()) else [])
    return "points (world axes)", head, rows


def points_table(points: dict, units: RateUnits = RateUnits()) -> str:
    """:func:`points_rows` as a text table under its title."""
    title, head, rows = points_rows(points, units)
    return title + "\n" + table(head, rows)


def linkage_construction_text(d: dict) -> str:
    """The textbook's construction of a four-bar (diagonal z, its angles at the output pivot) or
    a slider-crank's transmission angle, in degrees."""
    mu = f"transmission angle mu = {np.degrees(d['transmission_angle']):.6g} deg"
    if d.get("diagonal") is None:
        return f"{d['kind']}: {mu}"
    angles = "" if d.get("alpha") is None else (f", at the output pivot alpha = {np.degrees(d['alpha']):.6g} deg "
                                                 f"(diagonal to output link), beta = {np.degrees(d['beta']):.6g} deg "
                                                 "(diagonal to ground link)")
    return f"four-bar: {mu}, diagonal z (crank tip to output pivot) = {d['diagonal']:.6g} m{angles}"


def motion_dict(m: MotionAlong) -> dict:
    """A sweep's analysis.motion.links.MotionAlong as JSON-ready lists, one entry per step."""
    return {"loop_joints": m.loop_joints, "loop_rates": m.loop_rates, "loop_accelerations": m.loop_accelerations,
            "links": m.links, "points": m.points}


def strokes_dict(strokes: list) -> list:
    return [{"coordinate": st.coordinate, "stroke": st.stroke, "low_at": st.low_at, "high_at": st.high_at,
             "time_ratio": st.time_ratio, "crank_angles": list(st.crank_angles) if st.crank_angles else None}
            for st in strokes]


def strokes_text(strokes: list, angular: bool) -> list:
    """A line per slider: its stroke, where its ends are reached, and the time ratio."""
    def at(x) -> str:
        return f"{np.degrees(x):.6g} deg" if angular else f"{1000 * x:.6g} mm"

    lines = []
    for st in strokes:
        line = (f"slider {st.coordinate}: stroke {1000 * st.stroke:.6g} mm (ends at input {at(st.low_at)} and "
                f"{at(st.high_at)})")
        if st.time_ratio is not None:
            line += (f"; time ratio {st.time_ratio:.6g} (crank turns {np.degrees(st.crank_angles[0]):.6g} deg "
                     f"forward, {np.degrees(st.crank_angles[1]):.6g} deg back)")
        lines.append(line)
    return lines


def motion_rows_text(res: SweepResult, motion: MotionAlong, rows: list, degrees: bool, units: RateUnits | None = None) -> str:
    """The sweep's absolute quantities at the rows shown: the input (in deg when typed so), each turning
    link's angle [deg] (with ``units``, the rate's units typed: its omega and alpha in them too), each
    slider (loop) coordinate [mm] and each point's position [mm]."""
    cols, head, turning = [], [], {}
    for name, m in motion.links.items():
        if "angle" in m and np.ptp(np.unwrap(m["angle"])) > DEFAULT.equal:  # the link turns
            turning[name] = m
            head.append(f"{name} [deg]")
            cols.append(column_text(np.degrees(np.asarray(m["angle"]))))
            if units is not None and "omega" in m:
                w, a = units.angular_rate, units.angular_acceleration
                head += [f"omega {name} [{w}]", f"alpha {name} [{a}]"]
                cols += [column_text(in_unit(np.asarray(m["omega"], float), w), absolute=1e-9),
                         column_text(in_unit(np.asarray(m["alpha"], float), a), absolute=1e-9)]
    for name, v in motion.loop_joints.items():
        angular = name in motion.angular_loop
        head.append(f"{name} (loop) [{'deg' if angular else 'mm'}]")
        cols.append(column_text(np.degrees(v) if angular else 1000 * np.asarray(v)))
    for name, p in motion.points.items():
        xy = 1000 * np.asarray(p["position"])
        head += [f"{name} x [mm]", f"{name} y [mm]"]
        cols += [column_text(xy[:, 0], absolute=1e-9), column_text(xy[:, 1], absolute=1e-9)]
    if not cols:
        return ""
    x = np.degrees(res.values) if degrees else np.asarray(res.values)
    unit = "deg" if degrees else res.unit
    body = [[f"{x[k]:.6g}"] + [c[k] for c in cols] for k in rows]
    along = along_line(turning)
    return (f"{along}\n" if along else "") + "absolute motion\n" + table([f"input [{unit}]"] + head, body)

"""Human-readable summaries of a checked cell (for `robomax check`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from rich.console import Group
from rich.table import Table

from robomax_py.spec import (
    Box,
    Capsule,
    CellSpec,
    Cylinder,
    MeshShape,
    ObjectSpec,
    Sphere,
)


def describe_shape(obj: ObjectSpec) -> str:
    s = obj.shape
    if isinstance(s, Box):
        return "box " + " x ".join(f"{v:.3f}" for v in s.extents) + " m"
    if isinstance(s, Cylinder):
        return f"cylinder r {s.radius:.3f} m, length {s.length:.3f} m"
    if isinstance(s, Sphere):
        return f"sphere r {s.radius:.3f} m"
    if isinstance(s, Capsule):
        return f"capsule r {s.radius:.3f} m, length {s.length:.3f} m"
    if isinstance(s, MeshShape):
        return f"mesh {s.path.name}"
    return type(s).__name__


def controller_summary(cell: CellSpec) -> str:
    """What the programs select on the robot's controller (`robot.controller`), in one line."""
    setup = cell.controller
    tool = setup.tool
    parts = [f"tool {tool.number} '{tool.name}'" + (" (on the controller)" if tool.existing else "")
             if tool is not None else f"tool 1 '{cell.tool.name}_tcp'"]
    if setup.frame is None:
        parts.append("targets in the robot base frame")
    else:
        f = setup.frame
        xyz = ", ".join(f"{v:.3f}" for v in f.T_world_frame[:3, 3])
        parts.append(f"user frame {f.frame.number} '{f.frame.name}' at [{xyz}] m in the cell")
    if setup.inputs:
        parts.append("inputs " + ", ".join(f"{i.signal} {i.number}" + (f" ({i.name})" if i.name else "")
                                           for i in setup.inputs))
    unmapped = [s for s in cell.signals if setup.input_of(s) is None]
    if unmapped:
        parts.append("signals without an input (KRL, TP, URScript need one): " + ", ".join(unmapped))
    registers = [f"{kind} {list(regs)}" for kind, regs in (("PR", setup.position_registers),
                                                            ("R", setup.numeric_registers)) if regs]
    if registers:
        parts.append("registers " + ", ".join(registers))
    if not cell.tending:
        parts.append(f"welds: {'the controller package' if setup.weld == 'package' else 'spot_weld calls'}")
    return "; ".join(parts)


def _process_line(cell: CellSpec) -> str:
    """The process's times and distances: a weld cell's weld time; a gripper cell's (tending, pick
    and place) close and open times instead, which it keeps as its stops' times at rest."""
    p = cell.process
    lines = f"approach {p.approach * 1000:.1f} mm, clearance {p.clearance * 1000:.1f} mm"
    if not cell.tending:
        return f"weld {p.weld_time:.2f} s, {lines}"
    at_rest = {spot.action: p.weld_time_of(spot) for seam in cell.seams for spot in seam.spots if spot.action}
    times = ", ".join(f"{action} {at_rest[action]:.2f} s" for action in ("grip", "release") if action in at_rest)
    return f"gripper {times}; {lines}"


def _software_limits(cell: CellSpec, robot: Any) -> str:
    """The joints `robot.joint_limits` narrows, as the cell file states them: 'joint_a6 [-185, 185] deg'."""
    assert cell.joint_limits is not None
    urdf = robot.model
    out = []
    for i, (name, (lo, hi), linear) in enumerate(zip(robot.joint_names, cell.joint_limits, robot.prismatic)):
        if lo <= urdf.lowerPositionLimit[i] + 1e-12 and hi >= urdf.upperPositionLimit[i] - 1e-12:
            continue                            # the URDF's range
        out.append(f"{name} [{lo:.3f}, {hi:.3f}] m" if linear else f"{name} [{np.degrees(lo):.1f}, {np.degrees(hi):.1f}] deg")
    return ", ".join(out) or "as the URDF's"


def cell_summary(cell: CellSpec, robot: Any) -> Group:
    """Robot, tool, objects, seams and spots of a cell, as rich tables."""
    head = Table.grid(padding=(0, 2))
    head.add_row("cell", f"{cell.name}  ({cell.source})")
    # As the cell file states it: deg, m for a prismatic joint (a track), marked.
    home = ", ".join(f"{v:.3f} m" if prismatic else f"{np.degrees(v):.1f}" for v, prismatic in zip(cell.home, robot.prismatic))
    head.add_row("robot", f"{robot.name}: {robot.dof} axes, IK {robot.ik_solver}, home [{home}] deg")
    if cell.joint_limits is not None:
        head.add_row("limits", f"software limits {_software_limits(cell, robot)}")
    tcp = cell.tool.T_flange_tcp[:3, 3]
    load = cell.tool.load
    weight = "" if load is None else f", {load.mass:g} kg at [{', '.join(f'{v:.3f}' for v in load.cog)}] m"
    head.add_row("tool", f"{cell.tool.name}: TCP at [{', '.join(f'{v:.3f}' for v in tcp)}] m from the flange{weight}")
    head.add_row("process", _process_line(cell))
    head.add_row("controller", controller_summary(cell))

    objects = Table(title="objects", title_justify="left")
    for col in ("name", "shape", "position (m)", "role"):
        objects.add_column(col)
    for obj in (*cell.objects, *cell.dynamic):
        role = "workpiece" if obj.workpiece else "obstacle"
        if obj.present is not None:
            role += " present " + ", ".join(f"[{a:g}, {b:g}] s" for a, b in obj.present)
        xyz = ", ".join(f"{v:.3f}" for v in obj.T_world_object[:3, 3])
        objects.add_row(obj.name, describe_shape(obj), f"[{xyz}]", role)

    seams = Table(title="seams", title_justify="left")
    for col in ("seam", "spots", "order", "alpha/beta (deg)", "gamma (deg)", "grid", "orientations"):
        seams.add_column(col)
    for seam in cell.seams:
        g0, g1 = (math.degrees(a) for a in seam.gamma_range)
        seams.add_row(
            seam.name, str(len(seam.spots)), "given" if seam.ordered else "free",
            f"±{math.degrees(seam.alpha_max):g} / ±{math.degrees(seam.beta_max):g}"
            + (", either side" if seam.either_side else ""),
            f"[{g0:g}, {g1:g}]", str(seam.grid), str(seam.grid ** 3 * (2 if seam.either_side else 1)),
        )
    if not cell.machines:
        return Group(head, objects, seams)
    machines = Table(title="machines", title_justify="left")
    for col in ("machine", "door", "closed (machining)", "stations"):
        machines.add_column(col)
    for m in cell.machines:
        windows = ", ".join(f"[{a:g}, {b:g}]" for a, b in m.windows[:3]) + (" ..." if len(m.windows) > 3 else "") + " s"
        visits = sorted({s.name.split("_", 1)[1] for seam in cell.seams for s in seam.spots if s.machine == m.name})
        machines.add_row(m.name, m.door, windows, ", ".join(visits))
    return Group(head, objects, seams, machines)

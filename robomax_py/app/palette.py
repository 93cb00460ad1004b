"""Colours shared by the 3-D preview and the cycle-time chart, so a kind looks the same in both.

Colours are 0xRRGGBB integers (what meshcat materials take); `hex_colour` gives matplotlib's form.
"""

from __future__ import annotations

from robomax_py.spec import ObjectSpec

# The robot's links: a saturated orange no cell object uses, so a screenshot test can find it.
ROBOT = 0xFF8C00
TOOL_BODY = 0x4A4F57
TOOL_TIPS = 0xB87333

# Cell objects by role (`object_role`).
ROLE_COLOURS: dict[str, int] = {
    "part": 0x3B7DD8,        # workpiece: the tips may touch it
    "clamp": 0xD62728,
    "fixture": 0x8C8C8C,     # tables, plates, posts: every other static object
    "dynamic": 0x9467BD,     # present only in time windows
}
DYNAMIC_OPACITY = 0.45

# The floor plate under the cell.
FLOOR = 0xD9DCE1

# Spot markers.
SPOT = 0xFFD400

# Voxel map (`preview --voxels`): the blocked leaves' centres.
VOXEL = 0x17BECF

# Trajectory phase kinds (timing.trajectory.SEGMENT_KINDS) for the TCP path and the Gantt bars.
PHASE_COLOURS: dict[str, int] = {
    "weld": 0xE41A1C,
    "approach": 0x2CA02C,
    "retract": 0x98DF8A,
    "move": 0x1F77B4,
    "blend": 0x1F77B4,
    "detour": 0xE377C2,
    "wait": 0x7F7F7F,
}


# What each colour means, in the words of the preview's legend: key -> (label, colour). Keys are the
# role names, the phase kinds drawn as path lines, and the other things drawn. Moves and blends share
# a colour and one entry; weld and wait phases draw no line (the robot stands at the spot / still).
LEGEND: dict[str, tuple[str, int]] = {
    "robot": ("robot", ROBOT),
    "tool_body": ("weld gun", TOOL_BODY),
    "tool_tips": ("gun tips", TOOL_TIPS),
    "part": ("workpiece", ROLE_COLOURS["part"]),
    "clamp": ("clamp", ROLE_COLOURS["clamp"]),
    "fixture": ("fixture (table, plate, post)", ROLE_COLOURS["fixture"]),
    "dynamic": ("moving obstacle (shown while present)", ROLE_COLOURS["dynamic"]),
    "spot": ("weld spot (triad: the gun's frame there)", SPOT),
    "approach": ("path: approach", PHASE_COLOURS["approach"]),
    "retract": ("path: retract", PHASE_COLOURS["retract"]),
    "move": ("path: move", PHASE_COLOURS["move"]),
    "detour": ("path: detour", PHASE_COLOURS["detour"]),
    "voxel": ("blocked voxel", VOXEL),
}
# The phase kinds each path legend entry stands for.
PATH_LEGEND_KINDS: dict[str, tuple[str, ...]] = {
    "approach": ("approach",), "retract": ("retract",), "move": ("move", "blend"), "detour": ("detour",),
}


def object_role(obj: ObjectSpec, dynamic: bool = False) -> str:
    """The role a cell object is drawn as: "part", "clamp", "fixture" or "dynamic".

    The cell format marks workpieces (`workpiece: true`) and dynamic objects; clamps are recognised
    by name (an object whose name contains "clamp"), every other static object is a fixture.
    """
    if dynamic:
        return "dynamic"
    if obj.workpiece:
        return "part"
    if "clamp" in obj.name.lower():
        return "clamp"
    return "fixture"


def phase_colour(kind: str) -> int:
    """Colour of a phase kind; an unknown kind is drawn like a move."""
    return PHASE_COLOURS.get(kind, PHASE_COLOURS["move"])


def hex_colour(colour: int) -> str:
    """0xRRGGBB -> '#rrggbb'."""
    return f"#{colour:06x}"


__all__ = [
    "DYNAMIC_OPACITY",
    "FLOOR",
    "LEGEND",
    "PATH_LEGEND_KINDS",
    "PHASE_COLOURS",
    "ROBOT",
    "ROLE_COLOURS",
    "SPOT",
    "TOOL_BODY",
    "TOOL_TIPS",
    "VOXEL",
    "hex_colour",
    "object_role",
    "phase_colour",
]

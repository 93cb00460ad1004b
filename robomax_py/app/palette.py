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

"""What changed in a cell while its program runs (`robomax replan --event`): the event grammar,
read without eval into checked values (SI), and a cell with the events applied.

One event per `--event`; times are seconds from the original program's start, lengths metres,
angles degrees (as in cell files):

    window:NAME=A-B[,C-D...]   NAME (a dynamic object, or a machine: its door) is present (a door:
                               closed) in exactly these windows; `window:NAME=none`: never again
    late:NAME=S                NAME's next opening comes S s late: the window in progress at the
                               replanning time T, or the next to begin after it, ends S s later
    appear:NAME SHAPE xyz=X,Y,Z [rpy=R,P,Y] [from=T1] [until=T2]
                               a new object, SHAPE one of box=X,Y,Z (full extents), sphere=R,
                               cylinder=R,L; present from T1 (default: T) until T2 (default: for
                               good)
    remove:NAME                the object NAME (static or dynamic, or a machine's door) is gone

Every number is a plain decimal (no nan, inf, hex or underscores) within stated bounds, every name
a cell identifier; anything else is an `EventError` naming the option, the event and the problem.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

from robomax_py.errors import EventError
from robomax_py.io.cell_file_values import MAX_WINDOW_S
from robomax_py.spec import (
    Box,
    CellSpec,
    Cylinder,
    MachineSpec,
    ObjectSpec,
    Shape,
    Sphere,
    frozen_array,
)
from robomax_py.transforms import pose_matrix
from robomax_py.units import deg_to_rad

__all__ = ["EVENT_GRAMMAR", "Appear", "Event", "Late", "Remove", "Windows", "apply_events", "parse_event"]

OPTION = "--event"
MAX_EVENT_CHARS = 500
MAX_WINDOWS = 1000
MAX_SIZE_M = 100.0          # an object's extent, radius or length
MAX_COORD_M = 1000.0        # |x|, |y|, |z| of an object's position
MAX_ANGLE_DEG = 360.0
_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d{1,3})?")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]{0,63}")

EVENT_GRAMMAR = ("window:NAME=A-B[,C-D...] | window:NAME=none | late:NAME=S | remove:NAME | "
                 "appear:NAME box=X,Y,Z|sphere=R|cylinder=R,L xyz=X,Y,Z [rpy=R,P,Y] [from=T1] [until=T2] "
                 "(s from program start, m, deg)")


@dataclass(frozen=True, slots=True)
class Windows:
    """`window:`: the object's windows (s from program start) replaced; () never present again."""

    text: str
    name: str                                   # the dynamic object (a machine's door by its own name)
    windows: tuple[tuple[float, float], ...]


@dataclass(frozen=True, slots=True)
class Late:
    """`late:`: the object's next window (in progress at the replanning time, or next) ends later."""

    text: str
    name: str
    seconds: float


@dataclass(frozen=True, slots=True, eq=False)
class Appear:
    """`appear:`: a new object, present over [start, end] (end inf: for good)."""

    text: str
    obj: ObjectSpec
    start: float | None                         # None: from the replanning time
    end: float


@dataclass(frozen=True, slots=True)
class Remove:
    """`remove:`: an object gone from the cell."""

    text: str
    name: str


Event = Windows | Late | Appear | Remove


def _fail(text: str, problem: str) -> EventError:
    shown = text if len(text) <= 80 else text[:77] + "..."
    return EventError(None, OPTION, f"{shown!r}: {problem}; events: {EVENT_GRAMMAR}")


def _number(text: str, value: str, what: str, lo: float, hi: float, open_lo: bool = False) -> float:
    if not _NUMBER.fullmatch(value):
        raise _fail(text, f"{what}: expected a plain decimal number, got {value!r}")
    x = float(value)
    if not math.isfinite(x) or x < lo or x > hi or (open_lo and x <= lo):
        bound = f"({lo:g}, {hi:g}]" if open_lo else f"[{lo:g}, {hi:g}]"
        raise _fail(text, f"{what}: {value} is outside {bound}")
    return x


def _numbers(text: str, value: str, what: str, count: int, lo: float, hi: float,
             open_lo: bool = False) -> list[float]:
    parts = value.split(",")
    if len(parts) != count:
        raise _fail(text, f"{what}: expected {count} comma-separated numbers, got {value!r}")
    return [_number(text, p.strip(), what, lo, hi, open_lo) for p in parts]


def _dynamic_names(cell: CellSpec) -> dict[str, str]:
    """Name a `window:` or `late:` event may use -> the dynamic object it means (machines by name)."""
    names = {d.name: d.name for d in cell.dynamic}
    names.update({m.name: m.door for m in cell.machines if m.door in names})
    return names


def _known(cell: CellSpec) -> str:
    names = sorted({*(d.name for d in cell.dynamic), *(m.name for m in cell.machines)})
    return ", ".join(names) or "none"


def _name(text: str, value: str) -> str:
    if not _NAME.fullmatch(value):
        raise _fail(text, f"expected a name (letters, digits, _ and -, at most 64), got {value!r}")
    return value


def parse_event(text: str, cell: CellSpec) -> Event:
    """One `--event` value, checked against the cell (names it knows, bounds); EventError otherwise."""
    if len(text) > MAX_EVENT_CHARS:
        raise _fail(text, f"longer than {MAX_EVENT_CHARS} characters")
    kind, sep, body = text.strip().partition(":")
    if not sep:
        raise _fail(text, "expected KIND:..., KIND one of window, late, appear, remove")
    kind = kind.strip().lower()
    if kind in ("window", "late"):
        name, eq, value = body.partition("=")
        name = _name(text, name.strip())
        if not eq:
            raise _fail(text, f"expected {kind}:NAME=...")
        dynamic = _dynamic_names(cell)
        if name not in dynamic:
            raise _fail(text, f"unknown dynamic object or machine {name!r} (the cell has: {_known(cell)})")
        if kind == "late":
            return Late(text, dynamic[name], _number(text, value.strip(), "late by (s)", 0.0, MAX_WINDOW_S, True))
        return Windows(text, dynamic[name], _windows(text, value.strip()))
    if kind == "remove":
        name = _name(text, body.strip())
        door = {m.name: m.door for m in cell.machines}.get(name, name)
        if door not in {o.name for o in (*cell.objects, *cell.dynamic)}:
            raise _fail(text, f"unknown object {name!r} (objects: "
                              f"{', '.join(o.name for o in (*cell.objects, *cell.dynamic))})")
        return Remove(text, door)
    if kind == "appear":
        return _appear(text, body, cell)
    raise _fail(text, f"unknown event kind {kind!r}")


def _windows(text: str, value: str) -> tuple[tuple[float, float], ...]:
    if value.lower() == "none":
        return ()
    parts = value.split(",")
    if len(parts) > MAX_WINDOWS:
        raise _fail(text, f"more than {MAX_WINDOWS} windows")
    out: list[tuple[float, float]] = []
    for part in parts:
        a, dash, b = part.strip().partition("-")
        if not dash:
            raise _fail(text, f"expected a window A-B (s), got {part.strip()!r}")
        w0 = _number(text, a.strip(), "window start (s)", 0.0, MAX_WINDOW_S)
        w1 = _number(text, b.strip(), "window end (s)", 0.0, MAX_WINDOW_S)
        if w1 <= w0:
            raise _fail(text, f"window {part.strip()}: its end is not after its start")
        if out and w0 <= out[-1][1]:
            raise _fail(text, f"window {part.strip()}: windows must be in time order and apart")
        out.append((w0, w1))
    return tuple(out)


def _appear(text: str, body: str, cell: CellSpec) -> Appear:
    words = body.split()
    if not words:
        raise _fail(text, "expected appear:NAME SHAPE xyz=X,Y,Z ...")
    name = _name(text, words[0])
    if name in {o.name for o in (*cell.objects, *cell.dynamic)}:
        raise _fail(text, f"the cell already has an object {name!r}")
    keys: dict[str, str] = {}
    for word in words[1:]:
        key, eq, value = word.partition("=")
        if not eq or key not in ("box", "sphere", "cylinder", "xyz", "rpy", "from", "until"):
            raise _fail(text, f"unexpected {word!r} (keys: box, sphere, cylinder, xyz, rpy, from, until)")
        if key in keys:
            raise _fail(text, f"{key} given twice")
        keys[key] = value
    shapes = [k for k in ("box", "sphere", "cylinder") if k in keys]
    if len(shapes) != 1:
        raise _fail(text, "expected exactly one shape: box=X,Y,Z, sphere=R or cylinder=R,L")
    shape: Shape
    if shapes[0] == "box":
        x, y, z = _numbers(text, keys["box"], "box (m)", 3, 0.0, MAX_SIZE_M, True)
        shape = Box((x, y, z))
    elif shapes[0] == "sphere":
        shape = Sphere(_number(text, keys["sphere"], "sphere radius (m)", 0.0, MAX_SIZE_M, True))
    else:
        r, length = _numbers(text, keys["cylinder"], "cylinder radius, length (m)", 2, 0.0, MAX_SIZE_M, True)
        shape = Cylinder(r, length)
    if "xyz" not in keys:
        raise _fail(text, "expected its position xyz=X,Y,Z (m)")
    xyz = _numbers(text, keys["xyz"], "xyz (m)", 3, -MAX_COORD_M, MAX_COORD_M)
    rpy = _numbers(text, keys["rpy"], "rpy (deg)", 3, -MAX_ANGLE_DEG, MAX_ANGLE_DEG) if "rpy" in keys else [0.0] * 3
    start = _number(text, keys["from"], "from (s)", 0.0, MAX_WINDOW_S) if "from" in keys else None
    end = _number(text, keys["until"], "until (s)", 0.0, MAX_WINDOW_S) if "until" in keys else math.inf
    if start is not None and end <= start:
        raise _fail(text, "until is not after from")
    T = frozen_array(pose_matrix(xyz, [deg_to_rad(a) for a in rpy]))
    return Appear(text, ObjectSpec(name=name, shape=shape, T_world_object=T), start, end)


def apply_events(cell: CellSpec, events: tuple[Event, ...], at: float) -> CellSpec:
    """The cell as the events leave it, in the original program's clock; `at` (s) is the
    replanning time (`late:` makes the window in progress then, or the next, end later; `appear:`
    without `from` is there from then on). EventError where an event cannot apply (a `late:` with
    no window left to delay)."""
    objects, dynamic = list(cell.objects), list(cell.dynamic)
    for ev in events:
        if isinstance(ev, Remove):
            objects = [o for o in objects if o.name != ev.name]
            dynamic = [d for d in dynamic if d.name != ev.name]
        elif isinstance(ev, Appear):
            start = at if ev.start is None else ev.start
            if start <= at and math.isinf(ev.end):
                objects.append(ev.obj)                     # there now and for good: a static obstacle
            else:
                dynamic.append(replace(ev.obj, present=((start, ev.end),)))
        else:
            k = next((i for i, d in enumerate(dynamic) if d.name == ev.name), None)
            if k is None:
                raise _fail(ev.text, f"{ev.name!r} was removed by an earlier event")
            d = dynamic[k]
            windows = d.present if d.present is not None else ((0.0, math.inf),)
            new = ev.windows if isinstance(ev, Windows) else _later(ev, windows, at)
            dynamic[k] = replace(d, present=new)
    names = {d.name: d.present for d in dynamic}
    machines = tuple(MachineSpec(m.name, m.door, names[m.door] or ()) if m.door in names else m
                     for m in cell.machines)
    return replace(cell, objects=tuple(objects), dynamic=tuple(dynamic), machines=machines)


def _later(ev: Late, windows: tuple[tuple[float, float], ...], at: float) -> tuple[tuple[float, float], ...]:
    """The windows with the first one ending at or after `at` ending ev.seconds later (merged with
    any it then reaches)."""
    k = next((i for i, (_, w1) in enumerate(windows) if w1 >= at), None)
    if k is None:
        raise _fail(ev.text, f"{ev.name} has no window in progress at or after t = {at:g} s: nothing to delay")
    w0, w1 = windows[k]
    out = [*windows[:k], (w0, w1 + ev.seconds)]
    for a, b in windows[k + 1:]:
        if a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return tuple(out)

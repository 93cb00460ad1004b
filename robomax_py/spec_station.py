"""A multi-robot station (docs/stations.md), checked, in SI units: its robots, each seen as an
ordinary single-robot cell (its model, tool, placement, home and controller, the station's shared
objects and seams), and which robots may weld which spot.

`io.station` builds it from a station file; the planners read it. Each robot's `cell` holds every
seam of the station; `robot_view` narrows it to the spots that robot welds, so the single-robot
pipeline, writers and verify run on it unchanged.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

from robomax_py.spec import CellSpec, Notice

# A spot of a station: (seam name, spot name), unique in the station.
SpotKey = tuple[str, str]


@dataclass(frozen=True, slots=True)
class IoRange:
    """Controller I/O numbers the planner may allocate interlock signals from, ends included."""

    first: int
    last: int

    @property
    def size(self) -> int:
        return self.last - self.first + 1

    def numbers(self) -> range:
        return range(self.first, self.last + 1)


@dataclass(frozen=True, slots=True, eq=False)
class StationRobot:
    """One robot of a station: its name there, its cell (all of the station's seams) and the I/O
    numbers its controller lends to interlocks (inputs it waits on, outputs it sets)."""

    name: str
    cell: CellSpec
    interlock_inputs: IoRange
    interlock_outputs: IoRange


@dataclass(frozen=True, slots=True)
class StationSpot:
    """A spot of the station and the robots that may weld it (the seam's and the spot's `robots`)."""

    seam: str
    spot: str
    robots: tuple[str, ...]

    @property
    def key(self) -> SpotKey:
        return (self.seam, self.spot)


@dataclass(frozen=True, slots=True, eq=False)
class StationSpec:
    """A station file, checked: robots in file order, spots in file order."""

    name: str
    source: Path
    digest: str                               # SHA-256 of the station file (and its includes)
    robots: tuple[StationRobot, ...]
    spots: tuple[StationSpot, ...]
    notices: tuple[Notice, ...] = ()

    @property
    def robot_names(self) -> tuple[str, ...]:
        return tuple(r.name for r in self.robots)

    def robot(self, name: str) -> StationRobot:
        """The robot called `name` (KeyError when the station has none of that name)."""
        for r in self.robots:
            if r.name == name:
                return r
        raise KeyError(name)

    @property
    def clearance(self) -> float:
        """The margin kept between robots, m: the station's `process.clearance` (the one section every
        robot's cell shares)."""
        return max(r.cell.process.clearance for r in self.robots)

    def allowed(self, robot: str) -> tuple[SpotKey, ...]:
        """The spots `robot` may weld, in file order."""
        return tuple(s.key for s in self.spots if robot in s.robots)


def robot_view(station: StationSpec, robot: str, spots: Collection[SpotKey]) -> CellSpec:
    """`robot`'s cell narrowed to `spots` (seams and spots keep their file order; a seam left without
    spots is dropped). With no spot the cell has no seam: a robot with nothing to weld plans nothing."""
    cell = station.robot(robot).cell
    wanted = set(spots)
    seams = []
    for seam in cell.seams:
        kept = tuple(s for s in seam.spots if (seam.name, s.name) in wanted)
        if kept:
            seams.append(dataclasses.replace(seam, spots=kept))
    return dataclasses.replace(cell, seams=tuple(seams))

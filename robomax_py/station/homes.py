"""Two robots of a station that touch where they stand at home: no plan can start (each program
starts and ends there), so the station is refused before anything is planned, naming both robots
and the pieces that touch. The check is the robot-robot check `robomax verify` replays stations
with (`world.robot_pairs`), at the same margin the plan keeps between robots (the clearance)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from robomax_py.robot import RobotModel
from robomax_py.spec_station import StationSpec
from robomax_py.world.robot_pairs import robot_body, robots_contact
from robomax_py.world.scene import Scene


@dataclass(frozen=True, slots=True)
class HomesTouching:
    """Robots `a` and `b` (the station's `robots[i]` and `robots[j]`) touch at home: `piece_a` of
    a within `margin_m` of `piece_b` of b."""

    a: str
    b: str
    i: int
    j: int
    piece_a: str
    piece_b: str
    margin_m: float

    def message(self) -> str:
        return (f"{self.a} and {self.b} touch where they stand at home ({self.a}'s {self.piece_a} within "
                f"{self.margin_m * 1000:.0f} mm of {self.b}'s {self.piece_b}): every program starts and ends "
                f"there; move a base (robots[{self.i}].base, robots[{self.j}].base) or a home "
                f"(robots[{self.i}].home, robots[{self.j}].home)")


def homes_touching(station: StationSpec, models: Mapping[str, RobotModel],
                   scenes: Mapping[str, Scene]) -> HomesTouching | None:
    """The first pair of robots, in the file's order, that touch at home; None when all stand apart."""
    margin = station.clearance
    bodies = [robot_body(r.name, models[r.name], scenes[r.name]) for r in station.robots]
    homes = [np.asarray(r.cell.home, dtype=float) for r in station.robots]
    for i, a in enumerate(bodies):
        for j in range(i + 1, len(bodies)):
            got = robots_contact(a, homes[i], bodies[j], homes[j], margin)
            if got is not None:
                return HomesTouching(a.name, bodies[j].name, i, j, got.piece_a, got.piece_b, margin)
    return None

"""Where each carried part is on a pick-and-place program's clock, for the preview.

One drawn object per transfer: it lies at its pick location from when it is there (the start, or
when an earlier transfer released a part there) until the gripper arrives, moves with the TCP until
the release is done, then lies at the place location until a later transfer picks it up there (that
transfer's object takes over). The holds are those the carried check uses (`plan.loads.holds`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.loads import holds
from robomax_py.plan.poses import nominal_rotation
from robomax_py.spec import CellSpec, PartSpec, SpotSpec


@dataclass(frozen=True, slots=True, eq=False)
class CarriedPart:
    """A transfer's part: shown from `t_shown` to `t_hidden`; held from `t_grip` to `t_release`."""

    name: str                   # the drawn object's name: <transfer>_<part>
    part: PartSpec
    T_pick: FloatArray          # (4, 4) world: the part where it is picked up
    T_place: FloatArray         # (4, 4) world: where it is put down
    t_shown: float
    t_grip: float
    t_release: float
    t_hidden: float

    def pose(self, t: float, T_world_tcp: FloatArray) -> FloatArray | None:
        """The part's world pose at program time t with the TCP at T_world_tcp; None: not shown."""
        if t < self.t_shown or t > self.t_hidden:
            return None
        if t < self.t_grip:
            return self.T_pick
        if t <= self.t_release:
            return T_world_tcp @ self.part.T_tcp_part
        return self.T_place


def carried_parts(cell: CellSpec, spots: list[dict[str, Any]]) -> list[CarriedPart]:
    """The transfers' parts of a pick-and-place program, from its stops (`plan.loads.holds`: the
    entries `seam`, `name`, `t_arrive`, `t_leave`); empty for other cells."""
    out: list[CarriedPart] = []
    for hold in holds(cell, spots):
        if hold.release is None:
            continue
        part = cell.part(hold.part)
        out.append(CarriedPart(f"{hold.grip.name.split('_')[0]}_{part.name}", part, _at(hold.grip) @ part.T_tcp_part,
                               _at(hold.release) @ part.T_tcp_part, 0.0, hold.t_start, hold.t_end, math.inf))
    # A location emptied by a pick and filled by a place: hand the object over at those times.
    for k, item in enumerate(out):
        before = [o for o in out[:k] if np.allclose(o.T_place[:3, 3], item.T_pick[:3, 3], atol=1e-6)]
        later = [o for o in out[k + 1:] if np.allclose(o.T_pick[:3, 3], item.T_place[:3, 3], atol=1e-6)]
        shown = before[-1].t_release if before else 0.0
        hidden = later[0].t_grip if later else math.inf
        out[k] = CarriedPart(item.name, item.part, item.T_pick, item.T_place, shown, item.t_grip, item.t_release,
                             hidden)
    return out


def _at(spot: SpotSpec) -> FloatArray:
    T = np.eye(4)
    T[:3, :3] = nominal_rotation(spot)
    T[:3, 3] = spot.xyz
    return T

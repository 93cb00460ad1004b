"""How much shorter than teach-in (the baseline here: `PlanOptions(baseline=True)`, the cell's
order, nominal orientation, first branch) can a plan of a cell get? Leg by leg (a script, not a test).

    python tests/bench/bench_ceiling.py [CELL] [--pairs 40]

Both plans (optimised and baseline) are split into their welds and their legs: a leg is all the
motion from rest at one stop (home or a spot) to rest at the next (retract, move or detour,
approach), which is what a choice of orientation and configuration at its two ends can change.
The legs of the two plans are matched by the two stops they join and compared. Then a ceiling:

- every straight leg between two spots is timed, with the real timing layer (fly-by junctions,
  as the planner times them), for the `--pairs` candidate pairs of its two spots that the
  planner's estimate ranks fastest among those whose straight move is free; the fastest of them,
  or of the two plans' own, is that leg's best;
- every other leg (from or to home, round a clamp) takes the faster of the two plans.

ceiling = welds + the sum of the legs' bests. It is what any plan visiting the spots in this order
could reach if it could pick every leg's best at once (it cannot: neighbouring legs share their
spot's configuration), so 1 - ceiling / baseline bounds the saving any choice of orientations and
configurations can make with these legs, measured with the same timing layer as both plans.
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import dataclass
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import (
    PlanOptions,
    PlanResult,
    plan_cell,
    resolved_options,
    weld_end,
)
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.junction import WeldEnd, time_junction
from robomax_py.plan.poses import orientation_grid
from robomax_py.program import as_written_joints, written_speed, written_tcp_speed
from robomax_py.spec import CellSpec
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
TARGET_SAVING = 0.15      # the goal: cycle time >= 15 % shorter than the baseline


@dataclass(frozen=True, slots=True)
class Leg:
    start: str                # stop names: "home" or a spot's name
    end: str
    kinds: tuple[str, ...]    # phase kinds in it (retract, move / detour, approach)
    seconds: float

    @property
    def key(self) -> frozenset[str]:
        return frozenset((self.start, self.end))


def legs_of(result: PlanResult) -> tuple[list[Leg], float, float]:
    """The plan's legs in order, its weld seconds and its approach + retract seconds."""
    assert result.trajectory is not None
    stops = ["home", *(s.name for s in result.spots), "home"]
    legs: list[Leg] = []
    kinds: list[str] = []
    seconds = weld = lines = 0.0
    for phase in result.trajectory.phases:
        if phase.kind == "weld":
            legs.append(Leg(stops[len(legs)], stops[len(legs) + 1], tuple(kinds), seconds))
            kinds, seconds = [], 0.0
            weld += phase.duration
            continue
        if not kinds or kinds[-1] != phase.kind:
            kinds.append(phase.kind)
        seconds += phase.duration
        if phase.kind in ("approach", "retract"):
            lines += phase.duration
    legs.append(Leg(stops[len(legs)], stops[len(legs) + 1], tuple(kinds), seconds))
    return legs, weld, lines


class LegTimer:
    """Times the straight leg between two candidates of neighbouring spots as the planner would."""

    def __init__(self, cell: CellSpec, robot, world: CollisionWorld, spots: list[SpotCandidates]) -> None:  # type: ignore[no-untyped-def]
        self.cell, self.robot, self.world, self.spots = cell, robot, world, spots
        self.options = resolved_options(cell, PlanOptions())
        self.grids = [orientation_grid(seam) for seam in cell.seams]

    def end(self, i: int, a: int) -> WeldEnd:
        return weld_end(self.cell, self.spots[i], a, self.grids)

    def best_straight(self, i: int, j: int, pairs: int) -> tuple[float, int]:
        """Fastest timed straight leg i -> j over the `pairs` best-estimated free candidate pairs;
        (seconds, pairs timed). The leg starts at the candidate's spot configuration (IK of the
        unrounded pose; the planner starts where the approach really ended, within 1e-6 rad)."""
        ci, cj, lim = self.spots[i], self.spots[j], self.robot.limits
        est = (ptp_time_estimate(ci.q_app[:, None, :], cj.q_app[None, :, :], lim)
               + ptp_time_estimate(ci.q_app, ci.q_spot, lim)[:, None]
               + ptp_time_estimate(cj.q_app, cj.q_spot, lim)[None, :])
        best, timed = float("inf"), 0
        o = self.options
        for flat in np.argsort(est, axis=None, kind="stable"):
            if timed >= pairs:
                break
            a, b = (int(x) for x in np.unravel_index(int(flat), est.shape))
            if not self.world.check_segment(ci.q_app[a], cj.q_app[b]).free:
                continue
            timed += 1
            junction = time_junction(
                self.robot, self.world, lim, ci.q_spot[a], as_written_joints(np.array([ci.q_app[a], cj.q_app[b]]), self.robot.prismatic),
                "move", f"{ci.name} -> {cj.name}", self.end(i, a), self.end(j, b),
                tcp_speed=written_tcp_speed(o.tcp_speed * o.speed), speed=written_speed(o.speed),
                jerk_limited=o.jerk_limited, flyby=o.blend)
            best = min(best, float(sum(s.duration for s in junction.segments)))
        return best, timed


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("cell", nargs="?", default=str(REFERENCE_CELL))
    parser.add_argument("--pairs", type=int, default=40, help="candidate pairs timed per straight leg")
    args = parser.parse_args()

    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    opt = plan_cell(cell, robot, PlanOptions())
    base = plan_cell(cell, robot, PlanOptions(baseline=True))
    assert opt.status == base.status == "planned", (opt.message, base.message)
    legs_o, weld, lines_o = legs_of(opt)
    legs_b, _weld_b, lines_b = legs_of(base)
    by_key_o = {leg.key: leg for leg in legs_o}
    if {leg.key for leg in legs_b} != set(by_key_o):
        print("the two plans join different pairs of stops; leg-by-leg comparison skipped")
        print(f"cycle: optimised {opt.cycle_time:.3f} s, baseline {base.cycle_time:.3f} s")
        return

    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots = [c for s in range(len(cell.seams)) for c in seam_candidates(cell, robot, world, s)[0]]
    index = {c.name: k for k, c in enumerate(spots)}
    timer = LegTimer(cell, robot, world, spots)

    print(f"cell {cell.name}: cycle optimised {opt.cycle_time:.3f} s, baseline {base.cycle_time:.3f} s "
          f"({100 * (1 - opt.cycle_time / base.cycle_time):.1f} % shorter)")
    print(f"shared: welds {weld:.3f} s; approach + retract lines {lines_o:.3f} s optimised, {lines_b:.3f} s baseline")
    print(f"\n{'leg (baseline order)':18s} {'kind':7s} {'baseline':>9s} {'optimised':>10s} {'best timed':>11s} "
          f"{'pairs':>6s} {'best':>7s}")
    t0 = time.process_time()
    ceiling = weld
    for leg in legs_b:
        other = by_key_o[leg.key]
        kind = "detour" if "detour" in leg.kinds or "detour" in other.kinds else "move"
        best = min(leg.seconds, other.seconds)
        measured, timed = float("nan"), 0
        if kind == "move" and "home" not in leg.key:
            measured, timed = timer.best_straight(index[leg.start], index[leg.end], args.pairs)
            best = min(best, measured)
        ceiling += best
        print(f"{leg.start + ' -> ' + leg.end:18s} {kind:7s} {leg.seconds:9.3f} {other.seconds:10.3f} "
              f"{measured:11.3f} {timed:6d} {best:7.3f}")
    saving = 1 - ceiling / base.cycle_time
    print(f"\nceiling (welds + every leg's best): {ceiling:.3f} s = {100 * saving:.1f} % shorter than the baseline "
          f"(target {100 * TARGET_SAVING:.0f} %: needs {base.cycle_time * (1 - TARGET_SAVING):.3f} s)")
    print(f"legs timed in {time.process_time() - t0:.1f} s CPU")


if __name__ == "__main__":
    main()

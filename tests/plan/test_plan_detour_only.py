"""Regression: a spot pair marked detour-only after one blocked straight probe, with no detour to be found.

Found while building cells/frame.yaml: `_Sequencer._probe_pairs` checks one straight move per spot pair
(the cheapest candidate pair) and marks the pair detour-only when it is blocked; when `_new_detour` then
found nothing, only that exact candidate pair was banned, the optimiser picked the next candidate pair
of the same spots, and the loop ended with "sequencing did not converge in N rounds" without naming a
spot. Here the small two-spot cell gets a "clamp" that blocks exactly the first probed move s7 -> s8
(a collision world that reports that one segment blocked) and a roadmap that finds nothing, while every
other straight move between s7 and s8 is free.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, graph, resolved_options
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.graph import Sequencer as _Sequencer
from robomax_py.plan.roadmap import Detour
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld, SegmentCheck
from robomax_py.world.scene import build_scene
from tests.conftest import SmallCell

JOINT_TOL_RAD = 1e-12


class _ClampedWorld:
    """The real collision world, except that one joint-space segment (either way) is blocked."""

    def __init__(self, world: CollisionWorld, q0: np.ndarray, q1: np.ndarray) -> None:
        self._world, self._q0, self._q1 = world, q0, q1
        self.blocked_asks = 0

    def _is_blocked(self, a: np.ndarray, b: np.ndarray) -> bool:
        def same(x: np.ndarray, y: np.ndarray) -> bool:
            return bool(np.allclose(x, y, atol=JOINT_TOL_RAD))

        return (same(a, self._q0) and same(b, self._q1)) or (same(a, self._q1) and same(b, self._q0))

    def check_segment(self, q0: np.ndarray, q1: np.ndarray, *args: Any, **kwargs: Any) -> SegmentCheck:
        if self._is_blocked(q0, q1):
            self.blocked_asks += 1
            return SegmentCheck(free=False, checks=1, states=2, narrow_phase_tests=1, s_contact=0.5)
        return self._world.check_segment(q0, q1, *args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)


class _NoRoadmap:
    def query(self, q0: np.ndarray, q1: np.ndarray) -> Detour | None:
        return None


def _setup(tmp_path: Path, write_small_cell: SmallCell) -> tuple[CellSpec, Any, CollisionWorld, list[SpotCandidates]]:
    cell = load_cell(write_small_cell(tmp_path, "detour_only"))
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots, _ = seam_candidates(cell, robot, world, 0)
    assert [c.name for c in spots] == ["s7", "s8"] and min(len(c) for c in spots) > 1
    return cell, robot, world, spots


def _sequencer(cell: CellSpec, robot: Any, world: Any, spots: list[SpotCandidates], rounds: int) -> _Sequencer:
    # No detour of any kind: no roadmap, no local C-space map (detours: roadmap), no lift below.
    options = resolved_options(cell, PlanOptions(max_rounds=rounds, detours="roadmap"))
    seq = _Sequencer(cell, robot, world, _NoRoadmap(), spots, options,  # type: ignore[arg-type]
                     np.random.default_rng(0))
    seq._lift_detour = lambda i, a, j, b: None  # type: ignore[method-assign]   # no way over the "clamp"
    seq._withdrawn_detour = lambda i, a, j, b: None  # type: ignore[method-assign]   # nor off the flange
    seq._open_side_detour = lambda i, a, j, b: None  # type: ignore[method-assign]   # nor round its open side
    return seq


def test_blocked_first_probe_with_free_alternative_plans_straight(tmp_path: Path, write_small_cell: SmallCell) -> None:
    cell, robot, world, spots = _setup(tmp_path, write_small_cell)
    probe = _sequencer(cell, robot, world, spots, 1)
    a, b = probe.probe_pair(0, 1)                                    # what `_probe_pairs` checks first
    clamped = _ClampedWorld(world, spots[0].q_app[a], spots[1].q_app[b])
    seq = _sequencer(cell, robot, clamped, spots, 80)
    outcome = seq.run()
    assert outcome.status == "found", outcome.message
    transitions = outcome.transitions
    assert clamped.blocked_asks >= 1                                 # the probe did hit the "clamp"
    between = [t for t in transitions if t.label in ("s7 -> s8", "s8 -> s7")]
    assert len(between) == 1 and between[0].kind == "move"
    assert (0, 1) not in seq.detour_only                              # the mark was lifted
    # The move the tour takes is not the blocked one.
    q_from, q_to = between[0].waypoints[0], between[0].waypoints[-1]
    assert not clamped._is_blocked(q_from, q_to)
    assert seq.rounds < 10


def test_non_convergence_names_the_moves(tmp_path: Path, write_small_cell: SmallCell,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """If the loop still runs out of rounds, the message names the moves left open (rounds without
    the repairs of one order between them, which would otherwise settle this cell within a round)."""
    monkeypatch.setattr(graph, "REPAIRS_PER_ROUND", 0)
    cell, robot, world, spots = _setup(tmp_path, write_small_cell)
    seq = _sequencer(cell, robot, _BlockEverything(world), spots, 2)
    outcome = seq.run()
    assert outcome.status == "not_converged" and outcome.tour is None
    assert "did not converge in 2 rounds" in outcome.message
    assert "home -> s7" in outcome.message or "home -> s8" in outcome.message, outcome.message


def test_nothing_free_is_disconnected_with_the_move_named(tmp_path: Path, write_small_cell: SmallCell) -> None:
    """Every move blocked, no detour: within a few rounds the cell is reported disconnected, naming
    the move nothing joins (the repairs of one order use up its candidate pairs)."""
    cell, robot, world, spots = _setup(tmp_path, write_small_cell)
    seq = _sequencer(cell, robot, _BlockEverything(world), spots, 80)
    outcome = seq.run()
    assert outcome.status == "disconnected" and outcome.tour is None, outcome.message
    assert "nothing known joins home -> s" in outcome.message, outcome.message
    assert seq.rounds <= 3


class _BlockEverything:
    """Every straight move between different configurations is blocked."""

    def __init__(self, world: CollisionWorld) -> None:
        self._world = world

    def check_segment(self, q0: np.ndarray, q1: np.ndarray, *args: Any, **kwargs: Any) -> SegmentCheck:
        return SegmentCheck(free=False, checks=1, states=2, narrow_phase_tests=1, s_contact=0.5)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)


def test_mostly_blocked_spot_pair_offers_only_verified_moves(tmp_path: Path, write_small_cell: SmallCell) -> None:
    """Past MAX_BLOCKED_STRAIGHT blocked straight moves between two spots, only the straight moves
    known to be free are offered (else the DP would pick an unchecked pair every round)."""
    from robomax_py.plan.graph import MAX_BLOCKED_STRAIGHT

    cell, robot, world, spots = _setup(tmp_path, write_small_cell)
    seq = _sequencer(cell, robot, world, spots, 1)
    pairs = [(a, b) for a in range(len(spots[0])) for b in range(len(spots[1]))]
    assert len(pairs) > MAX_BLOCKED_STRAIGHT + 1
    for a, b in pairs[:MAX_BLOCKED_STRAIGHT - 1]:
        seq._record_straight(0, a, 1, b, False)
    free_a, free_b = pairs[MAX_BLOCKED_STRAIGHT]
    seq._record_straight(0, free_a, 1, free_b, True)
    before = seq.full_cost(0, 1)
    assert np.isfinite(before).sum() == before.size - (MAX_BLOCKED_STRAIGHT - 1)     # unknown pairs still offered
    a, b = pairs[MAX_BLOCKED_STRAIGHT - 1]
    seq._record_straight(0, a, 1, b, False)
    after = seq.full_cost(0, 1)
    assert np.argwhere(np.isfinite(after)).tolist() == [[free_a, free_b]]
    assert after[free_a, free_b] == before[free_a, free_b]


def test_spot_pair_without_detours_is_given_up(tmp_path: Path, write_small_cell: SmallCell) -> None:
    """After MAX_FAILED_DETOURS failed detour searches a detour-only pair is unconnected: no
    candidate pair is offered, and the outcome names it instead of running out of rounds."""
    from robomax_py.plan.graph import MAX_FAILED_DETOURS

    cell, robot, world, spots = _setup(tmp_path, write_small_cell)
    seq = _sequencer(cell, robot, _BlockEverything(world), spots, 80)
    outcome = seq.run()
    assert outcome.status == "disconnected", outcome.message
    assert f"no detour found {MAX_FAILED_DETOURS} times between" in outcome.message
    assert seq.rounds < 80

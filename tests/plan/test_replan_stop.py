"""The stop rule of replanning (`plan.replan.stop_at`) on synthetic programs: rest, a move with a
cosine speed profile, an action at rest, another move, rest. For any replanning time the robot
comes to rest on the planned path (within 1e-9 rad of its polyline), within the joint limits,
completing an action in progress; and the continuation's cell keeps what is left, in its clock."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.app.replan import continuation_cell
from robomax_py.io.cell import load_cell
from robomax_py.io.cell_continuation import shifted_windows
from robomax_py.plan.replan import Action, ReplanInputError, stop_at
from robomax_py.robot import JointLimits, load_robot
from robomax_py.tolerances import DEFAULT as TOL

REPO = Path(__file__).resolve().parents[2]
ON_PATH_TOL_RAD = 1e-9
LIMIT_RTOL = 1e-6
REST_FRACTION = 1e-3     # the last step's speed, as a fraction of the velocity limit: at rest
DT_S = 0.004
V_MAX = np.array([2.0, 1.5])          # rad/s
A_MAX = np.array([6.0, 4.0])          # rad/s^2
LIMITS = JointLimits(lower=np.full(2, -10.0), upper=np.full(2, 10.0), velocity=V_MAX, acceleration=A_MAX,
                     jerk=np.full(2, 100.0))


def _move(qa: np.ndarray, qb: np.ndarray, d: float) -> np.ndarray:
    """Samples of a cosine-profile move qa -> qb over d s (peak speed pi/2 * |dq| / d)."""
    s = np.arange(0.0, d, DT_S) / d
    return qa + (qb - qa) * (0.5 - 0.5 * np.cos(np.pi * s))[:, None]


def _program(dq1: np.ndarray, dq2: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[Action]]:
    """rest 0.3 s, move 1, action 0.5 s at rest, move 2, rest 0.3 s; each move as slow as its limits need."""
    def duration(dq: np.ndarray) -> float:
        return float(max(np.max(np.pi / 2 * np.abs(dq) / V_MAX), np.max(np.sqrt(np.pi ** 2 / 2 * np.abs(dq) / A_MAX)),
                         0.1))

    q0 = np.zeros(2)
    q1, q2 = q0 + dq1, q0 + dq1 + dq2
    parts = [np.repeat(q0[None], round(0.3 / DT_S), axis=0), _move(q0, q1, duration(dq1)),
             np.repeat(q1[None], round(0.5 / DT_S), axis=0), _move(q1, q2, duration(dq2)),
             np.repeat(q2[None], round(0.3 / DT_S), axis=0)]
    q = np.vstack(parts)
    t = np.arange(len(q)) * DT_S
    i_arrive = len(parts[0]) + len(parts[1])
    action = Action("job", "a1", float(t[i_arrive]), float(t[i_arrive + len(parts[2]) - 1]))
    return t, q, [action]


def _distance_to_polyline(q: np.ndarray, path: np.ndarray) -> float:
    a, b = path[:-1], path[1:]
    ab = b - a
    lengths = np.sum(ab * ab, axis=1)
    s = np.clip(np.sum((q - a) * ab, axis=1) / np.where(lengths > 0, lengths, 1.0), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + s[:, None] * ab - q, axis=1)))


moves = st.lists(st.floats(-2.0, 2.0), min_size=2, max_size=2).map(np.array)


@settings(max_examples=60, deadline=None)
@given(moves, moves, st.floats(0.0, 1.0, exclude_max=True))
def test_the_robot_stops_on_its_path_at_rest_within_its_limits(dq1: np.ndarray, dq2: np.ndarray,
                                                               fraction: float) -> None:
    t, q, actions = _program(dq1, dq2)
    T = float(t[0] + fraction * (t[-1] - t[0]))
    stop = stop_at(t, q, actions, T, LIMITS)
    assert stop.t_stop >= T and stop.t[0] <= T
    assert _distance_to_polyline(stop.q, q) <= ON_PATH_TOL_RAD
    for qk in stop.q_motion:
        assert _distance_to_polyline(qk, q) <= ON_PATH_TOL_RAD
    a = actions[0]
    if a.t_arrive <= T < a.t_leave:
        assert stop.how == "action" and stop.t_stop == pytest.approx(a.t_leave)
    assert (a in stop.done) == (stop.t_stop >= a.t_leave - 1e-9)
    if stop.how == "slowed":
        v = np.abs(np.diff(stop.q_motion, axis=0)) / np.diff(stop.t)[:, None]
        assert np.all(v <= V_MAX * (1 + LIMIT_RTOL))
        assert np.all(v[-1] <= REST_FRACTION * V_MAX)           # at rest at the end
        # The program up to T, then the stop, measured as `verify` measures a program.
        # Program samples before the stop's first, which starts at T: a program sample at the same
        # instant to rounding (119 * 0.004 s against 0.476 s) would join the two by a step of 1e-17 s
        # and read an acceleration the motion never has.
        before = t < stop.t[0] - 1e-9
        ts = np.concatenate([t[before], stop.t])
        qs = np.vstack([q[before], stop.q_motion])
        dt = np.diff(ts)
        acc = np.abs(np.diff(np.diff(qs, axis=0) / dt[:, None], axis=0)) / ((dt[:-1] + dt[1:]) / 2)[:, None]
        assert np.all(acc <= A_MAX * (1 + TOL.acceleration_rtol))
    else:
        # Following the program to where it is at rest itself (an action's end, a wait, or at T).
        around = stop.t_stop + np.array([-2 * DT_S, 0.0, 2 * DT_S])
        q_around = np.stack([np.interp(around, t, q[:, j]) for j in range(2)], axis=1)
        assert min(np.max(np.abs(q_around[1] - q_around[0])), np.max(np.abs(q_around[2] - q_around[1]))) \
            <= ON_PATH_TOL_RAD


def test_a_moving_robot_slows_down_sooner_than_its_next_stop() -> None:
    t, q, actions = _program(np.array([1.5, -1.0]), np.array([-1.0, 1.0]))
    T = 0.3 + 0.4                           # mid-way through the first move, at speed
    stop = stop_at(t, q, actions, T, LIMITS)
    assert stop.how == "slowed"
    assert stop.t_path < actions[0].t_arrive
    assert not stop.done


def test_at_rest_it_stops_where_it_is_and_outside_the_program_is_refused() -> None:
    t, q, actions = _program(np.array([1.0, 1.0]), np.array([1.0, 1.0]))
    stop = stop_at(t, q, actions, 0.1, LIMITS)
    assert stop.how == "at rest" and stop.t_stop == pytest.approx(0.1)
    with pytest.raises(ReplanInputError, match="not inside the program"):
        stop_at(t, q, actions, float(t[-1]) + 1.0, LIMITS)
    with pytest.raises(ReplanInputError, match="not inside the program"):
        stop_at(t, q, actions, float("nan"), LIMITS)


def test_windows_move_to_the_continuations_clock() -> None:
    assert shifted_windows(((0.0, 9.0), (16.0, 25.0), (32.0, 41.0)), 20.0) == ((0.0, 5.0), (12.0, 21.0))
    assert shifted_windows(((0.0, 9.0),), 9.5) == ()


def test_the_continuations_cell_keeps_what_is_left() -> None:
    cell = load_cell(REPO / "cells" / "tending.yaml")
    spots = cell.seams[0].spots
    t, q, _ = _program(np.array([0.5, 0.5]), np.array([0.5, 0.5]))
    done = (Action("tending", spots[0].name, 1.0, 1.4), Action("tending", spots[1].name, 9.8, 10.1))
    stop = replace(stop_at(t, q, [], 0.1, LIMITS), t_stop=20.0, done=done, q=np.asarray(cell.home))
    robot = load_robot(cell.robot)
    cont = continuation_cell(cell, stop, "tending_from_20", robot)
    assert [s.name for s in cont.seams[0].spots] == [s.name for s in spots[2:]]
    assert cont.name == "tending_from_20" and cont.start is not None
    np.testing.assert_allclose(cont.start, cell.home, atol=1e-6)
    door = next(d for d in cont.dynamic if d.name == "cnc1_door")
    assert door.present == ((0.0, 5.0), (12.0, 21.0))

"""The two-step profile under the paper's constraint set (`timing.frenet_profile`), checked from
outside: its motion, sampled as positions every 5 ms and differentiated (`frenet_measure`, which
uses no curvature and no formula (7)), keeps v_max, the acceleration ellipse and the jerk ellipse
of the tangential and normal jerk; on a straight line it takes ruckig's exact jerk-limited time;
a path and its reverse take the same time.

Tolerances: the measured ellipses and components within 1e-3 of their limits (central differences
average the jerk over 20 ms and turn with the path over 10 ms; measured up to 0.9999 on the
warehouse legs, the profile keeping 1e-3 inside v_max on the bounds it follows); the profile no
more than 0.5 % slower than ruckig's exact optimum on a straight line (it keeps 0.01-0.1 % inside
its limits and its nodes are 1 cm apart; measured up to 0.38 %, on 0.4 m unloaded); a path and its
reverse within 0.5 % (measured 0.12 % and 0.22 %)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ruckig import InputParameter, Result, Ruckig, Trajectory

from robomax_py.spec import TcpLimits
from robomax_py.timing._common import TimingError
from robomax_py.timing.bezier_construct import EndPose, construct, straight
from robomax_py.timing.frenet_measure import frenet_series, peaks
from robomax_py.timing.frenet_profile import FrenetProfile, frenet_profile
from robomax_py.timing.quintic_chain import QuinticChain

UNLOADED = TcpLimits(v=1.5, a_T=2.0, a_R=4.0, j_T=8.0, j_R=10.0)      # the paper's table 1
LOADED = TcpLimits(v=1.5, a_T=0.5, a_R=1.0, j_T=2.0, j_R=2.5)
MEASURED_RTOL = 1e-3
STRAIGHT_RTOL = 5e-3
DT = 0.005


def _turn(k_meet: float = -0.7, d: tuple[float, float, float, float] = (0.6, 0.9, 0.5, 0.8)) -> QuinticChain:
    """A warehouse half loop: 3.5 m straight, a U-turn of two seven-step curves, 3.5 m straight."""
    meet = EndPose(0.5, 5.0, math.pi / 2, k_meet)
    return QuinticChain.of([straight([5.5, 3.5], [2.0, 3.5]), construct(EndPose(2.0, 3.5, math.pi), meet, d[0], d[1]),
                            construct(meet, EndPose(2.0, 6.5, 0.0), d[2], d[3]), straight([2.0, 6.5], [5.5, 6.5])])


def _measure(chain: QuinticChain, prof: FrenetProfile) -> object:
    t = np.arange(0.0, prof.duration + DT, DT)
    return frenet_series(t, chain.points(prof.at_time(t)[0]))


@pytest.mark.parametrize("limits", [LOADED, UNLOADED], ids=["loaded", "unloaded"])
@pytest.mark.parametrize("shape", [(-0.7, (0.6, 0.9, 0.5, 0.8)), (-0.2, (0.3, 1.0, 0.4, 0.5))], ids=["round", "square"])
def test_the_motion_keeps_the_papers_constraints_measured_from_its_positions(limits: TcpLimits, shape: tuple) -> None:
    chain = _turn(*shape)
    prof = frenet_profile(chain, limits)
    series = _measure(chain, prof)
    pk = peaks(series, limits)  # type: ignore[arg-type]
    assert pk.within(limits, MEASURED_RTOL), pk
    # At rest at both ends, with no acceleration: the start and stop are jerk-limited too.
    assert prof.v[0] == 0.0 and prof.v[-1] == 0.0 and prof.a[0] == 0.0 and prof.a[-1] == 0.0
    assert abs(series.v[0]) < 1e-3 and abs(series.v[-1]) < 1e-3   # type: ignore[attr-defined]
    # The jerk limit binds somewhere (the check is not vacuous) and the profile is below step 1's.
    assert pk.jerk_ellipse > 0.99
    assert np.all(prof.b <= prof.envelope * (1 + 1e-9) + 1e-12)


def _ruckig_time(distance: float, limits: TcpLimits) -> float:
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [distance], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [limits.v], [limits.a_T], [limits.j_T]
    traj = Trajectory(1)
    assert Ruckig(1).calculate(inp, traj) in (Result.Working, Result.Finished)
    return float(traj.duration)


@pytest.mark.parametrize("limits", [LOADED, UNLOADED], ids=["loaded", "unloaded"])
@pytest.mark.parametrize("distance", [0.4, 3.0, 8.0])
def test_on_a_straight_line_it_takes_the_exact_jerk_limited_time(limits: TcpLimits, distance: float) -> None:
    """On a straight line the constraint set is |a| <= a_Tmax, |j| <= j_Tmax, v <= v_max: the
    time-optimal motion is ruckig's (too short to cruise, cruising, cruising long)."""
    chain = QuinticChain.of([straight([0.0, 0.0], [distance * 0.6, distance * 0.8])])
    ours = frenet_profile(chain, limits).duration
    exact = _ruckig_time(distance, limits)
    assert exact * (1 - 1e-6) <= ours <= exact * (1 + STRAIGHT_RTOL), (ours, exact)


@pytest.mark.parametrize("limits", [LOADED, UNLOADED], ids=["loaded", "unloaded"])
def test_a_path_and_its_reverse_take_the_same_time(limits: TcpLimits) -> None:
    """The constraints do not change when time runs backwards, so neither does the least time; the
    sweep is one-sided, so the two profiles differ a little (within 0.5 %)."""
    chain = _turn()
    backwards = QuinticChain.of([c[::-1] for c in chain.control[::-1]])
    there, back = frenet_profile(chain, limits).duration, frenet_profile(backwards, limits).duration
    assert abs(there - back) <= 5e-3 * there


def test_bad_limits_are_refused() -> None:
    with pytest.raises(TimingError, match="finite and > 0"):
        frenet_profile(_turn(), TcpLimits(v=1.5, a_T=0.0, a_R=1.0, j_T=2.0, j_R=2.5))

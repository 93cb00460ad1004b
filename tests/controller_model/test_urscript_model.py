"""The URScript model on hand-written scripts with hand-computed poses (expected rotations from scipy)."""

from __future__ import annotations

import math

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from controller_model.common import FloatArray
from controller_model.urscript import run_urscript

POS_TOL_M = 1e-12
ROT_TOL = 1e-12


def _known(T: FloatArray | None) -> FloatArray:
    assert T is not None, "the model left this frame undefined"
    return T


def _pose(xyz_m: tuple[float, float, float], R: FloatArray) -> FloatArray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz_m
    return T


def _rotvec(v: tuple[float, float, float]) -> FloatArray:
    return np.asarray(Rotation.from_rotvec(v).as_matrix())


SCRIPT = f"""def cell():
  set_tcp(p[0.0, 0.0, 0.25, 0.0, 0.0, 0.0])
  global fixture = p[0.1, 0.0, 0.0, 0.0, 0.0, {math.pi / 2!r}]
  def spot_weld(n, weld_time):
    sleep(weld_time)
  end
  def wait_for_signal(n):
    while not get_standard_digital_in(n):
      sync()
    end
  end
  $ 1 "Robot Program"
  movej([0.0, -1.5707963267948966, 1.5707963267948966, 0.0, 0.0, 0.0], a=1.4, v=1.05)
  movel(pose_trans(fixture, p[0.01, 0.0, 0.0, 0.0, 0.0, 0.0]), a=1.2, v=0.25, r=0)
  spot_weld(1, 0.500)  # flange/s7
  movel(p[0.3, -0.2, 0.4, 1.2, -0.4, 0.9], 1.2, 0.25, 0, 0.005)
  movej(p[0.3, -0.2, 0.4, 0.0, {math.pi!r}, 0.0])
  sleep(0.25)
  while not get_standard_digital_in(3):
    sync()
  end
end
"""


def test_pose_trans_composes_the_frames() -> None:
    run = run_urscript(SCRIPT)
    assert run.clean, run.issues
    home, welded, blended, joint_move = run.motions
    # a feature 0.1 m along x turned 90 deg about z; 0.01 m along its x is (0.1, 0.01, 0) in the base
    assert_allclose(_known(welded.T_base_tcp), _pose((0.1, 0.01, 0.0), _rotvec((0, 0, math.pi / 2))), atol=POS_TOL_M)
    assert_allclose(_known(welded.T_flange_tcp), _pose((0.0, 0.0, 0.25), np.eye(3)), atol=POS_TOL_M)
    assert_allclose(_known(welded.T_base_user), np.eye(4), atol=POS_TOL_M)
    assert welded.kind == "linear" and welded.stops and welded.where.line == 14
    assert_allclose(home.joints_deg or (), (0.0, -90.0, 90.0, 0.0, 0.0, 0.0), atol=1e-12)
    assert home.kind == "joint" and home.T_base_tcp is None
    assert blended.blend == "r=0.005"          # the fifth positional argument is r
    assert joint_move.kind == "joint" and joint_move.joints_deg is None   # movej to a pose: IK on the controller


def test_rotation_vector_is_axis_times_angle() -> None:
    blended = run_urscript(SCRIPT).motions[2]
    assert_allclose(_known(blended.T_base_tcp)[:3, :3], _rotvec((1.2, -0.4, 0.9)), atol=ROT_TOL)
    assert_allclose(_known(blended.T_base_tcp)[:3, 3], [0.3, -0.2, 0.4], atol=POS_TOL_M)
    flipped = run_urscript(SCRIPT).motions[3]
    assert_allclose(_known(flipped.T_base_tcp)[:3, :3], np.diag([-1.0, 1.0, -1.0]), atol=1e-12)


def test_calls_and_waits_in_order() -> None:
    run = run_urscript(SCRIPT)
    kinds = [type(e).__name__ for e in run.events]
    assert kinds == ["Motion", "Motion", "Call", "Motion", "Motion", "Wait", "Wait"]
    (call,) = run.calls
    assert (call.name, call.args) == ("spot_weld", (1.0, 0.5))
    timed, signal = run.waits
    assert timed.seconds == 0.25
    assert (signal.input_number, signal.state) == (3, True)


def test_what_may_change_motion_is_reported() -> None:
    script = """def odd():
  set_tcp(p[0, 0, 0, 0, 0, 0])
  if get_standard_digital_in(1):
    movel(p[0.1, 0, 0, 0, 0, 0])
  end
  movel(pose_add(p[0.1, 0, 0, 0, 0, 0], p[0, 0, 0.1, 0, 0, 0]))
  movec(p[0.1, 0, 0, 0, 0, 0], p[0.2, 0, 0, 0, 0, 0])
  movel(target)
  def mover(n):
    movej([0, 0, 0, 0, 0, 0])
  end
  mover(1)
  thread t():
    movel(p[0.1, 0, 0, 0, 0, 0])
  end
  handle = run t()
  movel([0, 0, 0, 0, 0, 0])
  frobnicate(3)
end
"""
    run = run_urscript(script)
    by_line = {i.where.line: i.kind for i in run.issues}
    assert by_line == {3: "unsupported", 6: "unsupported", 7: "unsupported", 8: "undefined", 12: "unsupported",
                       16: "unsupported", 17: "unsupported", 18: "unsupported"}
    assert [c.name for c in run.calls] == ["mover"]


def test_the_flow_is_followed() -> None:
    """A call of a function without parameters runs it (its return back to the caller), halt()
    ends the program; a return under a condition is reported, not taken."""
    script = """def flow():
  set_tcp(p[0, 0, 0, 0, 0, 0])
  def mover():
    movej([0.1, 0, 0, 0, 0, 0])
    return
    movej([0.2, 0, 0, 0, 0, 0])
  end
  mover()
  if get_standard_digital_in(1):
    return
  end
  movej([0.3, 0, 0, 0, 0, 0])
  halt()
  movej([0.4, 0, 0, 0, 0, 0])
end
"""
    run = run_urscript(script)
    firsts = [m.joints_deg[0] for m in run.motions if m.joints_deg]
    assert_allclose(firsts, [math.degrees(0.1), math.degrees(0.3)])
    assert {i.where.line for i in run.unsupported} == {9, 10}
    assert run.stopped is not None and run.stopped.line == 13


def test_an_unknown_tcp_is_reported() -> None:
    run = run_urscript("movel(p[0.1, 0, 0, 0, 0, 0])\n")
    assert [(i.where.line, i.kind) for i in run.issues] == [(1, "undefined")]
    assert run.motions[0].T_flange_tcp is None
    run = run_urscript("movel(p[0.1, 0, 0, 0, 0, 0])\n", tcp=np.eye(4))
    assert run.clean


def test_a_def_called_at_the_top_level_runs_and_input_waits_read_both_ways() -> None:
    script = """def prog():
  set_tcp(p[0, 0, 0.1, 0, 0, 0])
  movel(p[0.5, 0, 0.5, 0, 0, 0], 1.2, 0.25, 0, 0)
  while (get_standard_digital_in(5) != True):
    sync()
  end
  while get_standard_digital_in(6) == True:
    sleep(0.01)
  end
end

prog()
"""
    run = run_urscript(script)
    assert run.clean, run.issues
    (m,) = run.motions
    assert m.where.line == 3 and m.stops
    assert [(w.input_number, w.state) for w in run.waits] == [(5, True), (6, False)]


def test_a_function_that_only_waits_for_its_input_is_that_wait() -> None:
    """A call of ``def wait_for_signal(n)`` whose body is a wait loop on input n waits for the
    input the call passes; a function doing more stays a call."""
    script = """def prog():
  def wait_for_signal(n):
    while not get_standard_digital_in(n):
      sync()
    end
  end
  def wait_and_tell(n):
    while not get_standard_digital_in(n):
      sync()
    end
    textmsg("in")
  end
  wait_for_signal(5)
  wait_and_tell(6)
end
"""
    run = run_urscript(script)
    assert run.clean, run.issues
    assert [(w.input_number, w.state, w.where.line) for w in run.waits] == [(5, True, 13)]
    assert [(c.name, c.args) for c in run.calls] == [("wait_and_tell", (6.0,))]

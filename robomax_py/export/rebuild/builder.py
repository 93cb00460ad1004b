"""`rebuild`, a program's motion built move by move (`_Builder`) the way the planner built it, with
its speeds, weld times, frames and interlocks checked."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import ProgramError
from robomax_py.export.mount import stated_as_if_upright
from robomax_py.export.plan_program import frame_defs
from robomax_py.export.rebuild.result import (
    CONFIG_TOL_RAD,
    FRAME_TOL_DEG,
    FRAME_TOL_MM,
    TCP_SPEED_TOL_MM_S,
    Problem,
    Rebuilt,
    SignalEvent,
    Span,
)
from robomax_py.export.rebuild.signals import (
    input_signal,
    output_signal,
    unmapped_output,
)
from robomax_py.export.rebuild.spline_block import SplinePoint, add_point, in_block
from robomax_py.export.rebuild.welds import (
    schedule_problem,
    schedule_time,
    weld_time_problem,
)
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.plan.waiting import clear_wait, signal_of
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
    from_frame,
    lin_pose,
    ptp_target,
)
from robomax_py.robot import RobotModel, mount_tool
from robomax_py.robot.ik import same_config
from robomax_py.robot.solve import brand_text_of, config_texts_near
from robomax_py.spec import CellSpec
from robomax_py.timing import (
    LinMoveError,
    Segment,
    TimingError,
    Trajectory,
    concatenate,
    dwell,
    resample,
)
from robomax_py.timing.chain import LinStep, PtpStep, Step, chain_path, time_chain
from robomax_py.world.scene import clamps_near


def rebuild(program: Program, cell: CellSpec, robot: RobotModel, file: Path | str,
            lines: tuple[int, ...] | None = None, brand: str | None = None,
            stored: tuple[FrameDef, ...] = (), controller: bool = False,
            station: frozenset[str] | None = None, T_base_world: FloatArray | None = None) -> Rebuilt:
    """Rebuild the motion; ProgramError when the program is not for this cell's robot.

    lines : the program line of each instruction (as the parser read them), for messages.
    brand : whose configuration data the program's Cartesian targets carry (docs/cell-files.md, "Controller programs");
        None: the robot's controller brand.
    stored : the frames the controller holds without the program stating them (the cell's tool
        and user frame, calibrated on the controller under the dialect's names). A LIN's target
        is composed as the controller composes it: the controller's base, the user frame in force,
        the target; the arm follows it with the tool in force (the program's, which the cell's
        gun then carries wherever that puts it).
    controller : the program is a controller's (a dialect of a brand): its configuration data count
        the joints as the controller does (robot.yaml `controller.joint_signs` / `joint_zeros_deg`),
        so the configuration a LIN ends in is stated from the controller's values of the joints the
        arm reaches (`solve.brand_text_of`) before it is compared with the written one. The
        program's joint targets are the URDF's here (`dialect.in_controller_joints` inverse).
    station : the signals the robots of a station set (a station replay); a wait for one of them,
        or for a signal the cell does not know, is then a `SignalEvent` that takes no time here.
        None: a lone program, whose waits for unknown signals are problems.
    T_base_world : (4, 4) the controller's world frame in its robot base (KUKA inv($ROBROOT),
        `export.controller_world`): what a user frame stated in the world frame (`FrameDef.in_world`)
        and the dialect's base 0 (KUKA $WORLD) are composed on. None: the robot base itself.
    A program that does not name its robot (a header with robot "" and no joints, as
    programs written by others) is taken to be for the cell's robot, joints in URDF order.
    """
    header = program.header
    if header.robot and header.robot != robot.name:
        raise ProgramError(file, "ROBOT", f"program is for robot {header.robot!r}, the cell uses {robot.name!r}")
    if header.joints and tuple(header.joints) != tuple(robot.joint_names):
        raise ProgramError(file, "AXES", f"expected {list(robot.joint_names)}, got {list(header.joints)}")
    builder = _Builder(cell, robot, brand or robot.controller.brand, {**_by_name(stored), **_by_name(program.frames)},
                       controller, station)
    builder.T_base_world = np.eye(4) if T_base_world is None else np.asarray(T_base_world, dtype=float)
    numbered = [(ins, None if lines is None else lines[i]) for i, ins in enumerate(program.instructions)]
    moves = [(ins, line) for ins, line in numbered if not isinstance(ins, Comment)]
    if not moves or not isinstance(moves[0][0], PtpMove):
        raise ProgramError(file, "BEGIN", "the first statement must be a joint move (PTP): where the robot starts")
    first = moves[0][0]
    if len(first.target_deg) != robot.dof:
        raise ProgramError(file, f"line {moves[0][1]}" if moves[0][1] else "BEGIN",
                           f"the first move gives {len(first.target_deg)} axis values, the robot has {robot.dof} joints")
    builder.start(ptp_target(first, robot.prismatic))
    for k in range(1, len(moves)):
        ins, builder.line = moves[k]
        if isinstance(ins, PtpMove) and len(ins.target_deg) != robot.dof:
            builder.problems.append(Problem(builder.t, "format", f"a joint move gives {len(ins.target_deg)} axis "
                                            f"values, the robot has {robot.dof} joints", builder.line))
            return builder.result(None)
        if not builder.add(ins, moves[k + 1][0] if k + 1 < len(moves) else None, k):
            return builder.result(None)
    if builder.pending:
        builder.problems.append(Problem(builder.t, "flyby", "the program ends flying by: the last move has FLYBY",
                                        builder.line))
        if not builder.flush():
            return builder.result(None)
    traj = resample(concatenate(builder.segments))
    # Spot times from the trajectory's own weld phases (exactly on its samples), in program order.
    welds: dict[str, list[Any]] = {}
    for phase in traj.phases_of("weld"):
        welds.setdefault(phase.label, []).append(phase)
    for spot in builder.spots:
        phase = welds[f"{spot['seam']}/{spot['name']}"].pop(0)
        spot["t_arrive"], spot["t_leave"] = float(phase.t_start), float(phase.t_end)
    return builder.result(traj)


def _by_name(frames: tuple[FrameDef, ...]) -> dict[tuple[str, str], FrameDef]:
    return {(f.kind, f.name): f for f in frames}


class _Builder:
    def __init__(self, cell: CellSpec, robot: RobotModel, brand: str,
                 frames: dict[tuple[str, str], FrameDef], controller: bool = False,
                 station: frozenset[str] | None = None) -> None:
        self.cell, self.robot, self.brand = cell, robot, brand
        self.controller = controller                       # configuration data in the controller's joint values
        self.frames = frames
        self.T_base_world = np.eye(4)                      # the controller's world in its robot base
        self.reported: set[tuple[str, str]] = set()        # frames whose difference is reported
        self.tools: list[FloatArray | None] = []           # of the pending steps: the tool of each LIN
        self.segments: list[Segment] = []
        self.spots: list[dict[str, Any]] = []
        self.problems: list[Problem] = []
        self.pending: list[Step] = []
        self.configs: list[tuple[int, str]] = []          # (index in pending, CONFIG) of pending LINs
        self.q = np.zeros(robot.dof)
        self.t = 0.0
        self.last_config = ""
        self.line: int | None = None                      # of the statement being added
        self.step_lines: list[int | None] = []            # of the pending steps
        self.spans: list[Span] = []
        self.waited: set[str] = set()                      # clamp inputs waited for so far
        self.after_action = False                          # a weld or gripper action since the last move
        self.block: list[SplinePoint] = []                 # the spline block being read
        self.station = station                             # signals the robots of a station set
        self.events: list[SignalEvent] = []

    def _problem(self, kind: str, detail: str | None) -> None:
        if detail is not None:
            self.problems.append(Problem(self.t, kind, detail, self.line))

    def result(self, traj: Trajectory | None) -> Rebuilt:
        return Rebuilt(traj, self.spots, self.problems, self.spans, self.events)

    def start(self, q: FloatArray) -> None:
        self.q = np.asarray(q, dtype=float)
        self.segments.append(dwell(self.q, 0.0, kind="wait", label="start"))

    def add(self, ins: Any, following: Any, index: int) -> bool:
        if in_block(ins):
            return add_point(self, ins, following, index)
        if isinstance(ins, (PtpMove, LinMove)):
            kind = self._kind(ins, following)
            self.after_action = False
            ins = self._check_speeds(ins, kind)
            tool = None
            if isinstance(ins, LinMove):
                resolved = self._frames_of(ins)
                if resolved is None:
                    return False
                tool, base = resolved
                step: Step = self._lin_step(ins, base, kind, index)
            else:
                step = self._step(ins, following, index)
            self.pending.append(step)
            self.tools.append(tool)
            self.step_lines.append(self.line)
            if isinstance(ins, LinMove):
                self.configs.append((len(self.pending) - 1, ins.config))
            return True if ins.flies else self.flush()
        if self.pending:
            what = "weld" if isinstance(ins, Spot) else ("gripper action" if isinstance(ins, Gripper) else
                                                         "output" if isinstance(ins, SetSignal) else "wait")
            self.problems.append(Problem(self.t, "flyby", f"a {what} after a move that flies by (blended): the robot "
                                                          "is not at rest", self.line))
            if not self.flush():
                return False
        if isinstance(ins, (Spot, Gripper)):
            label = f"{ins.seam}/{ins.name}"
            if isinstance(ins, Spot):
                self._check_interlocks(ins, label)
                if not ins.package:
                    self._problem("weld", weld_time_problem(self.cell, ins, label))
                if ins.package:
                    self._problem("weld", schedule_problem(self.cell, ins, label))
                    seconds, problem = schedule_time(self.cell, ins)
                    self._problem("weld", problem)
                    ins = dataclasses.replace(ins, time_s=seconds)
            self._check_action(ins, label)
            self.segments.append(dwell(self.q, ins.time_s, kind="weld", label=label))
            config = self.last_config or self.config_text(self.q)
            self.spots.append({"seam": ins.seam, "name": ins.name, "t_arrive": self.t,
                               "t_leave": self.t + ins.time_s, "config": config, "line": self.line,
                               "brand": self.brand, "controller": self.controller})
            self.spans.append(Span(self.t, self.t + ins.time_s, self.line))
            self.t += ins.time_s
            self.after_action = True
        elif isinstance(ins, Wait):
            self._hold(ins.seconds, "WAIT")
        elif isinstance(ins, WaitFor):
            self._wait_for(ins)
        elif isinstance(ins, SetSignal):
            self._set_signal(ins)
        return True

    def _kind(self, ins: PtpMove | LinMove, following: Any) -> str:
        """What a move is: a line into a weld or gripper action is its approach, the first move
        after one its retract, any other line a detour's (`planner.detour_moves: lin`)."""
        if not isinstance(ins, LinMove):
            return "move"
        if isinstance(following, (Spot, Gripper)):
            return "approach"
        return "retract" if self.after_action else "detour"

    def _check_speeds(self, ins: PtpMove | LinMove, kind: str = "move") -> PtpMove | LinMove:
        """A speed or acceleration above the axes' limits, or a line faster than the cell's line
        speed (a detour's line: its detour line speed), is reported; the move is rebuilt at most
        at the axes' limits."""
        what = "joint move" if isinstance(ins, PtpMove) else "line"
        fractions = {"acceleration": ins.accel}
        if isinstance(ins, PtpMove):
            fractions["speed"] = ins.speed
        over = {k: v for k, v in fractions.items() if v > 1.0 + 1e-9}
        for k, v in over.items():
            self.problems.append(Problem(self.t, "speed", f"a {what} at {100.0 * v:.0f} % of the axes' {k}: above 100 %",
                                         self.line))
        if isinstance(ins, LinMove):
            planner = self.cell.planner
            detour = kind == "detour"
            limit_mm_s = 1000.0 * (planner.detour_tcp_speed if detour else planner.tcp_speed)
            if ins.speed_mm_s > limit_mm_s + TCP_SPEED_TOL_MM_S:
                name, key = ("detour line speed", "detour_tcp_speed") if detour else ("line speed", "tcp_speed")
                self.problems.append(Problem(self.t, "speed", f"a line at {ins.speed_mm_s:.1f} mm/s, faster than the "
                                                              f"cell's {name} {limit_mm_s:.1f} mm/s (planner.{key})",
                                             self.line))
        if not over:
            return ins
        if isinstance(ins, PtpMove):
            return dataclasses.replace(ins, speed=min(ins.speed, 1.0), accel=min(ins.accel, 1.0))
        return dataclasses.replace(ins, accel=min(ins.accel, 1.0))

    def _step(self, ins: PtpMove, following: Any, index: int) -> Step:
        return PtpStep(ptp_target(ins, self.robot.prismatic), speed=ins.speed, accel=ins.accel, flyby=math.radians(ins.flyby),
                       kind="move", label=ins.comment or f"statement {index + 1}", flyby_tcp=ins.flyby_mm / 1000.0)

    def _lin_step(self, ins: LinMove, T_ctrl_frame: FloatArray, kind: str, index: int) -> Step:
        # The controller's composition: its robot base (in the URDF root), the user frame, the target.
        T = from_frame(self.robot.controller.T_root_base, T_ctrl_frame @ lin_pose(ins))
        return LinStep(T, ins.speed_mm_s / 1000.0, None, flyby=math.radians(ins.flyby), kind=kind,
                       label=ins.comment or f"statement {index + 1}", flyby_tcp=ins.flyby_mm / 1000.0, accel=ins.accel)

    def _frames_of(self, ins: LinMove) -> tuple[FloatArray, FloatArray] | None:
        """The tool (flange -> TCP) and the user frame (in the controller's robot base) a LIN is
        executed with; None when the program leaves one unknown (reported)."""
        out = []
        for kind, name in (("tool", ins.tool), ("base", ins.base)):
            what = "tool" if kind == "tool" else "user frame (base)"
            if name == NULL_FRAME:
                # No tool: the flange; no user frame: the dialect's base 0 (KUKA $WORLD, which
                # the integrator's $ROBROOT places away from the robot base on a tilted mount).
                out.append(np.eye(4) if kind == "tool" else self._on_world(name, np.eye(4)))
                continue
            if name == UNSET_FRAME:
                self.problems.append(Problem(self.t, "frame", f"the program selects no {what} before this move: the "
                                                              f"controller would use whichever was left active", self.line))
                return None
            frame = self.frames.get((kind, name))
            if frame is None:
                known = ", ".join(sorted(n for k, n in self.frames if k == kind)) or "none"
                self.problems.append(Problem(self.t, "frame", f"the move uses {what} {name}, whose value neither the "
                                                              f"program nor the cell gives (known: {known})", self.line))
                return None
            out.append(self._on_world(name, frame.pose) if frame.in_world else frame.pose)
        tool, base = out
        self._check_tool(ins.tool, tool)
        return tool, base

    def _on_world(self, name: str, T_world_frame: FloatArray) -> FloatArray:
        """A user frame stated in the controller's world frame, in the robot base; one stated as if
        a tilted robot's $ROBROOT were $WORLD is reported once (`mount.stated_as_if_upright`)."""
        if ("base", name) not in self.reported:
            self.reported.add(("base", name))
            base = frame_defs(cell_program_frames(self.cell))[1:]
            found = stated_as_if_upright(name, self.T_base_world, T_world_frame, base[0].pose if base else np.eye(4),
                                         FRAME_TOL_MM, FRAME_TOL_DEG)
            if found:
                self.problems.append(Problem(self.t, "frame", found, self.line))
        out: FloatArray = self.T_base_world @ T_world_frame
        return out

    def _check_tool(self, name: str, T_flange_tcp: FloatArray) -> None:
        """A tool unlike the cell's gun is reported once: the arm follows the program's tool, and
        the gun's real TCP lands elsewhere."""
        if ("tool", name) in self.reported:
            return
        self.reported.add(("tool", name))
        d_mm, d_deg = _frame_difference(T_flange_tcp, np.asarray(self.robot.T_flange_tcp))
        if d_mm > FRAME_TOL_MM or d_deg > FRAME_TOL_DEG:
            self.problems.append(Problem(self.t, "frame", f"tool {name or 'flange (null frame)'} is not the cell's tool "
                                                          f"({d_mm:.3f} mm, {d_deg:.4f} deg off): the arm follows the "
                                                          "program's tool", self.line))

    def flush(self) -> bool:
        """Build and time the pending chain; False when it cannot be built (reported)."""
        steps, configs, lines, tools = self.pending, self.configs, self.step_lines, self.tools
        self.pending, self.configs, self.step_lines, self.tools = [], [], [], []
        robot = self._chain_robot([t for t in tools if t is not None], lines)
        try:
            path = chain_path(robot, self.q, steps)
            segments = time_chain(path, steps, robot.limits)
        except LinMoveError as exc:
            self.problems.append(Problem(self.t, "lin", f"a LIN move cannot be followed: {exc}", lines[-1]))
            return False
        except TimingError as exc:
            if "does not move" in str(exc):
                return True
            self.problems.append(Problem(self.t, "timing", f"the motion cannot be timed: {exc}", lines[-1]))
            return False
        t_end = self.t
        for k, seg in enumerate(segments):
            self.spans.append(Span(t_end, t_end + seg.duration, lines[k] if k < len(lines) else None))
            t_end += seg.duration
            for idx, written in configs:
                if idx == k:
                    actual = self.config_text(path.targets[k])
                    self.last_config = actual
                    nearby = config_texts_near(self.robot, path.targets[k], self.brand, CONFIG_TOL_RAD,
                                               self.controller)
                    if written and not any(same_config(written, text) for text in nearby):
                        self.problems.append(Problem(t_end, "config", f"LIN ends in {actual}, the program says {written}",
                                                     lines[k]))
        self.segments.extend(segments)
        self.t = t_end
        self.q = np.asarray(segments[-1].q[-1], dtype=float)
        return True

    def _chain_robot(self, tools: list[FloatArray], lines: list[int | None]) -> RobotModel:
        """The arm with the tool the chain's lines are stated with mounted (the controller follows
        its own TCP); the cell's when they state the cell's exactly."""
        if not tools or np.array_equal(tools[0], self.robot.T_flange_tcp):
            return self.robot
        if any(not np.array_equal(t, tools[0]) for t in tools[1:]):
            self.problems.append(Problem(self.t, "frame", "the tool changes between blended moves: the chain is "
                                                          "followed with the first line's tool", lines[-1]))
        return mount_tool(self.robot, tools[0])

    def config_text(self, q: FloatArray) -> str:
        """The configuration data, in the program's brand, of joint values q."""
        return brand_text_of(self.robot, q, self.brand, self.controller)

    def _hold(self, seconds: float, label: str) -> None:
        if seconds > 0:
            self.segments.append(dwell(self.q, seconds, kind="wait", label=label))
            self.spans.append(Span(self.t, self.t + seconds, self.line))
            self.t += seconds

    def _check_action(self, ins: Spot | Gripper, label: str) -> None:
        """A tending station gets its gripper action, a weld spot a weld."""
        from robomax_py.program import identifier

        seam = next((s for s in self.cell.seams if identifier(s.name) == ins.seam), None)
        spec = next((p for p in seam.spots if identifier(p.name) == ins.name), None) if seam else None
        if spec is None:
            return
        said = ins.action if isinstance(ins, Gripper) else None
        if said != spec.action:
            want = f"a {spec.action}" if spec.action else "a weld"
            got = f"a {said}" if said else "a weld"
            self.problems.append(Problem(self.t, "action", f"{label}: the program does {got}, the cell asks for {want}",
                                         self.line))

    def _check_interlocks(self, spot: Spot, label: str) -> None:
        """A weld near a clamp with an input comes after waiting for that input."""
        from robomax_py.program import identifier

        seam = next((s for s in self.cell.seams if identifier(s.name) == spot.seam), None)
        spec = next((p for p in seam.spots if identifier(p.name) == spot.name), None) if seam else None
        if spec is None:
            return
        for obj in clamps_near(self.cell, spec.xyz):
            if identifier(str(obj.signal)) not in self.waited:
                self.problems.append(Problem(self.t, "interlock", f"{label} is welded near clamp {obj.name} before "
                                                                  f"waiting for its input {obj.signal}", self.line))
                self.waited.add(identifier(str(obj.signal)))

    def _set_signal(self, ins: SetSignal) -> None:
        """An output set at rest: recorded for the station replay (no time here)."""
        signal = output_signal(self.cell, ins)
        if signal is None:
            self.problems.append(Problem(self.t, "signal", unmapped_output(self.cell, ins), self.line))
            return
        self.events.append(SignalEvent(self.t, "set", signal, ins.value, self.line))

    def _wait_for(self, ins: WaitFor) -> None:
        """A wait on an input number means the cell signal mapped to that number (the controller
        knows numbers, not names); a wait by name, the cell signal of that name."""
        from robomax_py.program import identifier

        signal = input_signal(self.cell, ins)
        if signal is None:
            known = ", ".join(f"{i.number} ({i.signal})" for i in self.cell.controller.inputs) or "none mapped"
            self.problems.append(Problem(self.t, "signal", f"the program waits for input {ins.number}, which the "
                                                           f"cell maps to no signal (robot.controller.inputs: {known})",
                                         self.line))
            return
        if any(obj.signal and identifier(obj.signal) == signal for obj in self.cell.objects) and \
                (self.station is None or signal not in self.station):
            self.waited.add(signal)           # a clamp input: set once the clamp is closed, no time planned
            return
        obstacle = next((d for d in self.cell.dynamic if signal_of(identifier(d.name), d.door) == signal), None)
        if obstacle is None and self.station is not None:
            # Another robot's signal (or one that no robot sets: the replay says it waits forever).
            self.events.append(SignalEvent(self.t, "wait", signal, True, self.line))
            return
        if obstacle is None:
            known = ", ".join([*(signal_of(identifier(d.name), d.door) for d in self.cell.dynamic),
                               *(identifier(str(o.signal)) for o in self.cell.objects if o.signal)]) or "none in this cell"
            self.problems.append(Problem(self.t, "signal", f"WAIT FOR {signal}: unknown signal (known: {known})",
                                         self.line))
            return
        self._hold(clear_wait(self.t, obstacle.present or ()), f"WAIT FOR {signal}")


def _frame_difference(A: FloatArray, B: FloatArray) -> tuple[float, float]:
    """Distance between two frames' origins (mm) and the angle of the rotation between them (deg)."""
    d_mm = 1000.0 * float(np.linalg.norm(A[:3, 3] - B[:3, 3]))
    cos = (float(np.trace(A[:3, :3].T @ B[:3, :3])) - 1.0) / 2.0
    return d_mm, math.degrees(math.acos(max(-1.0, min(1.0, cos))))

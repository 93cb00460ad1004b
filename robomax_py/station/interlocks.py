"""The interlocks of a coordinated station as the programs state them: per ordered zone a signal
`<leader>_<zone>_clear`, an output of the robot that leaves the zone first and an input of the one
that waits, each numbered from its controller's `interlock_io` range; and each robot's controller
setup with those signals added."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

from robomax_py.errors import CellFileError
from robomax_py.spec import ControllerInput, ControllerOutput, ControllerSetup
from robomax_py.spec_station import StationSpec
from robomax_py.station.coordinate import Interlock


@dataclass(frozen=True, slots=True)
class StationInterlock:
    """One interlock as written: `waiter` waits (input `input`) at its own time `wait_at` for
    `signal`, which `leader` sets (output `output`) at its own time `signal_at`; `zone` names the
    shared zone, its spans the times each robot spends in it on its own clock (s)."""

    zone: str
    leader: str
    waiter: str
    signal: str
    output: int
    input: int
    signal_at: float
    wait_at: float
    leader_span: tuple[float, float]
    waiter_span: tuple[float, float]


def allocate(station: StationSpec, interlocks: Sequence[Interlock]) -> tuple[StationInterlock, ...]:
    """Signals and I/O numbers for each interlock, in order; CellFileError naming the robot's
    `interlock_io` key when its range is too small for the interlocks the plan needs."""
    index = {r.name: i for i, r in enumerate(station.robots)}
    outputs = {r.name: iter(r.interlock_outputs.numbers()) for r in station.robots}
    inputs = {r.name: iter(r.interlock_inputs.numbers()) for r in station.robots}
    need_out = {r.name: sum(1 for x in interlocks if x.leader == r.name) for r in station.robots}
    need_in = {r.name: sum(1 for x in interlocks if x.waiter == r.name) for r in station.robots}
    out = []
    for k, lock in enumerate(interlocks):
        zone = f"z{k + 1}"
        numbers = []
        for robot, pool, kind, need in ((lock.leader, outputs, "outputs", need_out), (lock.waiter, inputs, "inputs", need_in)):
            number = next(pool[robot], None)
            if number is None:
                r = station.robots[index[robot]]
                rng = r.interlock_outputs if kind == "outputs" else r.interlock_inputs
                raise CellFileError(station.source, f"robots[{index[robot]}].controller.interlock_io.{kind}",
                                    f"[{rng.first}, {rng.last}] holds {rng.size} number(s); the plan needs "
                                    f"{need[robot]} interlock {kind} on {robot}: widen the range")
            numbers.append(number)
        out.append(StationInterlock(zone, lock.leader, lock.waiter, f"{lock.leader}_{zone}_clear", numbers[0],
                                    numbers[1], lock.signal_at, lock.wait_at, lock.leader_span, lock.waiter_span))
    return tuple(out)


def with_interlock_io(setup: ControllerSetup, robot: str, interlocks: Sequence[StationInterlock]) -> ControllerSetup:
    """A robot's controller setup with its interlock inputs (waited for) and outputs (set) added."""
    inputs = tuple(ControllerInput(x.signal, x.input) for x in interlocks if x.waiter == robot)
    outputs = tuple(ControllerOutput(x.signal, x.output) for x in interlocks if x.leader == robot)
    return dataclasses.replace(setup, inputs=setup.inputs + inputs, outputs=setup.outputs + outputs)

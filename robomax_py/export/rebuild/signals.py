"""The cell's signal a program's output statement sets, read through `robot.controller.outputs`."""

from __future__ import annotations

from robomax_py.program import SetSignal
from robomax_py.spec import CellSpec


def output_signal(cell: CellSpec, ins: SetSignal) -> str | None:
    """The signal an output statement sets: by number, the signal `robot.controller.outputs` maps
    to that output (None: none); by name, the signal whose controller name (RAPID) or own name it is."""
    from robomax_py.export.plan_program import identifier

    outputs = cell.controller.outputs
    if ins.number is not None:
        mapped = next((o for o in outputs if o.number == ins.number), None)
        return None if mapped is None else identifier(mapped.signal)
    named = next((o for o in outputs if o.name and o.name.lower() == ins.signal.lower()), None)
    return identifier(named.signal if named is not None else ins.signal)

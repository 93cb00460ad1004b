"""The cell's signal a program's wait or output statement names, read as the controller reads it:
through `robot.controller.inputs` / `.outputs` by number, by the I/O configuration's name (RAPID),
else by the signal's own name."""

from __future__ import annotations

from robomax_py.program import SetSignal, WaitFor
from robomax_py.spec import CellSpec


def output_signal(cell: CellSpec, ins: SetSignal) -> str | None:
    """The signal an output statement sets: by number, the signal `robot.controller.outputs` maps
    to that output (None: none); by name, the signal whose controller name (RAPID) or own name it is."""
    from robomax_py.program import identifier

    outputs = cell.controller.outputs
    if ins.number is not None:
        mapped = next((o for o in outputs if o.number == ins.number), None)
        return None if mapped is None else identifier(mapped.signal)
    named = next((o for o in outputs if o.name and o.name.lower() == ins.signal.lower()), None)
    return identifier(named.signal if named is not None else ins.signal)


def unmapped_output(cell: CellSpec, ins: SetSignal) -> str:
    """The problem of an output number the cell maps to no signal."""
    known = ", ".join(f"{o.number} ({o.signal})" for o in cell.controller.outputs) or "none mapped"
    return f"the program sets output {ins.number}, which the cell maps to no signal (robot.controller.outputs: {known})"


def input_signal(cell: CellSpec, ins: WaitFor) -> str | None:
    """The signal a wait means: on an input number, the cell signal mapped to that number (the
    controller knows numbers, not names; None: none); by name, the cell signal whose controller
    name it is, else the name itself."""
    from robomax_py.program import identifier

    inputs = cell.controller.inputs
    if ins.number is not None:
        mapped = next((i for i in inputs if i.number == ins.number), None)
        return None if mapped is None else identifier(mapped.signal)
    named = next((i for i in inputs if i.name and i.name.lower() == ins.signal.lower()), None)
    return identifier(named.signal) if named is not None else ins.signal

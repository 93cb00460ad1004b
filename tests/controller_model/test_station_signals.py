"""The other half of a wait between robots: a digital output switched, in each vendor's terms, as
the controller models read it (KRL ``$OUT[k]=TRUE`` and a ``SIGNAL`` name, after an advance-run stop
unless ``CONTINUE``; RAPID ``SetDO``/``Set``/``Reset``; FANUC ``DO[k]=ON``; URScript
``set_standard_digital_out(n, b)``, n in 0..7), and robomax's interlocked programs (the goldens of
tests/export/test_set_signal.py) judged by them: the waits and outputs in the order and on the
numbers robomax's own readers give back, every output set at rest."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from controller_model.common import Motion, ProgramRun, SetOutput, Wait
from controller_model.fanuc import run_fanuc
from controller_model.krl import run_krl
from controller_model.rapid import run_rapid
from controller_model.urscript import run_urscript

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "station_interlock"


def _run(ext: str) -> ProgramRun:
    text = (GOLDEN / f"station_r1{ext}").read_bytes().decode("utf-8")
    if ext == ".src":
        dat = (GOLDEN / "station_r1.dat").read_text(encoding="utf-8")
        return run_krl(text, dat, src_name="station_r1.src", dat_name="station_r1.dat")
    if ext == ".mod":
        return run_rapid({"station_r1.mod": text}, signals={"r2_z1_clear": 2}, outputs={"doR1Z1": 3})
    if ext == ".ls":
        return run_fanuc(text, name="station_r1.ls")
    return run_urscript(text, name="station_r1.script")


def _signals(run: ProgramRun) -> list[tuple[str, int | None, bool | None]]:
    return [("wait", e.input_number, e.state) if isinstance(e, Wait) else ("set", e.output_number, e.state)
            for e in run.events if isinstance(e, (Wait, SetOutput)) and not (isinstance(e, Wait) and e.seconds)]


@pytest.mark.parametrize("ext", [".src", ".mod", ".ls", ".script"])
def test_robomax_interlocked_program_as_the_controller_runs_it(ext: str) -> None:
    run = _run(ext)
    assert not run.issues, run.issues
    assert _signals(run) == [("wait", 2, True), ("set", 3, True), ("set", 3, False)]
    outputs = [e for e in run.events if isinstance(e, SetOutput)]
    assert all(o.after_stop for o in outputs)
    # The output follows the move home, at rest: the last motion before it stops exactly.
    before = [e for e in run.events[:run.events.index(outputs[0])] if isinstance(e, Motion)]
    assert before and before[-1].stops


def test_the_models_agree_with_robomax_readers(tmp_path: Path, write_small_cell: Any) -> None:
    from robomax_py.export import DIALECTS
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.program import SetSignal, WaitFor

    robot = load_cell_robot(load_cell(write_small_cell(tmp_path)))
    for name, ext in (("krl", ".src"), ("rapid", ".mod"), ("fanuc", ".ls"), ("urscript", ".script")):
        text = (GOLDEN / f"station_r1{ext}").read_bytes().decode("utf-8")
        parsed = DIALECTS[name].parse({ext: text}, f"station_r1{ext}", robot).program
        ours = [(("wait", i.number, True) if isinstance(i, WaitFor) else ("set", i.number, i.value))
                for i in parsed.instructions if isinstance(i, (WaitFor, SetSignal))]
        model = _signals(_run(ext))
        if name == "rapid":      # RAPID names its signals; the I/O configuration numbers them
            model = [(k, None, v) for k, _, v in model]
        assert ours == model, name


@pytest.mark.parametrize(("text", "want"), [
    ("$OUT[7]=TRUE", [(7, True, True)]),
    ("CONTINUE\n$OUT[7]=FALSE", [(7, False, False)]),
    ("SIGNAL clear $OUT[9]\nclear=TRUE", [(9, True, True)]),
])
def test_krl_outputs(text: str, want: list[tuple[int, bool, bool]]) -> None:
    run = run_krl(f"DEF p( )\n{text}\nEND\n")
    assert [(e.output_number, e.state, e.after_stop) for e in run.events if isinstance(e, SetOutput)] == want


def test_rapid_set_reset_and_delayed_set() -> None:
    run = run_rapid([("MODULE m\n  PROC main()\n    Set do1;\n    Reset do1;\n    SetDO \\SDelay:=0.2, do1, 1;\n"
                     "  ENDPROC\nENDMODULE\n")], outputs={"do1": 4})
    assert [(e.output_number, e.state) for e in run.events if isinstance(e, SetOutput)] == [(4, True), (4, False)]
    assert any("SetDO" in i.text for i in run.issues)


def test_urscript_output_beyond_the_standard_eight_is_an_alarm() -> None:
    run = run_urscript("def p():\n  set_standard_digital_out(8, True)\nend\n")
    assert not [e for e in run.events if isinstance(e, SetOutput)]
    assert [i.kind for i in run.issues] == ["alarm"]

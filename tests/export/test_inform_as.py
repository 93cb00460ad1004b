"""Yaskawa INFORM and Kawasaki AS: the pose and configuration conversions against second
implementations written from the definitions, published programs read, the dialect registry's
plug-ins, and the brands without a dialect."""

from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from robomax_py import export
from robomax_py.errors import ExportError
from robomax_py.export import inform, kawasaki_as
from robomax_py.export.dialect import Dialect
from robomax_py.program import LinMove, PtpMove, Spot, Wait, WaitFor, lin_pose
from robomax_py.robot.ik.config import ConfigIndicator, yaskawa_rconf

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
angle = st.floats(-179.9, 179.9)


@settings(max_examples=50, deadline=None)
@given(angle, st.floats(0.5, 179.5), angle)
def test_oat_is_intrinsic_zyz(o: float, a: float, t: float) -> None:
    """AS's O, A, T: rotations about z, the new y, the new z (scipy's intrinsic 'ZYZ')."""
    want = Rotation.from_euler("ZYZ", [o, a, t], degrees=True).as_matrix()
    np.testing.assert_allclose(kawasaki_as.matrix_from_oat((o, a, t)), want, atol=1e-12)
    back = kawasaki_as.oat_from_matrix(want)
    np.testing.assert_allclose(Rotation.from_euler("ZYZ", back, degrees=True).as_matrix(), want, atol=1e-9)


@settings(max_examples=50, deadline=None)
@given(angle, st.floats(-89.0, 89.0), angle)
def test_zyx_to_oat_and_back_is_the_same_rotation(a: float, b: float, c: float) -> None:
    """A LIN's ZYX angles written as OAT name the same rotation within 3e-7 rad (three angles
    rounded to 1e-5 deg), well inside verify's orientation tolerance (1e-6 rad), so that a spot the
    planner put at its tolerance's edge stays inside it; away from ZYX's gimbal lock (|B| < 60 deg)
    they read back as the very ZYX angles written."""
    zyx = LinMove((0, 0, 0), (a, b, c)).zyx_deg            # the program's values (4 decimals)
    R = lin_pose(LinMove((0, 0, 0), zyx))[:3, :3]
    oat = kawasaki_as.oat_from_zyx(zyx)
    off = Rotation.from_euler("ZYZ", oat, degrees=True) * Rotation.from_matrix(R).inv()
    assert off.magnitude() < 3e-7
    back = kawasaki_as.zyx_from_oat(oat)
    np.testing.assert_allclose(Rotation.from_euler("ZYX", back, degrees=True).as_matrix(), R, atol=5e-7)
    if abs(zyx[1]) < 60:
        assert LinMove((0, 0, 0), back).zyx_deg == zyx


def test_as_states_each_motions_acceleration(robot6) -> None:  # type: ignore[no-untyped-def]
    """A motion slower to accelerate (a part in the gripper) is written with ACCEL and DECEL for
    that motion only; the reader takes the smaller share, and ALWAYS for every later motion."""
    from robomax_py.program import Header, Program

    header = Header("c", "kr16", "gun", 1.0, tuple(f"a{i}" for i in range(6)))
    moves = (PtpMove((10, -80, 90, 5, 40, 0), 0.5, 0.36), LinMove((100, 20, 30), (0, 0, 0), "", 250.0, accel=0.42,
                                                                   tool="", base=""),
             PtpMove((0, -90, 90, 0, 30, 0), 1.0))
    files = kawasaki_as.write(Program("c", header, (), moves), robot6)
    assert "ACCEL 36.0\r\n  DECEL 36.0\r\n" in files[".as"] and files[".as"].count("ACCEL ") == 2
    got = kawasaki_as.parse(files, "x", robot6).program.instructions
    assert [m.accel for m in got] == [0.36, 0.42, 1.0]      # type: ignore[union-attr]
    text = (".PROGRAM p()\r\n  ACCEL 80 ALWAYS\r\n  DECEL 50\r\n  JMOVE #[0,0,0,0,0,0]\r\n"
            "  JMOVE #[1,0,0,0,0,0]\r\n.END\r\n")
    got = kawasaki_as.parse({".as": text}, "p.as", robot6).program.instructions
    assert [m.accel for m in got] == [0.5, 0.8]             # type: ignore[union-attr]


def _rconf_by_table(q_deg: list[float], overhead: bool, elbow: bool) -> str:
    """RCONF from the manuals' words (DX100 156191-1CD §4.1, NX100 149235-1CD §3.9), by the
    table's ranges written out: Flip for R in (-90, 90], (270, 360], (-360, -270]."""
    r = q_deg[3]
    flip = -90 < r <= 90 or 270 < r <= 360 or -360 < r <= -270
    over = [0 if -180 < v <= 180 else 1 for v in (q_deg[3], q_deg[5], q_deg[0])]
    return ",".join(map(str, [0 if flip else 1, 0 if elbow else 1, 1 if overhead else 0, *over, 0, 0]))


def test_as_states_a_blend_to_the_micrometre(robot6) -> None:  # type: ignore[no-untyped-def]
    """ACCURACY's distance with three decimals, as RoboDK's Kawasaki post writes it: a blend of a
    big arm rounded to 0.1 mm came back 0.02 deg off the plan at the wrist."""
    from robomax_py.program import Header, Program

    header = Header("c", "kr16", "gun", 1.0, tuple(f"a{i}" for i in range(6)))
    moves = (PtpMove((10, -80, 90, 5, 40, 0), 0.5, flyby_mm=33.2449), PtpMove((0, -90, 90, 0, 30, 0), 1.0))
    files = kawasaki_as.write(Program("c", header, (), moves), robot6)
    assert "ACCURACY 33.245\r\n" in files[".as"]
    got = kawasaki_as.parse(files, "x", robot6).program.instructions
    assert [m.flyby_mm for m in got] == [33.245, 0.0]      # type: ignore[union-attr]


@settings(max_examples=80, deadline=None)
@given(st.lists(st.floats(-359.0, 359.0), min_size=6, max_size=6), st.booleans(), st.booleans())
def test_rconf_against_the_table(q_deg: list[float], overhead: bool, elbow: bool) -> None:
    ind = ConfigIndicator(overhead * 1 + elbow * 2, 0)
    assert yaskawa_rconf(ind, np.radians(q_deg)) == _rconf_by_table(q_deg, overhead, elbow)


@pytest.fixture(scope="module")
def robot6():  # type: ignore[no-untyped-def]
    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import load_robot
    from tests.conftest import with_pulses

    root = Path(__file__).resolve().parents[2] / "robomax_py" / "robots" / "kr16" / "robot.yaml"
    return with_pulses(load_robot(load_robot_spec(root)))


def test_robodk_inform_job_reads(robot6) -> None:  # type: ignore[no-untyped-def]
    """RoboDK's published MH5F job: pulse MOVJ, Cartesian MOVL with RCONF, TIMER, WAIT IN#; the
    SETE / SETTOOL / MSG / DOUT lines are reported, CALL JOB and PAUSE not simulated."""
    text = (DATA / "robodk_PROGRAM.JBI").read_text()
    parsed = inform.parse({".jbi": text}, "PROGRAM.JBI", robot6)
    moves = [i for i in parsed.program.instructions if isinstance(i, (PtpMove, LinMove))]
    assert isinstance(moves[0], PtpMove) and isinstance(moves[2], LinMove)
    assert moves[2].position_mm == (418.57, 147.321, 251.179) and moves[2].zyx_deg == (0.0, 23.13, -180.0)
    assert moves[2].config == "0,0,0,0,0,0,0,0" and moves[2].speed_mm_s == 200.0 and moves[2].tool == "TOOL[9]"
    assert Wait(0.5) in parsed.program.instructions
    assert any(kind == "flow" for _, kind, _ in parsed.problems)        # PAUSE ends the verified cycle
    assert any("SETTOOL" in text for _, text in parsed.ignored)


def test_robodk_as_program_reads(robot6) -> None:  # type: ignore[no-untyped-def]
    text = (DATA / "robodk_Kawasaki.pg").read_text()
    parsed = kawasaki_as.parse({".pg": text}, "Kawasaki.pg", robot6)
    ins = parsed.program.instructions
    assert isinstance(ins[0], PtpMove) and ins[0].target_deg[0] == 5.8852
    # Its LMOVE comes before any SPEED ... MM/S: a linear speed in % of a maximum, not simulated.
    assert "LMOVE TRANS(372.971" in parsed.ignored[0][1]
    assert parsed.program.frames == ()          # BASE TRANS(0,...) selects an unnamed base; no LIN uses it
    assert any(isinstance(i, WaitFor) and i.number == 5 for i in ins)
    assert any("C1MOVE" in t for _, t in parsed.ignored)


def test_as_and_inform_read_back_what_they_write(robot6) -> None:  # type: ignore[no-untyped-def]
    from robomax_py.program import FrameDef, Header, Program

    header = Header("c", "kr16", "gun", 1.0, tuple(f"a{i}" for i in range(6)))
    for mod, tool, base in ((kawasaki_as, "tool2", "base3"), (inform, "TOOL[2]", "USER[3]")):
        frames = (FrameDef(tool, "tool", (0, 0, 200), (0, 90, 0), 2), FrameDef(base, "base", (1000, 0, 0), (30, 0, 0), 3))
        lin = LinMove((100, 20, 30), (10.0, 20.0, 30.0), "0,0,0,0,0,0,0,0" if mod is inform else "", 250.0,
                      tool=tool, base=base)
        q = tuple(float(v) for v in inform._from_pulses(inform._to_pulses((10, -80, 90, 5, 40, 0), robot6.controller.pulses_per_degree), robot6.controller.pulses_per_degree))
        program = Program("c", header, frames if mod is kawasaki_as else (),
                          (PtpMove(q, 0.5), lin, Spot("s1", "seam", 0.5), WaitFor("IN4", 4), Wait(0.25)))
        if mod is kawasaki_as:
            program = program.__class__(program.name, header, tuple(
                f.__class__(f.name, f.kind, f.xyz_mm, kawasaki_as.zyx_from_oat(kawasaki_as.oat_from_zyx(f.zyx_deg)), f.number)
                for f in frames), program.instructions)
        files = mod.write(program, robot6)
        key = next(k for k in files if k.startswith("."))
        got = mod.parse(files, "x", robot6).program
        assert len(got.instructions) == len(program.instructions)
        assert isinstance(got.instructions[1], LinMove) and got.instructions[1].tool == tool
        assert got.instructions[1].base == base and got.instructions[2] == Spot("s1", "seam", 0.5)
        assert key in (".as", ".jbi")


# ------------------------------------------------------------------ registry and brands


def test_dialects_load_from_entry_points(monkeypatch: pytest.MonkeyPatch) -> None:
    """A dialect registered by another package is loaded by its entry point; the package's own
    registrations of shipped dialects are the shipped objects; a bad entry point is an ExportError."""
    extra = Dialect("val3", (".pgx",), "staubli", inform.adapt, inform.write, inform.parse)

    def entry(name: str, value: str, obj: object) -> SimpleNamespace:
        return SimpleNamespace(name=name, value=value, load=lambda: obj)

    points = [entry("srcl", "robomax_py.export.shipped:SRCL", None), entry("val3", "plugin:DIALECT", extra)]
    monkeypatch.setattr(export.metadata, "entry_points", lambda group: points if group == export.ENTRY_POINT_GROUP else [])
    loaded = export.load_dialects()
    assert list(loaded)[:7] == ["srcl", "krl", "rapid", "fanuc", "urscript", "inform", "as"]
    assert loaded["val3"] is extra and export.native_dialect("staubli", loaded) == "val3"
    points.append(entry("bad", "plugin:BAD", object()))
    with pytest.raises(ExportError, match="bad"):
        export.load_dialects()


def test_native_for_a_brand_without_a_dialect_names_the_robot_file() -> None:
    assert export.format_names("native", "yaskawa") == ("inform",)
    assert export.format_names("native", "kawasaki") == ("as",)
    for brand in ("staubli", "comau", "nachi"):
        with pytest.raises(ExportError, match=rf"robots/x/robot.yaml: controller.brand: .*'{brand}'"):
            export.format_names("srcl,native", brand, "robots/x/robot.yaml")


def test_import_urdf_guesses_the_brand_from_the_package() -> None:
    from robomax_py.app.import_urdf import guess_brand

    assert guess_brand("gp180", "motoman_gp180_support", "urdf", "gp180.urdf") == "yaskawa"
    assert guess_brand("rx160", "staubli_rx160_support", "urdf", "rx160.urdf") == "staubli"
    assert guess_brand("rs007n", "kawasaki_rs007n_description", "urdf", "rs007n.urdf") == "kawasaki"


def test_inform_without_pulses_says_what_is_missing(robot6) -> None:  # type: ignore[no-untyped-def]
    import dataclasses

    bare = dataclasses.replace(robot6, controller=dataclasses.replace(robot6.controller, pulses_per_degree=()))
    with pytest.raises(ExportError, match="controller.pulses_per_degree"):
        inform._pulses(bare)
    assert math.isfinite(sum(robot6.controller.pulses_per_degree))


def test_all_passes_over_inform_for_an_arm_without_pulse_counts(robot6) -> None:  # type: ignore[no-untyped-def]
    """`all` is every dialect the robot file has the data for: INFORM without pulse counts is
    skipped, naming the robot file, the key and the dialect; named, it is refused before anything
    is planned, with the same file and key; with the counts it is written like the others."""
    import dataclasses

    bare = dataclasses.replace(robot6, controller=dataclasses.replace(robot6.controller, pulses_per_degree=()))
    chosen = export.choose_formats("all", bare)
    assert chosen.names == ("srcl", "krl", "rapid", "fanuc", "urscript", "as")
    assert [(k.format, k.robot_file, k.key) for k in chosen.skipped] == [
        ("inform", str(bare.source), "controller.pulses_per_degree")]
    message = chosen.skipped[0].message
    assert str(bare.source) in message and "controller.pulses_per_degree" in message and "inform" in message
    assert export.choose_formats("all,krl", bare).names == chosen.names
    for spec in ("inform", "srcl,inform", "all,inform"):
        with pytest.raises(ExportError, match=rf"--format inform: {re.escape(str(bare.source))}: "
                                              r"controller.pulses_per_degree is not given"):
            export.choose_formats(spec, bare)
    yaskawa = dataclasses.replace(bare, controller=dataclasses.replace(bare.controller, brand="yaskawa"))
    with pytest.raises(ExportError, match="controller.pulses_per_degree"):
        export.choose_formats("native", yaskawa)
    full = export.choose_formats("all", robot6)
    assert full.names == tuple(export.DIALECTS) and full.skipped == ()
    assert export.choose_formats("srcl", bare) == export.FormatChoice(("srcl",))


def test_all_passes_over_a_dialect_that_cannot_address_the_cells_signals(robot6) -> None:  # type: ignore[no-untyped-def]
    """The cell's input and output numbers are checked against each vendor's numbering before
    anything is planned: URScript addresses standard digital I/O 0..7, KRL, FANUC TP, INFORM and AS
    count from 1. `all` passes over a dialect that cannot address one, naming the cell file and the
    key; named, it is refused with that file and key; SRCL and RAPID name their signals."""
    from robomax_py.errors import CellFileError
    from robomax_py.spec import ControllerInput, ControllerOutput, ControllerSetup

    cell = Path("station.yaml")
    setup = ControllerSetup(inputs=(ControllerInput("clamp_closed", 12),), outputs=(ControllerOutput("zone_clear", 0),))
    signals = export.setup_signals(setup, "robots[1].controller")
    assert [(s.key, s.kind, s.number) for s in signals] == [
        ("robots[1].controller.inputs.clamp_closed", "input", 12), ("robots[1].controller.outputs.zone_clear", "output", 0)]
    chosen = export.choose_formats("all", robot6, signals, cell)
    assert chosen.names == ("srcl", "rapid")
    assert [(k.format, k.key) for k in chosen.skipped] == [
        ("krl", "robots[1].controller.outputs.zone_clear"), ("fanuc", "robots[1].controller.outputs.zone_clear"),
        ("urscript", "robots[1].controller.inputs.clamp_closed"), ("inform", "robots[1].controller.outputs.zone_clear"),
        ("as", "robots[1].controller.outputs.zone_clear")]
    assert chosen.skipped[2].message == ("station.yaml: robots[1].controller.inputs.clamp_closed: input 12 is outside "
                                         "URScript's inputs 0..7: no urscript program written")
    with pytest.raises(CellFileError, match=r"station.yaml: robots\[1\].controller.inputs.clamp_closed: input 12 is "
                                            r"outside URScript's inputs 0..7 \(--format urscript\)"):
        export.choose_formats("srcl,urscript", robot6, signals, cell)
    fits = export.setup_signals(ControllerSetup(inputs=(ControllerInput("clamp_closed", 7),)))
    assert export.choose_formats("all", robot6, fits, cell).names == tuple(export.DIALECTS)
    assert export.choose_formats("urscript", robot6, fits, cell).names == ("urscript",)
    # A Kawasaki user may give the number AS waits on (SWAIT 1020) for external input 20: told so.
    as_number = export.setup_signals(ControllerSetup(inputs=(ControllerInput("clamp_closed", 1020),)))
    with pytest.raises(CellFileError, match=r"input 1020 is outside AS's inputs 1..999 \(give external input k, "
                                            r"which AS waits for as signal 1000 \+ k: 1 for SWAIT 1001\)"):
        export.choose_formats("as", robot6, as_number, cell)


def test_publish_refuses_inform_without_pulse_counts_before_proving_any(robot6) -> None:  # type: ignore[no-untyped-def]
    """publish checks every format's calibration first: no dialect is proven for a set that cannot
    be whole (the plan is not even looked at)."""
    import dataclasses

    from robomax_py.publish import publish

    bare = dataclasses.replace(robot6, controller=dataclasses.replace(robot6.controller, pulses_per_degree=()))
    with pytest.raises(ExportError, match="controller.pulses_per_degree"):
        publish(None, None, bare, ("srcl", "inform"))  # type: ignore[arg-type]

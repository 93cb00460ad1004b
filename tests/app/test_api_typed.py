"""The typed public API on the small cell: `PlanOptions` instead of keyword overrides, a cell given
as a mapping, progress events, `RobomaxWarning`, programs written by dialect, and the package's
lazily served names."""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any, get_args

import pytest
import yaml

import robomax_py as rm
from tests.conftest import SHIPPED_CELL, SmallCell

REPO = Path(__file__).resolve().parents[2]


@dataclasses.dataclass
class Planned:
    folder: Path
    cell: rm.LoadedCell
    result: rm.PlanResult
    events: list[rm.ProgressEvent]


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> Planned:
    path = write_small_cell(tmp_path_factory.mktemp("typed_api"))
    cell = rm.load_cell(path)
    events: list[rm.ProgressEvent] = []
    result = rm.plan_cell(cell, progress=events.append)
    assert result.status == "planned", result.message
    return Planned(path.parent, cell, result, events)


def _same_plan(a: rm.PlanResult, b: rm.PlanResult) -> None:
    assert (a.status, a.message) == (b.status, b.message)
    assert [(s.seam, s.name, s.config) for s in a.spots] == [(s.seam, s.name, s.config) for s in b.spots]
    assert [t.kind for t in a.transitions] == [t.kind for t in b.transitions]
    assert a.cycle_time == pytest.approx(b.cycle_time, abs=1e-9)


def test_a_cell_from_its_mapping_plans_as_from_its_file(planned: Planned) -> None:
    data = yaml.safe_load((planned.folder / "small_cell.yaml").read_text())
    # Tuples where the file has lists: what code builds is taken as the file's lists would be.
    data["robot"]["base"]["xyz"] = tuple(data["robot"]["base"]["xyz"])
    cell = rm.load_cell(data, base_dir=planned.folder)     # its meshes are relative to base_dir
    assert cell.spec.name == planned.cell.spec.name
    assert [o.name for o in cell.spec.objects] == [o.name for o in planned.cell.spec.objects]
    _same_plan(rm.plan_cell(cell), planned.result)


def test_a_bad_mapping_is_named_as_the_file(tmp_path: Path) -> None:
    data: dict[str, Any] = yaml.safe_load(SHIPPED_CELL.read_text())
    data["seams"][0]["spots"][0]["normal"] = [0, 0]
    with pytest.raises(rm.CellFileError, match=r"^<mapping>: seams\[0\]\.spots\[0\]\.normal"):
        rm.load_cell(data, base_dir=SHIPPED_CELL.parent)
    del data["name"]
    with pytest.raises(rm.CellFileError, match="^<mapping>: name: required"):
        rm.load_cell(data, base_dir=SHIPPED_CELL.parent)
    good = yaml.safe_load(SHIPPED_CELL.read_text())
    with pytest.raises(rm.CellFileError, match=r"^<mapping>: objects\[\d+\]\.mesh: mesh .*not found"):   # meshes beside base_dir only
        rm.load_cell(good, base_dir=tmp_path)
    with pytest.raises(TypeError, match="base_dir"):
        rm.load_cell(SHIPPED_CELL, base_dir=tmp_path)


def test_progress_events_arrive_stage_by_stage(planned: Planned) -> None:
    events = planned.events
    assert all(isinstance(e, rm.ProgressEvent) for e in events)
    stages = list(dict.fromkeys(e.stage for e in events))
    assert stages == list(get_args(rm.PlanStage))
    for stage in stages:
        mine = [e for e in events if e.stage == stage]
        assert [e.done for e in mine] == sorted(e.done for e in mine)
        assert all(0 <= e.done <= e.total for e in mine)
        assert mine[-1].done == mine[-1].total > 0 and mine[-1].fraction == 1.0
        assert mine[0].label
    assert [e.total for e in events if e.stage == "candidates"][-1] == len(planned.result.spots)


def test_plan_options_fields_are_used_and_documented(planned: Planned) -> None:
    options = rm.PlanOptions(given_order=True, speed=0.5, blend=False)
    result = rm.plan_cell(planned.cell, options)
    assert result.status == "planned", result.message
    assert result.method == "published"
    assert (result.options.speed, result.options.blend) == (0.5, False)
    assert result.cycle_time > planned.result.cycle_time        # half speed, no blends: slower
    doc = rm.PlanOptions.__doc__ or ""
    missing = [f.name for f in dataclasses.fields(rm.PlanOptions) if f"`{f.name}`" not in doc]
    assert not missing, f"PlanOptions fields without a line in its docstring: {missing}"
    with pytest.raises(TypeError):
        rm.plan_cell(planned.cell, given_order=True)  # type: ignore[call-arg]


def test_statuses_kinds_and_reasons_are_literals(planned: Planned) -> None:
    assert planned.result.status in get_args(rm.PlanStatus)
    assert {t.kind for t in planned.result.transitions} <= set(get_args(rm.TransitionKind))
    assert "unreachable" in get_args(rm.FailureReason)


def test_programs_are_returned_by_dialect(planned: Planned, tmp_path: Path) -> None:
    out = tmp_path / "programs"
    written = rm.write_programs(planned.cell, planned.result, out, formats=["srcl", "krl"])
    assert isinstance(written, rm.WrittenPrograms)
    assert list(written.by_dialect) == ["srcl", "krl"]
    assert [p.name for p in written.by_dialect["srcl"]] == ["small_cell.srcl"]
    assert written.by_dialect["krl"][0].name == "small_cell.src"            # the main program first
    assert written.trajectory == out / "small_cell.json" and written.manifest.is_file()
    every = [written.trajectory, *written.by_dialect["srcl"], *written.by_dialect["krl"]]
    assert sorted(written) == sorted(every) and len(written) == len(every)
    assert all(p.is_file() for p in written)
    assert rm.verify_program(planned.cell, written.by_dialect["krl"][0]).clean

    with pytest.warns(DeprecationWarning, match=r"\['srcl', 'krl'\]"):
        again = rm.write_programs(planned.cell, planned.result, out, formats="srcl,krl")
    assert dict(again.by_dialect) == dict(written.by_dialect) and again[-1] == written[-1]
    with pytest.raises(rm.ExportError, match="one dialect name per item"):
        rm.write_programs(planned.cell, planned.result, out, formats=[])


def test_defaulted_limits_reach_the_caller_as_a_warning(tmp_path: Path, write_small_cell: SmallCell) -> None:
    robot = tmp_path / "kr125"
    shutil.copytree(REPO / "robomax_py" / "robots" / "kr125", robot)
    spec = yaml.safe_load((robot / "robot.yaml").read_text())
    del spec["limits"]["acceleration"], spec["limits"]["jerk"]
    (robot / "robot.yaml").write_text(yaml.safe_dump(spec))
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["robot"]["model"] = "kr125/robot.yaml"
    with pytest.warns(rm.RobomaxWarning, match="limits.acceleration and limits.jerk not given"):
        rm.load_cell(data, base_dir=tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", rm.RobomaxWarning)       # the shipped robot states its limits
        warnings.simplefilter("ignore", rm.CellWarning)         # (the small cell's zero clearance is noted)
        rm.load_cell(write_small_cell(tmp_path / "plain"))


def test_the_package_lists_and_serves_its_api_lazily() -> None:
    doc = rm.__doc__ or ""
    for name in rm.__all__:
        assert callable(getattr(rm, name)) or name == "__version__" or name in (
            "PlanStatus", "PlanStage", "TransitionKind", "FailureReason"), name
        assert name in dir(rm)
        if not name.startswith("_") and not name.endswith("Error") or name == "RobomaxError":
            assert name in doc, f"{name} missing from the package docstring"
    code = ("import sys, robomax_py; heavy = [m for m in ('numpy', 'robomax_py.app.api', 'robomax_py.plan') "
            "if m in sys.modules]; print(heavy); assert not heavy")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stdout + done.stderr

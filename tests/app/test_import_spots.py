"""`robomax import-spots`: the new cell `robomax check` accepts; refusals write nothing."""

from __future__ import annotations

import json
from pathlib import Path

import yaml
from spot_list_case import (
    STATION,
    cell_data,
    known_spots,
    station_spots,
    write_cell,
    write_csv,
)
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.io.cell import load_cell


def _setup(tmp_path: Path) -> tuple[Path, Path]:
    csv = write_csv(tmp_path / "spots.csv", known_spots()[:60], mm=True, groups=True)
    return write_cell(tmp_path / "cell.yaml", cell_data()), csv


def test_writes_a_cell_check_accepts(tmp_path: Path) -> None:
    cell, csv = _setup(tmp_path)
    out = tmp_path / "new.yaml"
    done = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), "--part", "plate", "--units", "mm",
                                    "-o", str(out), "--json"])
    assert done.exit_code == 0, done.output
    report = json.loads(done.stdout)
    assert report["schema"] == "robomax.cli.import-spots/1" and report["ok"]
    assert report["seams"] == [{"name": "top1", "spots": 30}, {"name": "top2", "spots": 30}]
    assert [s["name"] for s in yaml.safe_load(out.read_text())["seams"]] == ["top1", "top2"]
    assert CliRunner().invoke(app, ["check", str(out)]).exit_code == 0
    again = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), "--part", "plate", "-o", str(out)])
    assert again.exit_code == 2 and "exists; use --force" in again.output


def test_bad_input_writes_nothing(tmp_path: Path) -> None:
    cell, csv = _setup(tmp_path)
    out = tmp_path / "new.yaml"
    for args in (["--part", "nothing", "--units", "mm"], ["--part", "plate", "--units", "m"]):
        done = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), *args, "-o", str(out)])
        assert done.exit_code == 2 and "Traceback" not in done.output
        assert not out.exists()
    same = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), "--part", "plate", "-o", str(cell)])
    assert same.exit_code == 2 and "another file" in same.output


def test_frame_option_gives_the_cell_keys_spots(tmp_path: Path) -> None:
    """`--frame`: the list's coordinates in a named frame of the cell, as the key's `frame:` reads them."""
    csv = write_csv(tmp_path / "station.csv", station_spots()[:60], mm=True, groups=True)
    cell = write_cell(tmp_path / "cell.yaml", cell_data(frames=[STATION]))
    out = tmp_path / "new.yaml"
    done = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), "--part", "plate", "--units", "mm",
                                    "--frame", "station", "-o", str(out)])
    assert done.exit_code == 0, done.output
    keyed = load_cell(write_cell(tmp_path / "k.yaml", cell_data(frames=[STATION], spot_lists=[
        {"file": "station.csv", "part": "plate", "units": "mm", "frame": "station"}])))
    imported = load_cell(out)
    assert [s.name for s in imported.seams] == [s.name for s in keyed.seams] == ["top1", "top2"]
    for a, b in zip(imported.seams, keyed.seams, strict=True):
        for p, q in zip(a.spots, b.spots, strict=True):
            assert p.name == q.name and (abs(p.xyz - q.xyz) < 1e-6).all() and (abs(p.normal - q.normal) < 1e-8).all()
    bad = CliRunner().invoke(app, ["import-spots", str(cell), str(csv), "--part", "plate", "--units", "mm",
                                   "--frame", "nowhere", "-o", str(tmp_path / "bad.yaml")])
    assert bad.exit_code == 2 and "--frame: unknown frame 'nowhere'" in bad.output
    assert not (tmp_path / "bad.yaml").exists()


def test_sides_either_writes_seams_the_gun_may_weld_from_either_side(tmp_path: Path) -> None:
    """An open sheet whose spots are free on both sides: without `--sides` the spots are reported
    as ambiguous and the seams keep the default; with `--sides either` nothing is reported and every
    new seam says `tolerance.sides: either`, which `check` accepts."""
    data = cell_data()
    data["objects"] = [{"name": "sheet", "box": [0.4, 0.3, 0.0015], "pose": {"xyz": [1.4, 0.0, 0.9]}, "workpiece": True}]
    cell = write_cell(tmp_path / "cell.yaml", data)
    rows = "".join(f"m{i},{x:.3f},{y:.3f},0\n" for i, (x, y) in enumerate((x, y) for x in (-0.15, 0.0, 0.15)
                                                                          for y in (-0.1, 0.1)))
    (tmp_path / "s.csv").write_text("id,x,y,z\n" + rows)
    reports = {}
    for sides in ("normal", "either"):
        out = tmp_path / f"{sides}.yaml"
        done = CliRunner().invoke(app, ["import-spots", str(cell), str(tmp_path / "s.csv"), "--part", "sheet",
                                        "--sides", sides, "-o", str(out), "--json"])
        assert done.exit_code == 0, done.output
        reports[sides] = (json.loads(done.stdout), yaml.safe_load(out.read_text())["seams"])
        assert CliRunner().invoke(app, ["check", str(out)]).exit_code == 0
    assert len(reports["normal"][0]["ambiguous"]) == 6 and not reports["either"][0]["ambiguous"]
    assert all((s.get("tolerance") or {}).get("sides", "normal") == "normal" for s in reports["normal"][1])
    assert reports["either"][1] and all(s["tolerance"]["sides"] == "either" for s in reports["either"][1])
    bad = CliRunner().invoke(app, ["import-spots", str(cell), str(tmp_path / "s.csv"), "--part", "sheet",
                                   "--sides", "both", "-o", str(tmp_path / "bad.yaml")])
    assert bad.exit_code == 2 and "--sides: expected normal or either, got 'both'" in bad.output
    assert not (tmp_path / "bad.yaml").exists()

"""Link geometry built once per process and reused while the arm's files are unchanged: a second
load of the same robot.yaml builds nothing and gives the same geometry; a mesh file rewritten
between loads is read again, and the new shape is what the robot collides with."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import link_geometry
from robomax_py.robot import model as robot_model
from robomax_py.robot.model import load_robot

KR16 = Path(robot_model.__file__).resolve().parents[1] / "robots" / "kr16"


def _points(robot: robot_model.RobotModel) -> list[np.ndarray]:
    return [np.asarray(o.geometry.points()) if hasattr(o.geometry, "points") else np.zeros((0, 3))
            for o in robot.collision_model.geometryObjects]


@pytest.fixture
def kr16(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, list[str]]:
    """A copy of the KR 16 folder, an empty reuse table, and the URDFs built (kinds) as they happen."""
    folder = tmp_path / "kr16"
    shutil.copytree(KR16, folder)
    monkeypatch.setattr(link_geometry, "_GEOMETRY", {})
    built: list[str] = []
    build = link_geometry._build_geometry

    def counted(model, spec, kind, dirs):  # type: ignore[no-untyped-def]
        built.append(str(kind))
        return build(model, spec, kind, dirs)

    monkeypatch.setattr(link_geometry, "_build_geometry", counted)
    return folder, built


def test_a_second_load_builds_nothing_and_gives_the_same_geometry(kr16: tuple[Path, list[str]]) -> None:
    folder, built = kr16
    first = load_robot(load_robot_spec(folder / "robot.yaml"))
    assert len(built) == 2                                   # collision and visual
    second = load_robot(load_robot_spec(folder / "robot.yaml"))
    assert len(built) == 2
    assert [o.name for o in second.collision_model.geometryObjects] == [o.name for o in first.collision_model.geometryObjects]
    for a, b in zip(_points(first), _points(second), strict=True):
        np.testing.assert_array_equal(a, b)
    assert second.collision_model is not first.collision_model


def test_a_rewritten_mesh_is_read_again(kr16: tuple[Path, list[str]]) -> None:
    folder, built = kr16
    first = load_robot(load_robot_spec(folder / "robot.yaml"))
    meshes = sorted({o.meshPath for o in first.collision_model.geometryObjects if o.meshPath.startswith(str(folder))})
    assert meshes
    target = Path(meshes[-1])
    mesh = trimesh.load(target, force="mesh")
    mesh.apply_scale(2.0)
    mesh.export(target)
    stat = target.stat()
    os.utime(target, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))
    second = load_robot(load_robot_spec(folder / "robot.yaml"))
    assert built == ["COLLISION", "VISUAL", "COLLISION"]       # the visual meshes are other files
    k = next(i for i, o in enumerate(first.collision_model.geometryObjects) if o.meshPath == str(target))
    grown = np.ptp(_points(second)[k], axis=0) / np.ptp(_points(first)[k], axis=0)
    np.testing.assert_allclose(grown, 2.0, rtol=1e-6)       # the hull of the scaled mesh, not the old one

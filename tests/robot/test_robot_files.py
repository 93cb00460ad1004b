"""The robot library (robots/kr125, robots/kr16): URDF kinematics, limits, meshes, regeneration.

Independent checks of what ``robots/generate.py`` wrote: the URDF's Pinocchio forward kinematics
must equal ``opw_fk`` of the parameters in ``robot.yaml`` (the IK is built from those alone, so any
disagreement would put every planned pose off), collision pieces must be convex and enclose the
visual meshes, the arm must be free of self-collision in its reference poses, and the committed
files must be exactly what the script produces.
"""

from __future__ import annotations

import importlib.util
import itertools
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
import yaml

from robomax_py.robot.ik.opw import OpwParams, opw_fk

REPO = Path(__file__).resolve().parents[2]
ROBOTS = REPO / "robomax_py" / "robots"
ARMS = ("kr125", "kr16")
LINKS = ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6")
HOME_DEG = (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)

# Float64 FK through six joints at ~2.5 m reach differs from the closed form by ~1e-15.
FK_ATOL = 1e-12
# A visual vertex may sit this far outside the collision hulls (brief: 1 mm slack).
ENCLOSE_SLACK_M = 1e-3
# Hull volume equals the piece's own volume for a convex piece, up to float32 STL round-off.
CONVEX_REL_TOL = 1e-6
VISUAL_STL_MAX_BYTES = 300 * 1024


def _load_mesh(path: Path) -> trimesh.Trimesh:
    mesh = trimesh.load(path, force="mesh")
    assert isinstance(mesh, trimesh.Trimesh), path
    return mesh


def _robot_yaml(name: str) -> dict[str, Any]:
    with open(ROBOTS / name / "robot.yaml", encoding="utf-8") as fh:
        data: dict[str, Any] = yaml.safe_load(fh)
    return data


def _opw_params(name: str) -> OpwParams:
    p = _robot_yaml(name)["ik"]["params"]
    return OpwParams(
        a1=p["a1"], a2=p["a2"], b=p["b"], c1=p["c1"], c2=p["c2"], c3=p["c3"], c4=p["c4"],
        offsets=tuple(math.radians(v) for v in p["offsets"]),  # type: ignore[arg-type]
        sign_corrections=tuple(int(v) for v in p["sign_corrections"]),  # type: ignore[arg-type]
    )


def _model(name: str) -> Any:
    import pinocchio as pin

    return pin.buildModelFromUrdf(str(ROBOTS / name / f"{name}.urdf"))


def _collision_files(name: str, link: str) -> list[Path]:
    return sorted((ROBOTS / name / "meshes" / "collision").glob(f"{link}_*.stl"))


@pytest.mark.parametrize("name", ARMS)
def test_robot_yaml_has_exactly_the_spec_keys(name: str) -> None:
    data = _robot_yaml(name)
    # SPEC §1 keys plus our optional, informational extensions.
    assert set(data) == {"name", "urdf", "flange", "ik", "limits", "payload", "description"}
    assert data["name"] == name
    assert data["urdf"] == f"{name}.urdf"
    assert data["flange"] == "tool0"
    assert data["ik"]["solver"] == "opw"
    assert set(data["ik"]["params"]) == {"a1", "a2", "b", "c1", "c2", "c3", "c4", "offsets", "sign_corrections"}
    assert data["ik"]["params"]["offsets"] == [0, -90, 0, 0, 0, 0]
    assert data["ik"]["params"]["sign_corrections"] == [-1, 1, 1, -1, 1, -1]
    assert set(data["limits"]) <= {"acceleration", "jerk", "loaded"}
    for key in ("acceleration", "jerk"):
        values = data["limits"][key]
        assert len(values) == 6 and all(v > 0 for v in values)
    # The extension: limits with the rated payload, never above the unloaded ones.
    loaded = data["limits"].get("loaded")
    if loaded is not None:
        for key in ("acceleration", "jerk"):
            assert all(0 < a <= b for a, b in zip(loaded[key], data["limits"][key], strict=True))


@pytest.mark.parametrize("name", ARMS)
def test_home_is_within_limits_and_points_forward(name: str) -> None:
    model = _model(name)
    home = np.radians(HOME_DEG)
    assert np.all(home >= model.lowerPositionLimit) and np.all(home <= model.upperPositionLimit)
    # KUKA home: link arm vertical, forearm horizontal forward, flange z along +x.
    T = opw_fk(_opw_params(name), home)
    np.testing.assert_allclose(T[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)
    assert T[0, 3] > 1.0


@pytest.mark.parametrize("name", ARMS)
def test_urdf_meshes_are_relative_and_exist(name: str) -> None:
    root = ET.parse(ROBOTS / name / f"{name}.urdf").getroot()
    names = [m.get("filename", "") for m in root.iter("mesh")]
    assert names, "URDF names no meshes"
    for fn in names:
        assert not fn.startswith(("/", "package:", "file:")), fn
        assert (ROBOTS / name / fn).is_file(), fn
    for link in LINKS:
        el = root.find(f"link[@name='{link}']")
        assert el is not None
        assert len(el.findall("visual")) == 1
        assert 1 <= len(el.findall("collision")) <= 4
        mass = el.find("inertial/mass")
        assert mass is not None and float(mass.get("value", "0")) > 0.0


@pytest.mark.parametrize(("name", "link"), list(itertools.product(ARMS, LINKS)))
def test_collision_pieces_convex_watertight_and_enclosing(name: str, link: str) -> None:
    files = _collision_files(name, link)
    assert 1 <= len(files) <= 4
    planes = []
    for path in files:
        piece = _load_mesh(path)
        assert piece.is_watertight, path
        hull = piece.convex_hull
        assert abs(hull.volume - piece.volume) <= CONVEX_REL_TOL * hull.volume, path
        # Outward face planes n.x <= d of the hull.
        planes.append((hull.face_normals, np.einsum("ij,ij->i", hull.face_normals, hull.triangles[:, 0])))
    visual_path = ROBOTS / name / "meshes" / "visual" / f"{link}.stl"
    assert visual_path.stat().st_size <= VISUAL_STL_MAX_BYTES
    visual = _load_mesh(visual_path)
    inside = np.zeros(len(visual.vertices), dtype=np.bool_)
    for normals, offsets in planes:
        inside |= np.max(visual.vertices @ normals.T - offsets, axis=1) <= ENCLOSE_SLACK_M
    assert inside.all(), f"{int((~inside).sum())} visual vertices outside the collision hulls"


def _coal_convex(vertices: np.ndarray) -> Any:
    import coal

    pts = coal.StdVec_Vec3s()
    for p in np.asarray(vertices, dtype=float):
        pts.append(p)
    return coal.Convex.convexHull(pts, False, None)


def _collides(geom_a: Any, T_a: np.ndarray, geom_b: Any, T_b: np.ndarray) -> bool:
    import coal

    oa = coal.CollisionObject(geom_a, coal.Transform3s(T_a[:3, :3].copy(), T_a[:3, 3].copy()))
    ob = coal.CollisionObject(geom_b, coal.Transform3s(T_b[:3, :3].copy(), T_b[:3, 3].copy()))
    return bool(coal.collide(oa, ob, coal.CollisionRequest(), coal.CollisionResult()) > 0)


@pytest.mark.parametrize("name", ARMS)
@pytest.mark.parametrize("q_deg", [HOME_DEG, (0.0,) * 6, (0.0, -90.0, 0.0, 0.0, 0.0, 0.0), (0.0, -90.0, 90.0, 0.0, 90.0, 0.0)])
def test_no_self_collision_in_reference_poses(name: str, q_deg: tuple[float, ...]) -> None:
    import pinocchio as pin

    model = _model(name)
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.radians(q_deg))
    pose = {link: data.oMf[model.getFrameId(link)].homogeneous for link in LINKS}
    geoms = {link: [_coal_convex(_load_mesh(p).vertices) for p in _collision_files(name, link)] for link in LINKS}
    hits = []
    for i, j in itertools.combinations(range(len(LINKS)), 2):
        if j - i < 2:  # neighbours touch at their joint by design and are never checked
            continue
        a, b = LINKS[i], LINKS[j]
        if any(_collides(ga, pose[a], gb, pose[b]) for ga in geoms[a] for gb in geoms[b]):
            hits.append((a, b))
    assert not hits, f"{name} at {q_deg} deg: {hits}"


def _load_generator() -> Any:
    spec = importlib.util.spec_from_file_location("robots_generate", ROBOTS / "generate.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    # dataclasses look their module up in sys.modules while the class body runs.
    sys.modules[spec.name] = module
    # No robots/__pycache__: the robots folder holds data, not a package.
    saved, sys.dont_write_bytecode = sys.dont_write_bytecode, True
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[spec.name]
        sys.dont_write_bytecode = saved
    return module


def test_generate_is_deterministic_and_matches_committed_files(tmp_path: Path) -> None:
    generator = _load_generator()
    written = generator.generate(tmp_path)
    produced = {p.relative_to(tmp_path) for p in written}
    assert len(produced) == len(written)
    for rel in sorted(produced):
        assert (ROBOTS / rel).read_bytes() == (tmp_path / rel).read_bytes(), f"{rel} differs: rerun robots/generate.py"
    # No stale generated files left behind in the generated folders.
    committed = {
        p.relative_to(ROBOTS)
        for folder in ("kr125", "kr16", "tools/spot_gun_c")
        for p in (ROBOTS / folder).rglob("*")
        if p.is_file()
    }
    assert committed == produced

"""The C-type spot-welding gun (robots/tools/spot_gun_c): format, convex pieces, key dimensions and
the acceptance check against the reference cell.

Acceptance: at every spot of the reference cell, in the nominal spot frame of SPEC §3 and tilted by
alpha, beta in {-10, 0, 10} deg (gamma = 0), and also displaced 30 mm either way along the
electrode axis (approach / retract), the gun body must not intersect the workpiece or any other
object of the cell, while at the spot itself the tips touch the workpiece.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
import yaml

REPO = Path(__file__).resolve().parents[2]
GUN_DIR = REPO / "robomax_py" / "robots" / "tools" / "spot_gun_c"
# The reference cell: its frozen copies in tests/data (cells/cabin_flange.yaml is now our own cell).
CELL_CANDIDATES = (
    REPO / "tests" / "data" / "flange_cell" / "cabin_flange.yaml",
    REPO / "tests" / "data" / "reference" / "cabin_flange.yaml",
)
CONVEX_REL_TOL = 1e-6
MIN_GAP_M = 0.06  # open stroke: a 30 mm approach from either side
MIN_THROAT_M = 0.12  # reaches over a 40 mm flange with room for +-10 deg tilts
APPROACH_M = 0.03
TILTS_DEG = (-10.0, 0.0, 10.0)


def _tool() -> dict[str, Any]:
    with open(GUN_DIR / "tool.yaml", encoding="utf-8") as fh:
        data: dict[str, Any] = yaml.safe_load(fh)
    return data


def _load_mesh(path: Path) -> trimesh.Trimesh:
    mesh = trimesh.load(path, force="mesh")
    assert isinstance(mesh, trimesh.Trimesh), path
    return mesh


def _pieces(file_name: str) -> list[trimesh.Trimesh]:
    return list(_load_mesh(GUN_DIR / file_name).split(only_watertight=False))


def _T_flange_tcp() -> np.ndarray:
    """TCP pose in the flange frame from tool.yaml (rpy: R = Rz(yaw) Ry(pitch) Rx(roll), SPEC §3)."""
    tcp = _tool()["tcp"]
    roll, pitch, yaw = (math.radians(a) for a in tcp["rpy"])
    T = np.eye(4)
    T[:3, :3] = _rot(2, yaw) @ _rot(1, pitch) @ _rot(0, roll)
    T[:3, 3] = tcp["xyz"]
    return T


def _pieces_in_tcp_frame(file_name: str) -> list[trimesh.Trimesh]:
    T_tcp_flange = np.linalg.inv(_T_flange_tcp())
    return [p.copy().apply_transform(T_tcp_flange) for p in _pieces(file_name)]


def _coal_convex(vertices: np.ndarray) -> Any:
    import coal

    pts = coal.StdVec_Vec3s()
    for p in np.asarray(vertices, dtype=float):
        pts.append(p)
    # Not BVHModel.buildConvexRepresentation: it is unreliable in coal 3.0.3.
    return coal.Convex.convexHull(pts, False, None)


def _coal_mesh(mesh: trimesh.Trimesh) -> Any:
    import coal

    bvh = coal.BVHModelOBBRSS()
    pts = coal.StdVec_Vec3s()
    for p in np.asarray(mesh.vertices, dtype=float):
        pts.append(p)
    tris = coal.StdVec_Triangle()
    for f in np.asarray(mesh.faces):
        tris.append(coal.Triangle(int(f[0]), int(f[1]), int(f[2])))
    bvh.beginModel(len(mesh.faces), len(mesh.vertices))
    bvh.addSubModel(pts, tris)
    bvh.endModel()
    return bvh


def _transform(T: np.ndarray) -> Any:
    import coal

    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


def _collides(a: Any, b: Any) -> bool:
    import coal

    return bool(coal.collide(a, b, coal.CollisionRequest(), coal.CollisionResult()) > 0)


def _rot(axis: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def _pose(entry: dict[str, Any] | None) -> np.ndarray:
    """SPEC §3 pose: xyz in m, rpy in deg about fixed X, Y, Z (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    T = np.eye(4)
    if entry:
        roll, pitch, yaw = (math.radians(v) for v in entry.get("rpy", (0.0, 0.0, 0.0)))
        T[:3, :3] = _rot(2, yaw) @ _rot(1, pitch) @ _rot(0, roll)
        T[:3, 3] = entry.get("xyz", (0.0, 0.0, 0.0))
    return T


def _spot_frame(spot: dict[str, Any]) -> np.ndarray:
    """Nominal TCP frame of SPEC §3: z = -n, x = d orthogonalised against n, y = z x x."""
    n = np.asarray(spot["normal"], dtype=float)
    n /= np.linalg.norm(n)
    d = np.asarray(spot["direction"], dtype=float)
    x = d - np.dot(d, n) * n
    x /= np.linalg.norm(x)
    z = -n
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = spot["xyz"]
    return T


def _cell_objects(cell_path: Path, cell: dict[str, Any]) -> tuple[list[Any], list[tuple[str, Any]]]:
    """Collision objects of the cell: (workpieces, others with their names)."""
    import coal

    workpieces, others = [], []
    for obj in cell["objects"]:
        T = _pose(obj.get("pose"))
        if "mesh" in obj:
            mesh = _load_mesh(cell_path.parent / obj["mesh"])
            geom = _coal_mesh(mesh)
        elif "box" in obj:
            geom = coal.Box(*(float(v) for v in obj["box"]))
        elif "cylinder" in obj:
            geom = coal.Cylinder(float(obj["cylinder"]["radius"]), float(obj["cylinder"]["length"]))
        elif "sphere" in obj:
            geom = coal.Sphere(float(obj["sphere"]["radius"]))
        elif "capsule" in obj:
            geom = coal.Capsule(float(obj["capsule"]["radius"]), float(obj["capsule"]["length"]))
        else:
            raise AssertionError(f"unknown object kind in {obj}")
        co = coal.CollisionObject(geom, _transform(T))
        if obj.get("workpiece", False):
            workpieces.append(co)
        else:
            others.append((str(obj["name"]), co))
    return workpieces, others


def test_tool_yaml_follows_the_spec() -> None:
    data = _tool()
    assert set(data) == {"name", "body", "tips", "tcp"}
    assert data["name"] == "spot_gun_c"
    assert (GUN_DIR / data["body"]).is_file() and (GUN_DIR / data["tips"]).is_file()
    T = _T_flange_tcp()
    # Hung gun: the closing axis (TCP z) is perpendicular to the flange axis, the TCP 0.2-0.6 m out.
    assert abs(float(T[:3, 2] @ np.array([0.0, 0.0, 1.0]))) < 1e-12
    assert 0.2 <= float(np.linalg.norm(T[:3, 3])) <= 0.6


@pytest.mark.parametrize("file_name", ["body.stl", "tips.stl"])
def test_gun_files_split_into_convex_watertight_pieces(file_name: str) -> None:
    pieces = _pieces(file_name)
    assert len(pieces) >= 2
    for piece in pieces:
        assert piece.is_watertight
        hull = piece.convex_hull
        assert abs(hull.volume - piece.volume) <= CONVEX_REL_TOL * hull.volume


def test_gun_key_dimensions() -> None:
    import coal

    # Work in the TCP frame: z = closing axis, the fixed tip's face at z = 0.
    z_tcp = 0.0
    tips = _pieces_in_tcp_frame("tips.stl")
    # The fixed tip's face is the TCP; the moving tip faces it from the -z side.
    fixed_face = min(float(p.vertices[:, 2].min()) for p in tips if p.vertices[:, 2].max() > z_tcp)
    moving_face = max(float(p.vertices[:, 2].max()) for p in tips if p.vertices[:, 2].max() < z_tcp)
    assert fixed_face == pytest.approx(z_tcp, abs=1e-6)
    assert z_tcp - moving_face >= MIN_GAP_M
    # Electrodes about 16 mm across (every tip piece lies in the gun's y-z plane).
    for p in tips:
        assert float(np.ptp(p.vertices[:, 0])) <= 0.017
    # Throat: nothing of the body in a 100 mm wide slab from the axis to y = MIN_THROAT_M around
    # the sheet plane at the TCP (where a 40 mm flange sits while welding).
    slab = coal.CollisionObject(coal.Box(0.1, MIN_THROAT_M, 0.02), _transform(_pose({"xyz": [0, 0.5 * MIN_THROAT_M, z_tcp]})))
    for piece in _pieces_in_tcp_frame("body.stl"):
        body = coal.CollisionObject(_coal_convex(piece.vertices), _transform(np.eye(4)))
        assert not _collides(body, slab)
    # Everything sits in front of the flange face (z = 0), so the flange and wrist never touch it.
    for piece in _pieces("body.stl") + _pieces("tips.stl"):
        assert float(piece.vertices[:, 2].min()) > 0.0


@pytest.mark.parametrize("robot", ["kr125", "kr16"])
@pytest.mark.parametrize("a5_deg", [0.0, 90.0, -90.0])
def test_gun_clear_of_the_wrist(robot: str, a5_deg: float) -> None:
    import coal
    import pinocchio as pin

    root = REPO / "robomax_py" / "robots" / robot
    model = pin.buildModelFromUrdf(str(root / f"{robot}.urdf"))
    data = model.createData()
    q = np.radians([0.0, -90.0, 90.0, 30.0, a5_deg, 45.0])
    pin.framesForwardKinematics(model, data, q)
    T_flange = data.oMf[model.getFrameId("tool0")].homogeneous
    body = [coal.CollisionObject(_coal_convex(p.vertices), _transform(T_flange)) for p in _pieces("body.stl")]
    for link in ("link_3", "link_4", "link_5", "link_6"):
        T_link = data.oMf[model.getFrameId(link)].homogeneous
        for path in sorted((root / "meshes" / "collision").glob(f"{link}_*.stl")):
            geom = coal.CollisionObject(_coal_convex(_load_mesh(path).vertices), _transform(T_link))
            assert not any(_collides(geom, b) for b in body), f"gun body hits {path.name}"


def test_gun_welds_every_reference_spot_without_body_contact() -> None:
    cell_path = next((p for p in CELL_CANDIDATES if p.is_file()), None)
    assert cell_path is not None, "the reference cell (tests/data/reference) is shipped with the repository"
    with open(cell_path, encoding="utf-8") as fh:
        cell = yaml.safe_load(fh)
    workpieces, others = _cell_objects(cell_path, cell)
    assert workpieces, "the reference cell has no workpiece"
    T_tcp_flange = np.linalg.inv(_T_flange_tcp())
    body = [_coal_convex(p.vertices) for p in _pieces("body.stl")]
    tips = [_coal_convex(p.vertices) for p in _pieces("tips.stl")]
    import coal

    body_objs = [coal.CollisionObject(g, _transform(np.eye(4))) for g in body]
    tip_objs = [coal.CollisionObject(g, _transform(np.eye(4))) for g in tips]
    failures: list[str] = []
    spots = [s for seam in cell["seams"] for s in seam["spots"]]
    assert len(spots) == 15
    for spot in spots:
        T_nominal = _spot_frame(spot)
        for alpha, beta in itertools.product(TILTS_DEG, TILTS_DEG):
            T_tcp = T_nominal.copy()
            T_tcp[:3, :3] = T_nominal[:3, :3] @ _rot(0, math.radians(alpha)) @ _rot(1, math.radians(beta))
            for shift in (0.0, APPROACH_M, -APPROACH_M):
                T = T_tcp.copy()
                T[:3, 3] += shift * T_tcp[:3, 2]
                tf = _transform(T @ T_tcp_flange)
                for o in body_objs + tip_objs:
                    o.setTransform(tf)
                label = f"{spot['name']} alpha={alpha:g} beta={beta:g} shift={shift:+g}"
                for o in body_objs:
                    if any(_collides(o, w) for w in workpieces):
                        failures.append(f"{label}: body hits the workpiece")
                    failures += [f"{label}: body hits {name}" for name, other in others if _collides(o, other)]
                if shift == 0.0 and not any(_collides(t, w) for t in tip_objs for w in workpieces):
                    failures.append(f"{label}: tips do not touch the workpiece")
    assert not failures, "\n".join(failures[:20])

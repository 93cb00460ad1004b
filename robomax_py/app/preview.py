"""The meshcat view of a cell, animated along a program (`robomax preview`).

What is drawn, in the cell (world) frame, under the meshcat path `robomax/`:

- `cell/<role>/<name>`: every cell object (`scene.build_scene` poses, `geometry.shape_trimesh`
  meshes) in its role's colour (`palette.object_role`: part, clamp, fixture, dynamic);
- `robot/links/<k>`: the robot's visual geometry (its `RobotModel.visual_model`), `robot/tool/body`
  and `robot/tool/tips`: the gun's meshes in the flange frame, at the program's first pose;
- `spots/<seam>/<name>`: a marker at each spot and a triad at the TCP frame the program welds it
  with (the nominal spot frame when there is no program);
- `path/<k>_<kind>`: the TCP path, one line per phase, coloured by phase kind;
- an animation of the links and the tool on the program's own clock (frame k at k / fps seconds,
  the last at exactly the cycle time), played once when the page opens; dynamic objects are
  visible only inside their presence windows.

Poses under `robomax/` are in the cell frame; `robomax/` itself is shifted so that the point the
camera looks at (between the robot base and the spots) is the viewer's origin, which meshcat's orbit
controls always look at; the floor grid is shifted with it.

`write_html` writes one self-contained page (meshcat's `static_html`, which inlines the viewer's
three.js bundle and the scene); `serve` keeps a meshcat server running until interrupted. Both pages
carry the overlay of `preview_overlay` (cell name, legend, clock, play/pause, slider, current spot).
Both draw through the preview's own server (`preview_server`: meshcat's bridge bound to 127.0.0.1 unless
a host is given, its WebSocket opened only to the page's own Origin, nothing served but the viewer).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.app import palette
from robomax_py.app.preview_overlay import inject, overlay_facts, overlay_html
from robomax_py.app.preview_parts import CarriedPart, carried_parts
from robomax_py.app.preview_program import ShownProgram
from robomax_py.app.preview_server import LOOPBACK
from robomax_py.errors import PreviewError, RobotModelError
from robomax_py.plan.poses import nominal_rotation
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.geometry import load_mesh, shape_trimesh
from robomax_py.spec import Box, Capsule, CellSpec, Cylinder, Shape, Sphere
from robomax_py.world.scene import build_scene
from robomax_py.world.voxels import VoxelMap

DEFAULT_FPS = 30
ROOT = "robomax"
SPOT_MARKER_RADIUS_M = 0.006
TRIAD_SCALE_M = 0.06
# Camera: looks at the centre of the cell objects from this direction (world frame, unit-free).
CAMERA_DIRECTION = (-0.75, -1.0, 0.8)
CAMERA_DISTANCE_FACTOR = 1.05
CAMERA_MIN_DISTANCE_M = 2.5
FLOOR_MARGIN_M = 1.0
FLOOR_THICKNESS_M = 0.01
# A light background (meshcat's default is a dark blue gradient), RGB in [0, 1].
BACKGROUND_TOP = [0.98, 0.98, 0.99]
BACKGROUND_BOTTOM = [0.78, 0.81, 0.86]


@dataclass(frozen=True, slots=True)
class PreviewContent:
    """What `populate` drew: meshcat paths (relative to the visualizer) and their colours.

    objects : ((path, role, colour), ...) cell objects.
    robot : (path, ...) robot link meshes; tool : (path, ...) tool meshes.
    path_lines : ((path, kind, colour), ...) TCP path pieces.
    frames : number of animation frames (0 without a program).
    fps : animation frame rate, 1/s.
    duration : cycle time, s.
    """

    objects: tuple[tuple[str, str, int], ...]
    robot: tuple[str, ...]
    tool: tuple[str, ...]
    spots: tuple[str, ...]
    path_lines: tuple[tuple[str, str, int], ...]
    frames: int
    fps: int
    duration: float
    voxels: int = 0                  # blocked voxel leaves drawn (`--voxels`)


def frame_times(duration: float, fps: int) -> FloatArray:
    """Animation frame numbers on the real timeline: 0, 1, ..., then the cycle time x fps.

    Returns
    -------
    (m,) float
        Frame numbers (time = frame / fps, s); m = ceil(duration * fps) + 1, the last frame at exactly
        `duration`. A zero duration gives no frames.
    """
    if duration <= 0.0:
        return np.zeros(0)
    n = max(1, math.ceil(duration * fps - 1e-9))
    frames = np.arange(n + 1, dtype=float)
    frames[-1] = duration * fps
    return frames


def populate(vis: Any, cell: CellSpec, robot: RobotModel, program: ShownProgram, fps: int = DEFAULT_FPS,
             voxels: VoxelMap | None = None) -> PreviewContent:
    """Draw the cell, robot, tool, spots and TCP path into a meshcat visualizer and animate it.

    Parameters
    ----------
    vis : meshcat.Visualizer
        Drawn into under `robomax/`.
    robot : RobotModel
        The cell's robot with its tool mounted (`cell_io.load_cell_robot`).
    program : ShownProgram
        The motion; a single sample shows the robot standing still (no animation).
    fps : int
        Animation frames per second of program time.
    voxels : VoxelMap, optional
        Drawn as the centres of its blocked leaves (base frame), each point the precision limit wide.

    Raises
    ------
    RobotModelError
        A link or tool mesh cannot be read.
    """
    import meshcat.animation as mc_anim
    import meshcat.geometry as g

    T_world_base = np.asarray(cell.T_world_base, dtype=float)
    root = vis[ROOT]
    root.delete()

    objects = _draw_objects(root, cell, robot)
    links = _link_nodes(robot)
    for node in links:
        root[node.path].set_object(_mesh_geometry(node.vertices, node.faces), g.MeshLambertMaterial(color=palette.ROBOT))
    tool = _draw_tool(root, cell)

    q0 = program.q[0]
    poses0 = _node_poses(robot, links, T_world_base, q0)
    for path, T in poses0.items():
        root[path].set_transform(T)

    carried = carried_parts(cell, [{"seam": s.seam, "name": s.name, "t_arrive": s.t_arrive, "t_leave": s.t_leave}
                                   for s in program.spots])
    parts = _draw_parts(root, carried)
    _pose_parts(root, carried, parts, float(program.t[0]), T_world_base @ fk_tcp(robot, q0))
    spots = _draw_spots(root, cell, robot, program)
    lines = _draw_path(root, robot, program, T_world_base)
    n_voxels = _draw_voxels(root, voxels, T_world_base) if voxels is not None else 0

    frames = frame_times(program.duration, fps)
    if len(frames):
        anim = mc_anim.Animation(default_framerate=fps)
        qs = program.q_at(program.t[0] + frames / fps)
        dynamic = [(p, obj) for (p, role, _), obj in zip(objects, (*cell.objects, *cell.dynamic)) if role == "dynamic"]
        for frame, q in zip(frames, qs):
            at = anim.at_frame(root, float(frame))
            for path, T in _node_poses(robot, links, T_world_base, q).items():
                at[path].set_transform(T)
            for path, obj in dynamic:
                at[path].set_property("visible", "boolean", _present(obj.present, float(frame) / fps))
            _pose_parts(at, carried, parts, float(frame) / fps, T_world_base @ fk_tcp(robot, q), animated=True)
        vis.set_animation(anim, play=True, repetitions=1)
    _place_camera(vis, cell, robot)
    return PreviewContent(
        objects=tuple((f"{ROOT}/{p}", role, c) for p, role, c in objects),
        robot=tuple(f"{ROOT}/{n.path}" for n in links),
        tool=tuple(f"{ROOT}/{p}" for p in tool),
        spots=tuple(f"{ROOT}/{p}" for p in spots),
        path_lines=tuple((f"{ROOT}/{p}", kind, c) for p, kind, c in lines),
        frames=len(frames),
        fps=fps,
        duration=program.duration,
        voxels=n_voxels,
    )


def write_html(path: Path, cell: CellSpec, robot: RobotModel, program: ShownProgram, fps: int = DEFAULT_FPS,
               voxels: VoxelMap | None = None) -> PreviewContent:
    """Write the preview as one self-contained HTML page (atomically), with its overlay; works offline.

    A meshcat server runs only while the page is made (meshcat builds the page from its scene).
    """
    from robomax_py.io.files import write_atomic

    overlay = overlay_html(overlay_facts(cell, program, voxels is not None))
    vis = _visualizer()
    try:
        content = populate(vis, cell, robot, program, fps, voxels)
        html = inject(vis.static_html(), overlay)
    finally:
        _close(vis)
    write_atomic(path, html)
    return content


def serve(cell: CellSpec, robot: RobotModel, program: ShownProgram, announce: Callable[[str], None], fps: int = DEFAULT_FPS,
          voxels: VoxelMap | None = None, host: str = LOOPBACK, port: int | None = None) -> None:
    """Start a meshcat server with the preview, announce its URL, and serve until Ctrl-C (then return).

    Parameters
    ----------
    host : str
        The address (or host name) the web page and its WebSocket are served on; loopback by default.
        The URL announced is the one bound.
    port : int, optional
        The web port; by default the first free one from 7000 (meshcat's habit).

    Raises
    ------
    PreviewError
        The server cannot listen there (address not of this machine, port in use).
    """
    import time

    vis = _visualizer(host, port, overlay_html(overlay_facts(cell, program, voxels is not None)))
    try:
        populate(vis, cell, robot, program, fps, voxels)
        announce(vis.url())
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        return                               # Ctrl-C is how a preview ends (docs/cell-files.md, "Commands and exit codes": exit 0)
    finally:
        _close(vis)


def _visualizer(host: str = LOOPBACK, port: int | None = None, overlay: str | None = None) -> Any:
    """A meshcat visualizer drawing into its own preview server (`preview_server`), which it stops
    in `_close`; meshcat's own URL banner is not printed. `overlay`: an HTML fragment the server puts
    into the page it serves."""
    import contextlib
    import io

    import meshcat

    proc, zmq_url = _start_server(host, port, overlay)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            vis = meshcat.Visualizer(zmq_url=zmq_url)
    except BaseException:
        _stop(proc)
        raise
    vis.window.server_proc = proc
    return vis


def _start_server(host: str, port: int | None, overlay: str | None = None) -> tuple[Any, str]:
    """Start `preview_server` and return the process and its ZMQ URL.

    `overlay` goes to the server as the first line of its stdin (JSON), read before it listens; no
    size limit, unlike an argument, and nothing on disk. The server stays in this process group (a Ctrl-C or a signal to the group ends it too) and
    stops by itself when its stdin, a pipe kept open by this process, closes (this process ended,
    however). Its stderr goes to the null device: it says what went wrong on stdout.
    """
    import os
    import subprocess
    import sys

    import robomax_py

    package_root = str(Path(robomax_py.__file__).resolve().parents[1])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([package_root, *[p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]])
    args = [sys.executable, "-u", "-m", "robomax_py.app.preview_server", "--host", host]
    if port is not None:
        args += ["--port", str(port)]
    if overlay is not None:
        args.append("--overlay-stdin")
    proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    if overlay is not None:
        assert proc.stdin is not None
        try:
            proc.stdin.write(json.dumps(overlay).encode("ascii") + b"\n")
            proc.stdin.flush()
        except BrokenPipeError:
            pass                                  # it exited already; said below, from its stdout
    found: dict[str, str] = {}
    assert proc.stdout is not None
    for raw in proc.stdout:                       # ends at end of file: the server exited
        key, _, value = raw.decode("utf-8", "replace").strip().partition("=")
        found[key] = value
        if key in ("web_url", "error"):
            break
    proc.stdout.close()
    if "web_url" not in found or "zmq_url" not in found:
        _stop(proc)
        raise PreviewError(found.get("error") or f"the preview server exited (code {proc.returncode}) before listening")
    return proc, found["zmq_url"]


def _present(windows: tuple[tuple[float, float], ...] | None, t: float) -> bool:
    """Whether a dynamic object exists at program time t, s (no windows: always)."""
    return windows is None or any(a <= t <= b for a, b in windows)


def _close(vis: Any) -> None:
    proc = getattr(vis.window, "server_proc", None)
    if proc is not None:
        _stop(proc)


def _stop(proc: Any) -> None:
    proc.kill()
    proc.wait()
    for pipe in (proc.stdin, proc.stdout):
        if pipe is not None and not pipe.closed:
            pipe.close()


# --------------------------------------------------------------------------------------------------
# drawing


@dataclass(frozen=True, slots=True, eq=False)
class _LinkNode:
    """One visual geometry of the robot: its mesh in the geometry frame and where it is attached."""

    path: str
    geometry_index: int
    vertices: FloatArray
    faces: Any


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "_"


def _mesh_geometry(vertices: FloatArray, faces: Any) -> Any:
    import meshcat.geometry as g

    return g.TriangularMeshGeometry(np.asarray(vertices, dtype=np.float32), np.asarray(faces, dtype=np.uint32))


def _draw_objects(root: Any, cell: CellSpec, robot: RobotModel) -> list[tuple[str, str, int]]:
    import meshcat.geometry as g

    scene = build_scene(cell, robot)
    T_world_base = np.asarray(cell.T_world_base, dtype=float)
    drawn = []
    for specs, posed, dynamic in ((cell.objects, scene.obstacles, False), (cell.dynamic, scene.dynamic, True)):
        for spec, obj in zip(specs, posed):
            role = palette.object_role(spec, dynamic=dynamic)
            colour = palette.ROLE_COLOURS[role]
            mesh = shape_trimesh(spec.shape)
            opacity = palette.DYNAMIC_OPACITY if dynamic else 1.0
            path = f"cell/{role}/{_safe(obj.name)}"
            root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces),
                                  g.MeshLambertMaterial(color=colour, opacity=opacity))
            root[path].set_transform(T_world_base @ np.asarray(obj.T_base_object, dtype=float))
            drawn.append((path, role, colour))
    return drawn


def _draw_parts(root: Any, carried: list[CarriedPart]) -> list[str]:
    """The transfers' parts (pick and place), in the workpiece colour."""
    import meshcat.geometry as g

    drawn = []
    for item in carried:
        mesh = shape_trimesh(item.part.shape)
        path = f"cell/carried/{_safe(item.name)}"
        root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces), g.MeshLambertMaterial(color=palette.ROLE_COLOURS["part"]))
        drawn.append(path)
    return drawn


def _pose_parts(at: Any, carried: list[CarriedPart], paths: list[str], t: float, T_world_tcp: FloatArray,
                animated: bool = False) -> None:
    """Each part where it is at program time t (an animation frame's properties are typed)."""
    for item, path in zip(carried, paths):
        T = item.pose(t, T_world_tcp)
        if animated:
            at[path].set_property("visible", "boolean", T is not None)
        else:
            at[path].set_property("visible", T is not None)
        if T is not None:
            at[path].set_transform(T)


def _draw_tool(root: Any, cell: CellSpec) -> list[str]:
    import meshcat.geometry as g

    drawn = []
    for part, file, colour in (("body", cell.tool.body, palette.TOOL_BODY), ("tips", cell.tool.tips, palette.TOOL_TIPS)):
        try:
            mesh = load_mesh(Path(file))
        except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
            raise RobotModelError(cell.tool.source, part, f"cannot read mesh {file}: {exc}") from None
        path = f"robot/tool/{part}"
        root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces), g.MeshLambertMaterial(color=colour))
        drawn.append(path)
    return drawn


def _link_nodes(robot: RobotModel) -> list[_LinkNode]:
    nodes = []
    for k, obj in enumerate(robot.visual_model.geometryObjects):
        mesh_path = str(obj.meshPath or "")
        if mesh_path and Path(mesh_path).is_file():
            try:
                mesh = load_mesh(Path(mesh_path), np.asarray(obj.meshScale, dtype=float))
            except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
                raise RobotModelError(robot.source, f"link {obj.name}", f"cannot read mesh {mesh_path}: {exc}") from None
        else:
            shape = _coal_shape(obj.geometry)
            if shape is None:
                continue                       # a geometry type meshcat cannot show (e.g. a plane)
            mesh = shape_trimesh(shape)
        nodes.append(_LinkNode(f"robot/links/{k}_{_safe(obj.name)}", k, np.asarray(mesh.vertices, dtype=float), mesh.faces))
    return nodes


def _coal_shape(geom: Any) -> Shape | None:
    """The cell-file shape of a coal primitive, or None for other geometry."""
    import coal

    if isinstance(geom, coal.Box):
        h = np.asarray(geom.halfSide, dtype=float)
        return Box((2 * float(h[0]), 2 * float(h[1]), 2 * float(h[2])))
    if isinstance(geom, coal.Capsule):
        return Capsule(float(geom.radius), 2 * float(geom.halfLength))
    if isinstance(geom, coal.Cylinder):
        return Cylinder(float(geom.radius), 2 * float(geom.halfLength))
    if isinstance(geom, coal.Sphere):
        return Sphere(float(geom.radius))
    return None


def _node_poses(robot: RobotModel, links: list[_LinkNode], T_world_base: FloatArray, q: FloatArray) -> dict[str, FloatArray]:
    """World poses (4, 4) of every link node and of the tool (flange frame) at joint values q."""
    data = robot.model.createData()
    gdata = pin.GeometryData(robot.visual_model)
    q = np.asarray(q, dtype=float)
    pin.framesForwardKinematics(robot.model, data, q)
    pin.updateGeometryPlacements(robot.model, data, robot.visual_model, gdata)
    poses = {n.path: T_world_base @ gdata.oMg[n.geometry_index].homogeneous for n in links}
    poses["robot/tool"] = T_world_base @ data.oMf[robot.flange_frame_id].homogeneous
    return poses


def _draw_spots(root: Any, cell: CellSpec, robot: RobotModel, program: ShownProgram) -> list[str]:
    import meshcat.geometry as g

    T_world_base = np.asarray(cell.T_world_base, dtype=float)
    welded = {(s.seam, s.name): s for s in program.spots}
    drawn = []
    for seam in cell.seams:
        for spot in seam.spots:
            path = f"spots/{_safe(seam.name)}/{_safe(spot.name)}"
            shown = welded.get((seam.name, spot.name))
            if shown is not None:
                q = program.q_at(np.array([shown.t_arrive]))[0]
                T = T_world_base @ fk_tcp(robot, q)
            else:
                T = np.eye(4)
                T[:3, :3] = nominal_rotation(spot)
                T[:3, 3] = spot.xyz
            root[path].set_transform(T)
            root[f"{path}/marker"].set_object(g.Sphere(SPOT_MARKER_RADIUS_M), g.MeshLambertMaterial(color=palette.SPOT))
            root[f"{path}/frame"].set_object(g.triad(TRIAD_SCALE_M))
            drawn.append(path)
    return drawn


def _draw_path(root: Any, robot: RobotModel, program: ShownProgram, T_world_base: FloatArray) -> list[tuple[str, str, int]]:
    import meshcat.geometry as g

    if len(program.t) < 2:
        return []
    p_base = fk_tcp(robot, program.q)[:, :3, 3]
    p = p_base @ T_world_base[:3, :3].T + T_world_base[:3, 3]
    drawn = []
    for k, phase in enumerate(program.phases):
        if phase.kind == "weld" or phase.i_end <= phase.i_start:
            continue                          # at rest: the spot marker shows where
        colour = palette.phase_colour(phase.kind)
        path = f"path/{k:04d}_{phase.kind}"
        points = np.asarray(p[phase.i_start:phase.i_end + 1], dtype=np.float32).T
        root[path].set_object(g.Line(g.PointsGeometry(points), g.LineBasicMaterial(color=colour)))
        drawn.append((path, phase.kind, colour))
    return drawn


def _draw_voxels(root: Any, voxels: VoxelMap, T_world_base: FloatArray) -> int:
    """The blocked leaves' centres as one point cloud (world frame); how many."""
    import meshcat.geometry as g

    blocked = ~voxels.free
    centres = voxels.corner[blocked] + voxels.edge[blocked, None] / 2
    points = centres @ T_world_base[:3, :3].T + T_world_base[:3, 3]
    colour = np.tile(np.array([(palette.VOXEL >> s & 0xFF) / 255.0 for s in (16, 8, 0)], dtype=np.float32)[:, None],
                     (1, len(points)))
    root["voxels"].set_object(g.PointCloud(np.asarray(points.T, dtype=np.float32), colour, size=float(voxels.precision)))
    return len(points)


def _place_camera(vis: Any, cell: CellSpec, robot: RobotModel) -> None:
    """Look between the robot base and the spots from CAMERA_DIRECTION, far enough to see both; a floor
    plate under the cell; light background."""
    import meshcat.geometry as g

    base = np.asarray(cell.T_world_base, dtype=float)[:3, 3]
    spots = [np.asarray(s.xyz, dtype=float) for seam in cell.seams for s in seam.spots]
    pts = np.array([base, *spots, *(np.asarray(o.T_world_object, dtype=float)[:3, 3] for o in cell.objects)])
    work = np.mean(spots, axis=0) if spots else (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    target = (base + work) / 2.0
    target[2] = float(work[2])
    size = float(np.max(pts.max(axis=0) - pts.min(axis=0)))
    direction = np.array(CAMERA_DIRECTION, dtype=float)
    offset = direction / np.linalg.norm(direction) * max(CAMERA_MIN_DISTANCE_M, CAMERA_DISTANCE_FACTOR * size + 1.0)
    # meshcat's orbit controls always look at the viewer's origin: shift the cell so the target is
    # there. Paths under robomax/ keep their cell-frame poses relative to that shift. meshcat's grid
    # stays at the viewer's z = 0, so it is hidden and a floor plate is drawn at the cell's z = 0.
    shift = np.eye(4)
    shift[:3, 3] = -target
    vis[ROOT].set_transform(shift)
    vis["/Grid"].set_property("visible", False)
    lo = pts.min(axis=0) - FLOOR_MARGIN_M
    hi = pts.max(axis=0) + FLOOR_MARGIN_M
    floor = np.eye(4)
    floor[:3, 3] = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, -FLOOR_THICKNESS_M / 2.0]
    vis[f"{ROOT}/floor"].set_object(g.Box([float(hi[0] - lo[0]), float(hi[1] - lo[1]), FLOOR_THICKNESS_M]),
                                    g.MeshLambertMaterial(color=palette.FLOOR))
    vis[f"{ROOT}/floor"].set_transform(floor)
    # The camera sits in a frame rotated +90 deg about x (three.js is y-up): world (x, y, z) = local (x, -z, y).
    vis["/Cameras/default/rotated/<object>"].set_property("position", [float(offset[0]), float(offset[2]), float(-offset[1])])
    vis["/Background"].set_property("top_color", BACKGROUND_TOP)
    vis["/Background"].set_property("bottom_color", BACKGROUND_BOTTOM)


__all__ = [
    "DEFAULT_FPS",
    "PreviewContent",
    "frame_times",
    "populate",
    "serve",
    "write_html",
]

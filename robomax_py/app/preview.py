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
a host is given, its WebSocket opened only to the page's own Origin, nothing served but the viewer),
started and stopped by `preview_process`.

This module puts the view together and animates it; what is drawn is drawn by `preview_drawing`, the
camera, floor and background are set by `preview_camera`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.app import palette
from robomax_py.app.preview_camera import _place_camera
from robomax_py.app.preview_drawing import (
    ROOT,
    _draw_objects,
    _draw_parts,
    _draw_path,
    _draw_spots,
    _draw_tool,
    _draw_voxels,
    _link_nodes,
    _mesh_geometry,
    _node_poses,
    _pose_parts,
    _safe,
)
from robomax_py.app.preview_moving import draw_moving, pose_moving
from robomax_py.app.preview_overlay import inject, overlay_facts, overlay_html
from robomax_py.app.preview_parts import carried_parts
from robomax_py.app.preview_process import _close, _start_server, _stop
from robomax_py.app.preview_program import ShownProgram
from robomax_py.app.preview_server import LOOPBACK
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.spec import CellSpec
from robomax_py.world.voxels import VoxelMap

DEFAULT_FPS = 30


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
    moving = draw_moving(root, cell, robot, _safe)
    pose_moving(root, moving, float(program.t[0]), animated=False)
    objects += [(node.path, "dynamic", palette.ROLE_COLOURS["dynamic"]) for node in moving]
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
        standing = (*cell.objects, *(d for d in cell.dynamic if d.motion is None))
        dynamic = [(p, obj) for (p, role, _), obj in zip(objects, standing) if role == "dynamic"]
        for frame, q in zip(frames, qs):
            at = anim.at_frame(root, float(frame))
            for path, T in _node_poses(robot, links, T_world_base, q).items():
                at[path].set_transform(T)
            for path, obj in dynamic:
                at[path].set_property("visible", "boolean", _present(obj.present, float(frame) / fps))
            _pose_parts(at, carried, parts, float(frame) / fps, T_world_base @ fk_tcp(robot, q), animated=True)
            pose_moving(at, moving, float(frame) / fps, animated=True)
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


def _present(windows: tuple[tuple[float, float], ...] | None, t: float) -> bool:
    """Whether a dynamic object exists at program time t, s (no windows: always)."""
    return windows is None or any(a <= t <= b for a, b in windows)


__all__ = [
    "DEFAULT_FPS",
    "PreviewContent",
    "frame_times",
    "populate",
    "serve",
    "write_html",
]

"""The meshcat view of a station (`robomax preview STATION OUT_DIR`): every robot animated on the
station clock of its replay (`verify_station`: each waits where its program waits for another), and
the interlock zones the plan's `<station>.station.json` gives.

What is drawn, in the station's world frame, under `robomax/`:

- `cell/<role>/<name>`: the station's objects (drawn once: every robot's cell holds them);
- `robots/<name>/robot/links/<k>` and `robots/<name>/robot/tool/{body,tips}`: each robot and its
  gun, as the single-robot preview draws them (`preview_drawing`);
- `spots/<name>/<seam>/<spot>`: a marker at each spot a robot welds, in that robot's colour;
- `zones/<k>_<signal>`: each interlock zone, a translucent box;
- an animation of all robots on the one clock (frame k at k / fps s, the last at the end of the
  replay), played once when the page opens.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.app import palette
from robomax_py.app.preview import DEFAULT_FPS, frame_times
from robomax_py.app.preview_camera import _place_camera
from robomax_py.app.preview_drawing import (
    ROOT,
    _draw_objects,
    _draw_tool,
    _link_nodes,
    _mesh_geometry,
    _node_poses,
)
from robomax_py.app.preview_server import LOOPBACK
from robomax_py.errors import ProgramError
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.transforms import pose_matrix
from robomax_py.verify_station.timeline import StationMotion

ZONE_COLOUR = 0xFFB000
ZONE_OPACITY = 0.25
SPOT_RADIUS_M = 0.012
# Robot colours after the first (which keeps the preview's robot colour), to tell them apart.
ROBOT_COLOURS = (palette.ROBOT, 0x8FB8DE, 0xC9A0DC, 0x9FD8A0, 0xE8C07D, 0xD98C8C)


@dataclass(frozen=True, slots=True, eq=False)
class ShownRobot:
    """A robot of the station as shown: its name, cell view, model and motion on the station clock."""

    name: str
    cell: CellSpec
    robot: RobotModel
    motion: StationMotion


@dataclass(frozen=True, slots=True, eq=False)
class InterlockZone:
    """A zone two robots share: the signal that clears it and its box, T_world_zone (4, 4) at the
    box's centre, `size` its full extents (m)."""

    signal: str
    T_world_zone: FloatArray
    size: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class StationPreviewContent:
    robots: tuple[str, ...]          # meshcat paths of each robot's group
    zones: tuple[str, ...]
    frames: int
    duration: float


def read_zones(path: Path) -> tuple[InterlockZone, ...]:
    """The interlock zones of `<station>.station.json` (`interlocks[].zone`: `{box: [x, y, z], pose:
    {xyz, rpy (deg)}}` or `{min: [x, y, z], max: [x, y, z]}`, m, in the world; a zone given by name,
    as `robomax plan` writes it, is drawn from its `region`, `{min, max}`, where the robots would
    meet); none when the file or its zones are missing."""
    if not path.is_file():
        return ()
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ProgramError(path, None, f"cannot read the station file: {exc}") from None
    out = []
    interlocks = data.get("interlocks", []) if isinstance(data, dict) else []
    for i, entry in enumerate(interlocks if isinstance(interlocks, list) else []):
        zone = entry.get("zone") if isinstance(entry, dict) else None
        key = f"interlocks[{i}].zone"
        if not isinstance(zone, dict) and isinstance(entry, dict) and isinstance(entry.get("region"), dict):
            zone, key = entry["region"], f"interlocks[{i}].region"
        if not isinstance(zone, dict):
            continue
        signal = str(entry.get("signal", f"zone{i}"))
        try:
            if "min" in zone:
                lo, hi = np.asarray(zone["min"], dtype=float), np.asarray(zone["max"], dtype=float)
                T, size = pose_matrix((lo + hi) / 2.0, [0.0, 0.0, 0.0]), hi - lo
            else:
                pose = zone.get("pose", {})
                T = pose_matrix(np.asarray(pose.get("xyz", [0, 0, 0]), dtype=float),
                                np.radians(np.asarray(pose.get("rpy", [0, 0, 0]), dtype=float)))
                size = np.asarray(zone["box"], dtype=float)
        except (KeyError, TypeError, ValueError) as exc:
            raise ProgramError(path, key, f"expected {{box, pose}} or {{min, max}}: {exc}") from None
        if size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
            raise ProgramError(path, key, "a zone needs three positive extents")
        out.append(InterlockZone(signal, T, (float(size[0]), float(size[1]), float(size[2]))))
    return tuple(out)


def populate_station(vis: Any, robots: Sequence[ShownRobot], zones: Sequence[InterlockZone] = (),
                     fps: int = DEFAULT_FPS) -> StationPreviewContent:
    """Draw the station and animate every robot on the one clock (see the module docstring)."""
    import meshcat.animation as mc_anim
    import meshcat.geometry as g

    root = vis[ROOT]
    root.delete()
    first = robots[0]
    _draw_objects(root, first.cell, first.robot)
    drawn = []
    for k, shown in enumerate(robots):
        group = root["robots"][shown.name]
        links = _link_nodes(shown.robot)
        colour = ROBOT_COLOURS[k % len(ROBOT_COLOURS)]
        for node in links:
            group[node.path].set_object(_mesh_geometry(node.vertices, node.faces), g.MeshLambertMaterial(color=colour))
        _draw_tool(group, shown.cell)
        for path, T in _node_poses(shown.robot, links, np.asarray(shown.cell.T_world_base), shown.motion.q[0]).items():
            group[path].set_transform(T)
        for seam in shown.cell.seams:
            for spot in seam.spots:
                marker = root["spots"][shown.name][seam.name][spot.name]
                marker.set_object(g.Sphere(SPOT_RADIUS_M), g.MeshLambertMaterial(color=colour))
                marker.set_transform(pose_matrix(np.asarray(spot.xyz, dtype=float), [0.0, 0.0, 0.0]))
        drawn.append((group, links, shown))
    zone_paths = []
    for k, zone in enumerate(zones):
        node = root["zones"][f"{k}_{zone.signal}"]
        node.set_object(g.Box(list(zone.size)), g.MeshLambertMaterial(color=ZONE_COLOUR, transparent=True,
                                                                       opacity=ZONE_OPACITY))
        node.set_transform(zone.T_world_zone)
        zone_paths.append(f"{ROOT}/zones/{k}_{zone.signal}")
    duration = max(float(s.motion.t[-1]) for s in robots)
    frames = frame_times(duration, fps)
    if len(frames):
        anim = mc_anim.Animation(default_framerate=fps)
        times = frames / fps
        for group, links, shown in drawn:
            qs = shown.motion.at(times)
            T_world_base = np.asarray(shown.cell.T_world_base)
            for frame, q in zip(frames, qs):
                at = anim.at_frame(group, float(frame))
                for path, T in _node_poses(shown.robot, links, T_world_base, q).items():
                    at[path].set_transform(T)
        vis.set_animation(anim, play=True, repetitions=1)
    _place_camera(vis, first.cell, first.robot)
    return StationPreviewContent(tuple(f"{ROOT}/robots/{s.name}" for s in robots), tuple(zone_paths), len(frames),
                                 duration)


def write_station_html(path: Path, robots: Sequence[ShownRobot], zones: Sequence[InterlockZone] = (),
                       fps: int = DEFAULT_FPS) -> StationPreviewContent:
    """The station's preview as one self-contained HTML page (written atomically)."""
    from robomax_py.app.preview import _visualizer
    from robomax_py.app.preview_process import _close
    from robomax_py.io.files import write_atomic

    vis = _visualizer()
    try:
        content = populate_station(vis, robots, zones, fps)
        html = vis.static_html()
    finally:
        _close(vis)
    write_atomic(path, html)
    return content


def serve_station(robots: Sequence[ShownRobot], zones: Sequence[InterlockZone], announce: Callable[[str], None],
                  fps: int = DEFAULT_FPS, host: str = LOOPBACK, port: int | None = None) -> None:
    """Serve the station's preview (as `preview.serve` serves a cell's) until Ctrl-C."""
    import time

    from robomax_py.app.preview import _visualizer
    from robomax_py.app.preview_process import _close

    vis = _visualizer(host, port)
    try:
        populate_station(vis, robots, zones, fps)
        announce(vis.url())
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        return
    finally:
        _close(vis)


def shown_station(station_file: Path, programs: Path) -> tuple[list[ShownRobot], tuple[InterlockZone, ...]]:
    """The robots of the first program set of the station in `programs` (a folder or one program;
    as `verify` finds them), each on the clock of the set's replay, and the zones of its
    `<station>.station.json`."""
    from robomax_py.app.station_verify import verify_station_files
    from robomax_py.io.station import load_station

    _, members, report = verify_station_files(station_file, [programs])[0]
    shown = [ShownRobot(m.name, m.cell, m.robot, r.motion) for m, r in zip(members, report.members)
             if r.motion is not None]
    if not shown:
        raise ProgramError(programs, None, "no program of the station could be rebuilt: nothing to show")
    folder = programs if programs.is_dir() else programs.parent
    return shown, read_zones(folder / f"{load_station(station_file).name}.station.json")


__all__ = ["InterlockZone", "ShownRobot", "StationPreviewContent", "populate_station", "read_zones",
           "serve_station", "shown_station", "write_station_html"]

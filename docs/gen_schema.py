"""JSON Schemas of the files people write (cell, robot.yaml, tool.yaml), from the pydantic models.

The models in `robomax_py/io/cell_file*.py` and `robomax_py/io/robot.py` are what robomax accepts; this
script turns them into JSON Schema for editors (YAML completion and checking as you type) and into
the key tables of the documentation, with a one-line description of every key from DESCRIPTIONS
below. A key the models gain without a description here makes `python docs/gen_schema.py` fail, and
tests/test_docs_site.py checks that the committed schemas equal a fresh generation.

    python docs/gen_schema.py            # rewrite docs/schema/*.schema.json
    python docs/gen_schema.py --check    # exit 1 if they differ from the models
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from robomax_py.io.cell_file import CellFile
from robomax_py.io.robot import RobotFile, ToolFile

SCHEMA_DIR = Path(__file__).resolve().parent / "schema"

# What each key means, by "Model.key" (a subclass falls back to its bases). Units are the file's:
# metres, degrees, seconds.
DESCRIPTIONS: dict[str, str] = {
    # cell file
    "CellFile.robomax": "Format version of the cell file; 1.",
    "CellFile.name": "Name of the cell and of its programs; defaults to the file name without extension.",
    "CellFile.include": "Files merged into the cell (frames, objects, dynamic, seams, robot, tool), relative to this file.",
    "CellFile.frames": "Named frames, each a pose in its parent (the world, a frame or an object); see frames.md.",
    "FrameFile.name": "Unique frame name; not 'world', not an object's name.",
    "FrameFile.pose": "The frame's pose in its parent.",
    "FrameFile.parent": "The frame or object it is placed in; the world when absent.",
    "CellFile.robot": "The robot: which one, where it stands, its home posture.",
    "CellFile.tool": "Tool folder name in the library's tools/, or a path to a tool.yaml.",
    "CellFile.objects": "Static obstacles: fixtures, clamps, tables, the part.",
    "CellFile.seams": "Groups of weld spots; required unless the cell tends machines or picks and places.",
    "CellFile.process": "Weld process values shared by every spot.",
    "CellFile.planner": "Planner settings; every key optional.",
    "CellFile.dynamic": "Obstacles present only in time windows (a door, a turntable).",
    "CellFile.spot_lists": "CSV spot lists whose spots become seams after `seams` (docs/spot-lists.md).",
    "SpotListFile.file": "The CSV spot list, relative to the cell file.",
    "SpotListFile.part": "The object the spots lie on, whose frame the list's coordinates are in unless `frame` is given; normals are recovered from its surface.",
    "SpotListFile.units": "Units of the list's coordinates: m or mm.",
    "SpotListFile.frame": "The frame the list's coordinates are in when not the part's: a frame of the cell, an object or world.",
    "SpotListFile.max_distance": "m a spot may lie off the part's surface; further is an error naming the row.",
    "SpotListFile.ordered": "The `ordered` of every seam the list gives.",
    "SpotListFile.tolerance": "The `tolerance` of every seam the list gives.",
    "SpotListFile.grid": "The `grid` of every seam the list gives.",
    "CellFile.tending": "A machine-tending job instead of seams.",
    "CellFile.pick_place": "A pick-and-place job instead of seams.",
    "CellFile.continuation": "This cell is where a program's continuation runs (robomax replan writes it): times in "
                             "the continued program's clock, its actions done left out.",
    "ContinuationFile.cell": "The cell whose program this continues (for people reading the file).",
    "ContinuationFile.at": "s of the continued program's clock at which this program starts (where the robot stopped); "
                           "every window in the file moves to a clock starting here.",
    "ContinuationFile.done": "Actions the continued program completed, as seam/spot (a tending visit: tending/<visit>); "
                             "left out of this program.",
    "RobotRefFile.model": "Robot folder name in the library, or a path to a robot.yaml.",
    "RobotRefFile.base": "Where the robot's URDF root stands in the cell.",
    "RobotRefFile.frame": "The frame (or object) base is given in; the world when absent.",
    "RobotRefFile.home": "Start and end posture: one value per joint, deg (m for a prismatic joint).",
    "RobotRefFile.start": "Where programs start, at rest, when not at home (a continuation): one value per joint, deg "
                          "(m for a prismatic joint); they still end at home.",
    "RobotRefFile.joint_limits": "The controller's software limits, within the URDF's: one [min, max] per joint, deg (m "
                                  "for a prismatic joint), null where the URDF's range holds; plan and verify keep to "
                                  "them.",
    "RobotRefFile.controller": "Numbers the integrator's controller already holds (tool, user frame, inputs).",
    "PoseFile.xyz": "Position, m.",
    "PoseFile.rpy": "Roll, pitch, yaw in deg about the fixed X, Y, Z axes (R = Rz(yaw)·Ry(pitch)·Rx(roll)).",
    "RobotControllerFile.tool": "The controller's tool slot holding the tool's TCP.",
    "RobotControllerFile.frame": "The user frame every Cartesian target is stated in.",
    "RobotControllerFile.registers": "FANUC registers the programs may write.",
    "RobotControllerFile.inputs": "Controller input of each cell signal: a number or {number, name}.",
    "RobotControllerFile.outputs": "Controller output of each signal the robot sets for other robots of a station: a number or {number, name}.",
    "RobotControllerFile.weld": "call: each weld calls the program's spot_weld; package: the controller's spot instruction.",
    "ControllerFrameFile.number": "Slot number on the controller.",
    "ControllerFrameFile.name": "Name on the controller (RAPID data, UR variable); given means it exists there.",
    "UserFrameFile.pose": "The frame's pose in the cell's world.",
    "UserFrameFile.object": "Or: the frame sits at this object's pose.",
    "RegistersFile.position": "Position register numbers a program may write.",
    "RegistersFile.numeric": "Numeric register numbers a program may write.",
    "InputFile.number": "Input number on the controller.",
    "InputFile.name": "Input name in the controller's I/O configuration.",
    "OutputFile.number": "Output number on the controller.",
    "OutputFile.name": "Output name in the controller's I/O configuration.",
    "ObjectFile.name": "Unique name, used in messages and programs.",
    "ObjectFile.box": "Box full extents along its x, y, z, m; centred on its pose.",
    "ObjectFile.cylinder": "Cylinder along its local z, centred on its pose.",
    "ObjectFile.sphere": "Sphere centred on its pose.",
    "ObjectFile.capsule": "Capsule along its local z; length is the cylindrical part, the caps add radius at each end.",
    "ObjectFile.mesh": "Mesh file (any format trimesh reads, or a STEP part: .step, .stp), relative to the cell file.",
    "ObjectFile.units": "Unit of the numbers in the mesh file: m (default) or mm. A STEP file states its own and is "
                        "read in metres from it; there units is the unit of tolerance (default: the file's).",
    "ObjectFile.scale": "Further factor on the mesh after its units: one number or one per axis (default 1).",
    "ObjectFile.tolerance": "STEP only: largest distance between the mesh and the exact surface, in units "
                            "(default 0.1 mm).",
    "ObjectFile.pose": "Pose in the cell's world (or in frame); identity when absent.",
    "ObjectFile.frame": "The frame (or object) pose is given in; the world when absent.",
    "ObjectFile.workpiece": "The electrode tips may touch it (the part being welded); nothing else may.",
    "ObjectFile.signal": "A clamp's interlock input, waited for before welding near it.",
    "CylinderFile.radius": "Radius, m.",
    "CylinderFile.length": "Length along the local z axis, m.",
    "SphereFile.radius": "Radius, m.",
    "DynamicObjectFile.present": "Time windows [start, end] in s from program start in which the object is there.",
    "DynamicObjectFile.path": "A moving object: its timed poses in the world, position linear and rotation slerped "
                              "between them; there from the first to the last unless present says otherwise.",
    "DynamicObjectFile.repeat": "s between passes of the path (a conveyor bringing a part every period).",
    "DynamicObjectFile.count": "Passes of a repeated path; default the tending cycles, else 1.",
    "DynamicObjectFile.robot": "Another robot replaying a trajectory file: its links and tool are the obstacle.",
    "DynamicObjectFile.trajectory": "The other robot's robomax.trajectory/1 file, relative to the cell file.",
    "DynamicObjectFile.sweep": "m a moving object may move within the time one checked pose stands for; it counts "
                               "that much larger there (default 0.02 for a path, 0.05 for a robot).",
    "PathPoseFile.t": "s from program start.",
    "PathPoseFile.xyz": "Position, m, in the world.",
    "PathPoseFile.rpy": "Roll, pitch, yaw in deg about the fixed X, Y, Z axes.",
    "OtherRobotFile.model": "Folder name in robots/, or a path to a robot.yaml.",
    "OtherRobotFile.base": "The other robot's base in the world.",
    "OtherRobotFile.tool": "Its tool: folder name in robots/tools/, or a path to a tool.yaml; none when absent.",
    "SeamFile.name": "Unique seam name.",
    "SeamFile.ordered": "true: weld the spots in the listed order; false: the planner may reorder them.",
    "SeamFile.tolerance": "How far the gun may turn from the nominal orientation at each spot.",
    "SeamFile.frame": "The frame (or object) its spots are given in, unless a spot names its own; the world when absent.",
    "SeamFile.grid": "Samples per tolerance angle, ends included; the orientation grid has up to grid³ points.",
    "SeamFile.spots": "The weld spots.",
    "ToleranceFile.alpha": "Tilt about the TCP x axis allowed either way, deg.",
    "ToleranceFile.beta": "Tilt about the TCP y axis allowed either way, deg.",
    "ToleranceFile.gamma": "[min, max] spin about the electrode (TCP z) axis, deg.",
    "ToleranceFile.sides": "normal: the gun on the normal's side; either: on either side of the sheet, the "
                           "grid searched again turned 180 deg about the TCP x axis (extension).",
    "SpotFile.name": "Spot name, unique in its seam.",
    "SpotFile.xyz": "The weld point, m.",
    "SpotFile.normal": "Unit vector out of the sheet on the side the moving electrode comes from.",
    "SpotFile.direction": "Seam direction at the spot; sets the TCP x axis (made orthogonal to normal).",
    "SpotFile.weld_time": "This spot's weld time, s.",
    "SpotFile.schedule": "This spot's weld schedule number.",
    "SpotFile.alpha": "Pinned tilt alpha, deg (with beta and gamma).",
    "SpotFile.beta": "Pinned tilt beta, deg (with alpha and gamma).",
    "SpotFile.gamma": "Pinned spin gamma, deg (with alpha and beta).",
    "SpotFile.config": "Pinned configuration in the controller brand's words, e.g. S010 T101010.",
    "SpotFile.frame": "The frame (or object) xyz, normal and direction are given in; the seam's when absent.",
    "SpotFile.skip": "Leave the spot out of the plan.",
    "ProcessFile.weld_time": "Dwell at rest at every spot, s.",
    "ProcessFile.approach": "Straight approach and retract along the electrode axis at every spot, m.",
    "ProcessFile.clearance": "A configuration closer than this to an obstacle counts as a collision, m.",
    "ProcessFile.gun": "Weld gun number the programs name.",
    "ProcessFile.schedule": "Default weld schedule number.",
    "ProcessFile.interlock_distance": "A spot this close to a clamp with a signal waits for it, m.",
    "PlannerFile.seed": "Seed of every random choice; the same seed gives the same program.",
    "PlannerFile.speed": "Override of every programmed speed, fraction in (0, 1].",
    "PlannerFile.tcp_speed": "TCP speed on the approach and retract lines, m/s.",
    "PlannerFile.detour_speed": "Speed fraction of moves through detours.",
    "PlannerFile.detours": "Where detours are searched: roadmap, cspace, both, or learned (the learned C-space map alone).",
    "PlannerFile.detour_moves": "How detours move: ptp (joint-space moves) or lin (straight TCP lines through via points).",
    "PlannerFile.detour_tcp_speed": "TCP speed on the LIN lines of detours (detour_moves: lin), m/s.",
    "PlannerFile.learned": "The learned C-space map of detours: learned; read only then.",
    "LearnedMapFile.resolution": "Samples per axis of the A1-A3 map (8-60).",
    "LearnedMapFile.spacing": "Distance between the surface points the objects become, m.",
    "LearnedMapFile.inflation": "Added to the points' cover radius and the clearance, m.",
    "LearnedMapFile.training": "The model's training grid: coarse, or standard (about 30 times the training cost).",
    "LearnedMapFile.neurons": "Most hidden neurons of the RBF network; grown until it fits when absent.",
    "PlannerFile.dynamic": "timed: plan round dynamic objects in time; rest: wait at rest for them.",
    "PlannerFile.max_wait": "Longest wait at one place a timed search may propose, s.",
    "PlannerFile.transfers": "Pick and place: moves plans carried moves as every move; associative by the associative-memory table, k-NN graph, Dijkstra route and Jacobian interpolation (docs/associative.md).",
    "PlannerFile.cartesian_moves": "lin: approach, retract and detour lines as straight moves with fly-by; spline: a junction between two spots as one smooth Bézier TCP path, written as a spline block (KRL SPLINE, SRCL SPL) or short lines flown by, where that is faster (docs/bezier-paper.md).",
    "TendingFile.cycles": "How many times the sequence runs.",
    "TendingFile.gripper": "Seconds the gripper takes to close and to open.",
    "TendingFile.machines": "Machines whose doors close while they machine.",
    "TendingFile.stations": "Places the gripper grips or releases.",
    "TendingFile.sequence": "Station names of one cycle in order; default: the stations as listed.",
    "GripperFile.grip": "Seconds at rest to close the gripper.",
    "GripperFile.release": "Seconds at rest to open the gripper.",
    "MachineFile.name": "Machine name.",
    "MachineFile.door": "The door as an object: its shape and pose when closed.",
    "MachineFile.schedule": "When the door is closed: a fixed period (or give windows).",
    "MachineFile.windows": "Or the door's closed windows as they are, [start, end] s from program start, in order "
                           "([]: never closed).",
    "ScheduleFile.start": "First machining start (door closes), s.",
    "ScheduleFile.machining": "Seconds the door stays closed per part.",
    "ScheduleFile.period": "Seconds from one machining start to the next.",
    "ScheduleFile.count": "Number of machinings; default: the cycles.",
    "StationFile.name": "Station name.",
    "StationFile.xyz": "TCP position at the station, m.",
    "StationFile.rpy": "TCP orientation at the station, deg; the tool arrives and leaves along +z.",
    "StationFile.action": "grip or release.",
    "StationFile.machine": "The machine whose door the station lies behind.",
    "StationFile.frame": "The frame (or object) xyz and rpy are given in; the world when absent.",
    "StationFile.config": "Pinned configuration at the station.",
    "PickPlaceFile.gripper": "Seconds the gripper takes to close and to open.",
    "PickPlaceFile.unloaded": "TCP limits without a part.",
    "PickPlaceFile.parts": "Kinds of part carried.",
    "PickPlaceFile.locations": "Where parts lie.",
    "PickPlaceFile.transfers": "Moves of a part from one location to another, in order.",
    "TcpLimitsFile.v": "TCP speed, m/s.",
    "TcpLimitsFile.a_T": "Tangential TCP acceleration, m/s².",
    "TcpLimitsFile.a_R": "Radial (centripetal) TCP acceleration, m/s².",
    "TcpLimitsFile.j_T": "Rate of change of the tangential acceleration, m/s³.",
    "TcpLimitsFile.j_R": "Rate of change of the radial acceleration, m/s³.",
    "PartFile.mass": "Mass, kg; at most the robot's payload.",
    "PartFile.grasp": "The TCP in the part's frame while held.",
    "PartFile.limits": "TCP limits while this part is carried.",
    "LocationFile.name": "Location name.",
    "LocationFile.pose": "The part's frame when it lies here.",
    "LocationFile.frame": "The frame (or object) pose is given in; the world when absent.",
    "LocationFile.support": "Objects the part rests on here (it may touch them).",
    "TransferFile.part": "Which part.",
    "TransferFile.from": "Location it is taken from.",
    "TransferFile.to": "Location it is put down at.",
    # robot.yaml
    "RobotFile.name": "Must equal the folder name.",
    "RobotFile.urdf": "The URDF, relative to robot.yaml; its meshes by relative or package:// paths.",
    "RobotFile.flange": "URDF frame the tool mounts on.",
    "RobotFile.ik": "Inverse kinematics solver and its parameters.",
    "RobotFile.limits": "Acceleration and jerk limits; positions and velocities come from the URDF.",
    "RobotFile.controller": "The controller: brand, base frame, how it counts joints.",
    "RobotFile.collision": "Link pairs never checked against each other.",
    "RobotFile.srdf": "MoveIt SRDF whose disable_collisions pairs are honoured.",
    "RobotFile.payload": "Rated payload, kg.",
    "RobotFile.description": "Free text for listings.",
    "IkFile.solver": "opw, ur, numeric or table.",
    "IkFile.params": "Solver parameters; fitted from the URDF when absent (opw, ur).",
    "LimitsFile.acceleration": "Per joint, deg/s²; derived from the URDF velocity when absent.",
    "LimitsFile.jerk": "Per joint, deg/s³; derived when absent.",
    "LimitsFile.loaded": "Joint limits with the rated payload at the flange.",
    "LoadedLimitsFile.velocity": "Per joint, deg/s.",
    "LoadedLimitsFile.acceleration": "Per joint, deg/s².",
    "LoadedLimitsFile.jerk": "Per joint, deg/s³.",
    "ControllerFile.brand": "Whose configuration data programs carry, and the native dialect.",
    "ControllerFile.j23_coupling": "FANUC: the controller counts J3 from the horizontal.",
    "ControllerFile.pulses_per_degree": "Yaskawa: encoder pulses per degree of each axis.",
    "ControllerFile.base": "The controller's base frame in the URDF root frame.",
    "ControllerFile.joint_signs": "Controller value = sign × URDF value + zero; one ±1 per joint.",
    "ControllerFile.joint_zeros_deg": "The zero of each joint as the controller counts it, deg.",
    "CollisionFile.disable": "Pairs of link names never checked.",
    # tool.yaml
    "ToolFile.name": "Must equal the folder name.",
    "ToolFile.body": "Mesh of the tool body in the flange frame; collides with everything. A path, or "
                     "{mesh, units, scale, tolerance} for keys of its own.",
    "ToolFile.tips": "Mesh of the electrode tips or fingers; may touch workpieces only. A path, or "
                     "{mesh, units, scale, tolerance} for keys of its own.",
    "ToolFile.tcp": "The TCP in the flange frame; its z is the electrode closing axis.",
    "ToolFile.units": "Unit of the numbers in both mesh files: m (default) or mm; as beside a cell object's mesh "
                      "(docs/cad.md). A STEP states its own; there units is the unit of tolerance.",
    "ToolFile.scale": "Further factor on both meshes after their units: one number or one per axis (default 1).",
    "ToolFile.tolerance": "STEP only: largest distance between a mesh and the exact surface, in units "
                          "(default 0.1 mm, at least 0.01 mm).",
    "ToolFile.load": "The tool's load: {mass, cog}. Checked against the robot's rated payload; programs "
                     "declare it (RAPID tooldata, URScript set_payload). Absent: not stated.",
    "ToolLoadFile.mass": "The tool's mass, kg (> 0), with its bracket and anything else on the flange.",
    "ToolLoadFile.cog": "The tool's centre of gravity in the flange frame, m.",
    "ToolMeshFile.mesh": "The mesh file, relative to the tool.yaml: any format trimesh reads, or a STEP.",
    "ToolMeshFile.units": "Unit of this mesh's numbers (overrides the tool's units): m or mm.",
    "ToolMeshFile.scale": "Further factor on this mesh after its units (overrides the tool's scale).",
    "ToolMeshFile.tolerance": "STEP only: this mesh's meshing tolerance in units (overrides the tool's).",
}

FILES: dict[str, tuple[type[BaseModel], str]] = {
    "cell": (CellFile, "robomax cell file"),
    "robot": (RobotFile, "robomax robot.yaml"),
    "tool": (ToolFile, "robomax tool.yaml"),
}


def _models(root: type[BaseModel]) -> dict[str, type[BaseModel]]:
    """Every model reachable from root, by class name (the schema's $defs names)."""
    found: dict[str, type[BaseModel]] = {}

    def visit(tp: Any) -> None:
        if isinstance(tp, type) and issubclass(tp, BaseModel):
            if tp.__name__ in found:
                return
            found[tp.__name__] = tp
            for f in tp.model_fields.values():
                visit(f.annotation)
        for arg in getattr(tp, "__args__", ()) or ():
            visit(arg)
        for meta in getattr(tp, "__metadata__", ()) or ():
            visit(meta)
        origin = getattr(tp, "__origin__", None)
        if origin is not None and origin is not tp:
            visit(origin)

    visit(root)
    return found


def _description(model: type[BaseModel], key: str) -> str:
    for cls in model.__mro__:
        text = DESCRIPTIONS.get(f"{cls.__name__}.{key}")
        if text is not None:
            return text
    raise KeyError(f"docs/gen_schema.py: no description for {model.__name__}.{key}; add one to DESCRIPTIONS")


def schema(kind: str) -> dict[str, Any]:
    """The JSON Schema of one file kind, each property described."""
    root, title = FILES[kind]
    models = _models(root)
    out = root.model_json_schema(by_alias=True, mode="validation")
    out = {"$schema": "https://json-schema.org/draft/2020-12/schema", **out, "title": title}
    for name, body in [(root.__name__, out), *out.get("$defs", {}).items()]:
        model = models[name]
        for key, prop in body.get("properties", {}).items():
            prop.pop("title", None)
            prop["description"] = _description(model, key)
    return out


def render(kind: str) -> str:
    return json.dumps(schema(kind), indent=2, ensure_ascii=False) + "\n"


def _type(prop: dict[str, Any], kind_: str) -> str:
    if "$ref" in prop:
        name = prop["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{kind_}-{name.lower()})"
    if "anyOf" in prop:
        return " or ".join(t for t in (_type(p, kind_) for p in prop["anyOf"]) if t != "null")
    if "enum" in prop:
        return " \\| ".join(f"`{v}`" for v in prop["enum"])
    if "const" in prop:
        return f"`{prop['const']}`"
    kind = prop.get("type", "any")
    if kind == "array":
        item = _type(prop.get("items", {}), kind_)
        n = prop.get("minItems")
        if n is not None and n == prop.get("maxItems"):
            return f"{n} × {item}"
        return f"list of {item}"
    if kind == "object":
        extra = prop.get("additionalProperties")
        return f"mapping of text to {_type(extra, kind_)}" if isinstance(extra, dict) else "mapping"
    return {"number": "number", "integer": "integer", "string": "text", "boolean": "true/false"}.get(kind, kind)


def key_tables(kind: str) -> str:
    """Markdown: one table per mapping of the file, every key with its type, default and meaning."""
    root, _ = FILES[kind]
    full = schema(kind)
    sections = [(root.__name__, full), *full.get("$defs", {}).items()]
    parts = []
    for name, body in sections:
        rows = ["| key | type | default | meaning |", "|---|---|---|---|"]
        required = set(body.get("required", []))
        for key, prop in body.get("properties", {}).items():
            if key in required:
                default = "required"
            elif "default" not in prop:
                default = ""
            elif prop["default"] is None:
                default = "none"
            elif isinstance(prop["default"], dict) and prop["default"]:
                default = "its keys' defaults"
            else:
                default = "`" + json.dumps(prop["default"], ensure_ascii=False) + "`"
            rows.append(f"| `{key}` | {_type(prop, kind)} | {default} | {prop['description']} |")
        parts.append(f"#### `{name}` {{#{kind}-{name.lower()}}}\n\n" + "\n".join(rows))
    return "\n\n".join(parts) + "\n"


def main(argv: list[str]) -> int:
    check = "--check" in argv
    stale = []
    for kind in FILES:
        path = SCHEMA_DIR / f"{kind}.schema.json"
        text = render(kind)
        if check:
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                stale.append(path.name)
        else:
            SCHEMA_DIR.mkdir(exist_ok=True)
            path.write_text(text, encoding="utf-8")
    if stale:
        print("stale: " + ", ".join(stale) + " (run python docs/gen_schema.py)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""What a plan chose and why, as plain data (for --json) and as rich tables."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rich.table import Table

from robomax_py.export import SkippedFormat
from robomax_py.plan import PlanResult
from robomax_py.publish import CheckedProgram

KINDS = ("move", "detour", "approach", "weld", "retract", "wait")


def plan_report(result: PlanResult, seconds: float, written: list[Path],
                defaulted_limits: tuple[str, ...] = (), checked: Sequence[CheckedProgram] = (),
                skipped: Sequence[SkippedFormat] = ()) -> dict[str, Any]:
    """A JSON-ready summary: status, cycle time and its split, spots, detours, planning time,
    which of the robot's limits were derived rather than given (`RobotModel.defaulted_limits`),
    how each written program proved (`publish.CheckedProgram`) and which dialects `--format all`
    passed over for want of the robot file's data (`export.SkippedFormat`)."""
    report: dict[str, Any] = {
        "cell": result.cell, "robot": result.robot, "status": result.status, "message": result.message,
        "method": result.method, "planning_seconds": round(seconds, 3),
        "failures": [{"seam": f.seam, "spot": f.name, "reason": f.reason, "detail": f.detail} for f in result.failures],
        "files": [str(p) for p in written],
        "defaulted_limits": list(defaulted_limits),
        "programs": [
            {"format": c.format, "files": list(c.files), "bytes": sum(len(t.encode()) for t in c.files.values()),
             "rebuilt_joint_deg": round(c.difference.joint_deg, 6), "rebuilt_tcp_mm": round(c.difference.tcp_mm, 6),
             "rebuilt_time_ms": round(c.difference.time_s * 1000, 3), "write_cpu_s": round(c.write_seconds, 3),
             "prove_cpu_s": round(c.check_seconds, 3), "blends_rounded": c.blends_rounded}
            for c in checked
        ],
        "skipped_formats": [{"format": k.format, "robot_file": k.robot_file, "key": k.key, "why": k.why,
                             "message": k.message} for k in skipped],
    }
    if result.trajectory is None:
        return report
    split = {k: 0.0 for k in KINDS}
    for phase in result.trajectory.phases:
        split[phase.kind] = split.get(phase.kind, 0.0) + float(phase.t_end - phase.t_start)
    report["cycle_time"] = round(result.cycle_time, 4)
    if result.order is not None:
        o = result.order
        report["order"] = {
            "kept": o.kept, "note": o.note, "line": o.describe(),
            "searched_cycle": None if o.searched_cycle is None else round(o.searched_cycle, 4),
            "given_cycle": None if o.given_cycle is None else round(o.given_cycle, 4),
        }
    if result.clearance is not None:
        c = result.clearance
        report["clearance"] = {"mm": round(c.distance_m * 1000, 3), "t": round(c.t, 4), "between": c.between}
    report["split"] = {k: round(v, 4) for k, v in split.items()}
    report["tending"] = result.tending
    report["spots"] = [
        {"seam": s.seam, "spot": s.name, "t_arrive": round(s.t_arrive, 4),
         "alpha": round(math.degrees(s.angles[0]), 3), "beta": round(math.degrees(s.angles[1]), 3),
         "gamma": round(math.degrees(s.angles[2]), 3), "config": s.config}
        for s in result.spots
    ]
    report["detours"] = [
        {"between": t.label, "waypoints": len(t.waypoints), "checks_to_find": t.checks,
         "moves": "lin" if t.lin_targets is not None else "ptp"}
        for t in result.transitions if t.kind == "detour"
    ]
    # `planner.cartesian_moves: spline`: per junction between two spots, which way it moves and the
    # time of each (the spline's None where it has none: `note` says why).
    choices = [t for t in result.transitions if t.choice is not None]
    if choices:
        report["cartesian_moves"] = [
            {"between": t.label, "chosen": ch.chosen, "flyby_s": round(ch.flyby_time, 4),
             "spline_s": None if ch.spline_time is None else round(ch.spline_time, 4), "note": ch.note,
             "spline_points": None if t.spline is None else len(t.spline.targets),
             "bezier_deviation_mm": None if t.spline is None else round(t.spline.deviation_m * 1000.0, 3),
             "as_lines_s": None if t.spline is None or t.spline.lines_time is None else round(t.spline.lines_time, 4)}
            for t in choices if (ch := t.choice) is not None
        ]
    # Pick and place: each move's load and the overrides its limits asked for.
    slowed = [t for t in result.transitions if t.part is not None or t.tcp_speed is not None]
    if slowed:
        report["carried"] = [
            {"between": t.label, "part": t.part, "kind": t.kind, "speed": t.speed, "accel": t.accel,
             "tcp_speed_mm_s": None if t.tcp_speed is None else round(t.tcp_speed * 1000.0, 3)}
            for t in slowed
        ]
    if result.stats is not None:
        st = result.stats
        report["stats"] = {
            "candidates": st.candidates, "collision_checks": st.candidate_checks + st.sequencing_checks + st.verify_checks,
            "roadmap_checks": st.roadmap_checks, "sequencing_rounds": st.rounds, "dp_evaluations": st.dp_evaluations,
            "stage_seconds": {k: round(v, 3) for k, v in st.seconds.items()},
        }
        if st.learned is not None:
            m = st.learned
            report["learned_map"] = {
                "wrist_deg": [round(math.degrees(v), 3) for v in m.wrist], "resolution": m.resolution,
                "blocked_by_objects": m.blocked_by_objects, "blocked_by_itself": m.blocked_by_itself,
                "points": m.points, "points_in_reach": m.points_in_reach, "sphere_radius_m": round(m.sphere_radius, 4),
                "neurons": m.neurons, "weights": m.weights, "training_cached": m.training_cached,
                "training_cpu_s": round(m.training_cpu_seconds, 3), "training_checks": m.training_checks,
                "map_cpu_s": round(m.map_cpu_seconds, 3), "searches": m.searches, "found": m.found,
                "refused_segments": m.refused_segments, "refused_entries": m.refused_entries,
                "no_entry": m.no_entry, "no_path": m.no_path, "gave_up": m.gave_up,
            }
    return report


def report_tables(report: dict[str, Any]) -> list[Any]:
    head = Table.grid(padding=(0, 2))
    head.add_row("cell", f"{report['cell']} ({report['robot']}), {report['method']}")
    head.add_row("status", report["status"] if report["status"] == "planned" else f"{report['status']}: {report['message']}")
    if "cycle_time" in report:
        # A tending cell's stops are the gripper's actions (the trajectory's "weld" phases).
        word = {"weld": "grip/release"} if report.get("tending") else {}
        split = ", ".join(f"{word.get(k, k)} {v:.2f}" for k, v in report["split"].items() if v > 0)
        head.add_row("cycle time", f"{report['cycle_time']:.2f} s  ({split})")
        if "order" in report:
            head.add_row("order", report["order"]["line"])
        detours = ", ".join(f"{d['between']} ({'TCP lines, ' if d['moves'] == 'lin' else ''}{d['checks_to_find']} "
                            "checks)" for d in report["detours"])
        head.add_row("detours", detours or "none")
        moves = report.get("cartesian_moves", [])
        if moves:
            def move(m: dict[str, Any]) -> str:
                spline = "none: " + m["note"] if m["spline_s"] is None else f"{m['spline_s']:.3f} s"
                lines = "" if m["as_lines_s"] is None else f", as lines {m['as_lines_s']:.3f} s"
                return f"{m['between']}: {m['chosen']} (spline {spline}, fly-by {m['flyby_s']:.3f} s{lines})"

            head.add_row("splines", f"{sum(m['chosen'] == 'spline' for m in moves)} of {len(moves)} junctions; "
                         + "; ".join(move(m) for m in moves))
        carried = [c for c in report.get("carried", []) if c["part"]]
        if carried:
            head.add_row("carried", ", ".join(
                f"{c['part']} {c['between'].split(' -> ')[0]} ({'detour, ' if c['kind'] == 'detour' else ''}"
                f"speed {c['speed']:.2f}, accel {c['accel']:.2f})" for c in carried))
        if "clearance" in report:
            c = report["clearance"]
            head.add_row("clearance", f"{c['mm']:.1f} mm at t = {c['t']:.2f} s ({c['between']})")
    stages = report.get("stats", {}).get("stage_seconds", {})
    split = ", ".join(f"{k} {v:.2f}" for k, v in stages.items())
    head.add_row("planning", f"{report['planning_seconds']:.2f} s" + (f"  ({split})" if split else ""))
    if report.get("defaulted_limits"):
        head.add_row("limits", "derived from the URDF velocities (not in robot.yaml): "
                     + ", ".join(report["defaulted_limits"]))
    if "stats" in report:
        st = report["stats"]
        head.add_row("work", f"{st['candidates']} candidates, {st['collision_checks']:,} collision checks, "
                             f"{st['sequencing_rounds']} sequencing rounds")
    if "learned_map" in report:
        m = report["learned_map"]
        trained = "from the cache, trained in" if m["training_cached"] else "trained in"
        head.add_row("learned map", f"{m['points']:,} points ({m['points_in_reach']:,} in reach), {m['neurons']} neurons "
                     f"({trained} {m['training_cpu_s']:.1f} s CPU), {m['resolution']}^3 cells at wrist "
                     f"{m['wrist_deg']} deg; {m['found']} of {m['searches']} detour searches found, "
                     f"{m['refused_segments']} path segments refused by the exact check and repaired")
    for p in report.get("programs", []):
        rounded = " (its blends as the dialect rounds them; as planned, within the tolerances)" \
            if p.get("blends_rounded") else ""
        head.add_row("proven", f"{p['format']}: read back, rebuilt within {p['rebuilt_joint_deg']:.4f} deg, "
                               f"{p['rebuilt_tcp_mm']:.3f} mm, {p['rebuilt_time_ms']:.1f} ms of the plan{rounded}")
    for k in report.get("skipped_formats", []):
        head.add_row("not written", k["message"])
    for f in report["files"]:
        head.add_row("wrote", f)
    for f in report.get("removed", []):
        head.add_row("removed", f"{f} (an earlier plan's, not written this time)")
    out: list[Any] = [head]
    if report.get("spots"):
        tending = bool(report.get("tending"))
        spots = Table(title="stations in order" if tending else "spots in weld order", title_justify="left")
        for col in ("job" if tending else "seam", "station" if tending else "spot", "arrive (s)", "alpha", "beta",
                    "gamma (deg)", "config"):
            spots.add_column(col)
        for s in report["spots"]:
            spots.add_row(s["seam"], s["spot"], f"{s['t_arrive']:.2f}", f"{s['alpha']:g}", f"{s['beta']:g}",
                          f"{s['gamma']:g}", s["config"])
        out.append(spots)
    return out

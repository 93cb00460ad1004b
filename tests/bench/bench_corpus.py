"""The planner on the generated corpus, judged by an oracle that is not the planner (not a test):

    python tests/bench/bench_corpus.py [--count 200] [--seed 0] [--jobs 2] [--out DIR] [--quick]
                                       [--oracle-time 2.0] [--cpu-limit 900] [--cells CELL.yaml ...]

Cells come from `corpus_cells.py` (written into --out, default a temporary folder), or are given.
Each cell is planned in a fresh single-threaded process (`plan_cell`, CPU seconds of that process)
and judged by the oracle in the same process afterwards:

- per spot, in the cell file's order: some orientation of the seam's tolerance grid (SPEC §3,
  computed here) and some IK branch at which the spot and its approach line (the TCP `approach` m
  along the electrode axis, sampled every 5 mm in the same branch, the sweep between samples
  checked) are collision-free; up to 12 such configurations per IK branch. The oracle
  uses robomax's closed-form IK (`robot.solve.solve_all`) and its collision world
  (`world.collision.CollisionWorld`: the robot with the tool, tips allowed on workpieces) for this
  and for every connection below; nothing from `robomax_py.plan` (no candidates, roadmap, lifts,
  local maps or detours);
- per pair of consecutive stops of the given order (home, the spots as listed, home): a
  collision-free joint path between the approach points of one chosen configuration per spot,
  found by OMPL's RRT-Connect (joint space within the joint limits, each motion checked by the
  collision world's swept check, `--oracle-time` CPU seconds per query) unless the straight move is
  free. Configurations are chained forward through up to 3 per spot per IK branch.

So "feasible by the oracle" is a proof (the chain is a plan in the given order, which every
seam admits), and "infeasible by the oracle" only means the oracle found no way (for spots
without a free configuration, a proof over the grid). Printed: cells planned, feasible and
infeasible by the oracle, every cell the oracle connects but the planner does not (with the
planner's reason), planning CPU per cell (median, 90th percentile, max) and the cycle times.
`--quick`: a handful of small cells, as CI runs it; without OMPL installed, the oracle only tries
straight moves and reports a pair it cannot join straight as unknown.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

LINE_STEP_M = 0.005          # approach-line samples of the per-spot check
BRANCH_JUMP_RAD = 0.2        # a joint moving more between line samples: the branch switched
PER_BRANCH_KEPT = 12         # free configurations per IK branch and spot the oracle keeps
PER_BRANCH = 3               # of those, the ones the chain tries per branch (nearest the reached ones)
SOURCES = 3                  # reached configurations of the previous stop tried per configuration


# ----------------------------------------------------------------------------------------------
# The oracle


@dataclass
class OracleVerdict:
    verdict: str                         # feasible | infeasible | unknown
    detail: str = ""
    cpu: float = 0.0
    rrt_queries: int = 0
    straight: int = 0
    spots_without_configuration: list[str] = field(default_factory=list)
    failed_move: str = ""


def _rot(axis: int, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def spot_frames(spot: Any, seam: Any) -> np.ndarray:
    """(m, 4, 4) TCP poses (world) of a spot over its seam's tolerance grid, as SPEC §3 states
    them: z = -n, x = d made orthogonal to n, y = z x x; R = R_nominal Rx(a) Ry(b) Rz(g), `grid`
    values per angle with the ends included; nearest the nominal orientation first."""
    n = np.asarray(spot.normal, dtype=float)
    z = -n / np.linalg.norm(n)
    x = np.asarray(spot.direction, dtype=float)
    x = x - (x @ z) * z
    x /= np.linalg.norm(x)
    R0 = np.column_stack([x, np.cross(z, x), z])

    def axis(lo: float, hi: float) -> np.ndarray:
        return np.array([lo]) if hi - lo < 1e-12 else np.linspace(lo, hi, seam.grid)

    angles = [(a, b, g) for a in axis(-seam.alpha_max, seam.alpha_max) for b in axis(-seam.beta_max, seam.beta_max)
              for g in axis(*seam.gamma_range)]
    angles.sort(key=lambda abg: sum(abs(v) for v in abg))
    out = []
    for a, b, g in angles:
        T = np.eye(4)
        T[:3, :3] = R0 @ _rot(0, a) @ _rot(1, b) @ _rot(2, g)
        T[:3, 3] = spot.xyz
        out.append(T)
    return np.array(out)


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def spot_configurations(cell: Any, robot: Any, world: Any, seam: Any, spot: Any) -> tuple[np.ndarray, np.ndarray]:
    """The approach-point configurations (k, n) of a spot whose spot configuration and approach
    line (swept) are free, at most PER_BRANCH_KEPT per IK branch (orientations nearest the nominal
    first), and the IK branch of each. Joint values as the closed form gives them (one turn)."""
    from robomax_py.robot.solve import solve_all

    frames = spot_frames(spot, seam)
    T_base_world = np.linalg.inv(np.asarray(cell.T_world_base))
    steps = max(2, math.ceil(cell.process.approach / LINE_STEP_M) + 1)
    offsets = np.linspace(cell.process.approach, 0.0, steps)          # approach point -> spot
    poses = np.repeat(frames[:, None], steps, axis=1).copy()
    poses[..., :3, 3] += offsets[None, :, None] * frames[:, None, :3, 2]
    table = solve_all(robot, T_base_world[None, None] @ poses, expand_turns=False)     # (m, L, B, n)
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    oo, cc = np.nonzero(table.valid.all(axis=1))                      # (orientation, column) valid all along
    lines = table.q[oo, :, cc].copy()                                 # (c, L, n)
    lines[:, 1:] = lines[:, :1] + np.cumsum(_wrap(np.diff(lines, axis=1)), axis=1)
    ok = (np.abs(np.diff(lines, axis=1)).max(axis=(1, 2)) <= BRANCH_JUMP_RAD) if len(lines) else np.zeros(0, bool)
    ok &= ((lines >= lo - 1e-9) & (lines <= hi + 1e-9)).all(axis=(1, 2))
    lines, cc = lines[ok], cc[ok]
    if len(lines):
        ends_free = world.are_free(lines[:, -1]) & world.are_free(lines[:, 0])
        lines, cc = lines[ends_free], cc[ends_free]
    qs, branches = [], []
    kept: dict[int, int] = {}
    for line, col in zip(lines, cc):
        branch = int(table.branch[col])
        if kept.get(branch, 0) >= PER_BRANCH_KEPT:
            continue
        if not world.check_path(line).free:
            continue
        kept[branch] = kept.get(branch, 0) + 1
        qs.append(line[0])
        branches.append(branch)
    if not qs:
        return np.zeros((0, robot.dof)), np.zeros(0, dtype=int)
    return np.array(qs), np.array(branches)


class Connector:
    """Joint paths between two configurations: the straight move if free, else OMPL RRT-Connect
    (None without OMPL: unknown)."""

    def __init__(self, world: Any, robot: Any, time_limit: float, seed: int) -> None:
        self.world, self.time_limit = world, time_limit
        self.lo, self.hi = np.asarray(robot.limits.lower, dtype=float), np.asarray(robot.limits.upper, dtype=float)
        self.dof = robot.dof
        self.rrt_queries = self.straight = 0
        try:
            from ompl import base as ob
            from ompl import geometric as og
            from ompl import util as ou
        except ImportError:
            self.ompl = None
            return
        self.ompl = (ob, og)
        ou.setLogLevel(ou.LOG_NONE)
        ou.RNG.setSeed(seed)

    def straight_free(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        self.straight += 1
        return bool(self.world.check_segment(qa, qb).free)

    def connect(self, qa: np.ndarray, qb: np.ndarray) -> bool | None:
        if self.straight_free(qa, qb):
            return True
        if self.ompl is None:
            return None
        self.rrt_queries += 1
        ob, og = self.ompl
        space = ob.RealVectorStateSpace(self.dof)
        bounds = ob.RealVectorBounds(self.dof)
        for k in range(self.dof):
            bounds.setLow(k, float(self.lo[k]))
            bounds.setHigh(k, float(self.hi[k]))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        world, dof = self.world, self.dof

        def values(state: Any) -> np.ndarray:
            return np.array([state[k] for k in range(dof)])

        si.setStateValidityChecker(lambda s: bool(world.is_free(values(s))))

        class Swept(ob.MotionValidator):            # the collision world's swept check per motion
            def checkMotion(self, s1: Any, s2: Any) -> bool:          # OMPL's name
                return bool(world.check_segment(values(s1), values(s2)).free)

        validator = Swept(si)
        si.setMotionValidator(validator)
        si.setup()
        setup = og.SimpleSetup(si)
        start, goal = space.allocState(), space.allocState()
        for k in range(dof):
            start[k], goal[k] = float(qa[k]), float(qb[k])
        setup.setStartAndGoalStates(start, goal)
        setup.setPlanner(og.RRTConnect(si))
        solved = setup.solve(self.time_limit)
        return bool(solved) and setup.haveExactSolutionPath()


def oracle(cell: Any, robot: Any, time_limit: float = 2.0, seed: int = 0) -> OracleVerdict:
    """The oracle's verdict on a cell (see the module docstring)."""
    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    t0 = time.process_time()
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    stops: list[tuple[str, np.ndarray, np.ndarray]] = []
    missing = []
    for seam in cell.seams:
        for spot in seam.spots:
            qs, branches = spot_configurations(cell, robot, world, seam, spot)
            if len(qs) == 0:
                missing.append(f"{seam.name}/{spot.name}")
            stops.append((f"{seam.name}/{spot.name}", qs, branches))
    if missing:
        return OracleVerdict("infeasible", f"{len(missing)} spot(s) without a free configuration: "
                             + ", ".join(missing[:8]), time.process_time() - t0, spots_without_configuration=missing)
    home = np.asarray(cell.home, dtype=float)
    conn = Connector(world, robot, time_limit, seed)
    reached = [home]
    previous = "home"
    unknown = False
    for name, qs, branches in [*stops, ("home", home[None], np.zeros(1, dtype=int))]:
        # Up to PER_BRANCH configurations per branch, nearest the reached ones first.
        src = np.array(reached)
        dist = np.min(np.max(np.abs(qs[:, None, :] - src[None, :, :]), axis=2), axis=1)
        pick = []
        for b in np.unique(branches):
            idx = np.flatnonzero(branches == b)
            pick.extend(idx[np.argsort(dist[idx], kind="stable")][:PER_BRANCH].tolist())
        pick.sort(key=lambda i: dist[i])
        now: list[np.ndarray] = []
        for i in pick:
            order = np.argsort(np.max(np.abs(src - qs[i]), axis=1), kind="stable")[:SOURCES]
            for s in order:
                got = conn.connect(src[s], qs[i])
                if got:
                    now.append(qs[i])
                    break
                unknown |= got is None
            # Straight moves suffice on most pairs; a few reached configurations keep the chain open.
            if len(now) >= 4:
                break
        if not now:
            cpu = time.process_time() - t0
            move = f"{previous} -> {name}"
            if unknown:
                return OracleVerdict("unknown", f"no straight move {move} (OMPL not installed)", cpu,
                                     conn.rrt_queries, conn.straight, failed_move=move)
            return OracleVerdict("infeasible", f"no connection found {move}", cpu, conn.rrt_queries,
                                 conn.straight, failed_move=move)
        reached, previous = now, name
    return OracleVerdict("feasible", "", time.process_time() - t0, conn.rrt_queries, conn.straight)


# ----------------------------------------------------------------------------------------------
# One cell, in its own process


def run_one(path: Path, time_limit: float, plan: bool = True, judge: bool = True) -> dict[str, Any]:
    import robomax_py as rm

    cell = rm.load_cell(path)
    spec = cell.spec
    meta_file = path.with_suffix(".meta.json")
    meta = json.loads(meta_file.read_text()) if meta_file.is_file() else {}
    out: dict[str, Any] = {"cell": spec.name, "path": str(path), **meta,
                           "spots": sum(len(s.spots) for s in spec.seams), "seams": len(spec.seams)}
    if plan:
        t0 = time.process_time()
        result = rm.plan_cell(cell)
        out.update(status=result.status, message=result.message, cpu=time.process_time() - t0,
                   cycle=None if result.status != "planned" else round(result.cycle_time, 3),
                   rounds=None if result.stats is None else result.stats.rounds)
    if judge:
        out["oracle"] = asdict(oracle(spec, cell.robot, time_limit))
    return out


def _child(path: Path, result: Path, time_limit: float, cpu_limit: int, plan: bool, judge: bool) -> None:
    resource.setrlimit(resource.RLIMIT_CPU, (cpu_limit, cpu_limit + 5))
    data = run_one(path, time_limit, plan, judge)
    result.write_text(json.dumps(data), encoding="utf-8")
    sys.stdout.flush()
    os._exit(0)          # OMPL's bindings report leaks at interpreter exit; nothing is left to clean


def _run(path: Path, folder: Path, args: argparse.Namespace) -> dict[str, Any]:
    result = folder / f"{path.stem}.result.json"
    cmd = [sys.executable, __file__, "--one", str(path), "--result", str(result), "--oracle-time",
           str(args.oracle_time), "--cpu-limit", str(args.cpu_limit)]
    if args.no_oracle:
        cmd.append("--no-oracle")
    if args.no_plan:
        cmd.append("--no-plan")
    env = {**os.environ, "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    if result.is_file():
        data: dict[str, Any] = json.loads(result.read_text())
    else:
        data = {"cell": path.stem, "path": str(path), "status": "error",
                "message": f"exit {done.returncode}: " + (done.stderr.strip().splitlines() or ["(no output)"])[-1],
                "cpu": float(args.cpu_limit) if done.returncode < 0 else None}
    data["wall"] = time.perf_counter() - t0
    return data


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def report(rows: list[dict[str, Any]]) -> str:
    planned = [r for r in rows if r.get("status") == "planned"]
    verdict = {r["cell"]: (r.get("oracle") or {}).get("verdict", "-") for r in rows}
    feasible = [r for r in rows if verdict[r["cell"]] == "feasible"]
    infeasible = [r for r in rows if verdict[r["cell"]] == "infeasible"]
    unknown = [r for r in rows if verdict[r["cell"]] == "unknown"]
    missed = [r for r in feasible if r.get("status") != "planned"]
    beyond = [r for r in planned if verdict[r["cell"]] != "feasible"]
    cpu = [float(r["cpu"]) for r in rows if r.get("cpu") is not None]
    lines = [(f"cells {len(rows)}: planned {len(planned)}; oracle: feasible {len(feasible)}, infeasible "
              f"{len(infeasible)}, unknown {len(unknown)}"),
             (f"feasible by the oracle but not planned: {len(missed)}; planned where the oracle found no way: "
              f"{len(beyond)}"),
             (f"planning CPU per cell: median {_pct(cpu, 50):.1f} s, 90th percentile {_pct(cpu, 90):.1f} s, "
              f"max {max(cpu, default=float('nan')):.1f} s")]
    fails = [r for r in rows if r.get("status") != "planned"]
    fail_cpu = [float(r["cpu"]) for r in fails if r.get("cpu") is not None]
    if fail_cpu:
        lines.append(f"  of which not planned ({len(fails)}): median {_pct(fail_cpu, 50):.1f} s, max {max(fail_cpu):.1f} s")
    oracle_cpu = [float(r["oracle"]["cpu"]) for r in rows if r.get("oracle")]
    if oracle_cpu:
        lines.append(f"oracle CPU per cell: median {_pct(oracle_cpu, 50):.1f} s, max {max(oracle_cpu):.1f} s; "
                     f"RRT-Connect queries {sum(r['oracle']['rrt_queries'] for r in rows if r.get('oracle'))}")
    cycles = [float(r["cycle"]) for r in planned if r.get("cycle") is not None]
    if cycles:
        per_spot = [float(r["cycle"]) / r["spots"] for r in planned if r.get("cycle") is not None]
        lines.append(f"cycle: median {_pct(cycles, 50):.2f} s (range {min(cycles):.2f}-{max(cycles):.2f} s), "
                     f"median {_pct(per_spot, 50):.2f} s per spot")
    if missed:
        lines.append("feasible by the oracle, not planned:")
        for r in missed:
            lines.append(f"  {r['cell']}: {r.get('status')}: {r.get('message', '')[:300]}")
    if beyond:
        lines.append("planned, oracle found no way (the oracle's limits):")
        for r in beyond:
            lines.append(f"  {r['cell']}: {r['oracle']['verdict']}: {r['oracle']['detail'][:200]}")
    by: dict[str, list[int]] = {}
    for r in rows:
        key = str(r.get("family", "?"))
        got = by.setdefault(key, [0, 0, 0])
        got[0] += 1
        got[1] += r.get("status") == "planned"
        got[2] += verdict[r["cell"]] == "feasible"
    lines.append("per family (cells / planned / oracle-feasible): "
                 + ", ".join(f"{k} {v[0]}/{v[1]}/{v[2]}" for k, v in sorted(by.items())))
    lines.append("")
    lines.append(f"{'cell':<34} {'spots':>5} {'status':<10} {'cpu s':>7} {'cycle s':>8} {'oracle':<10} reason")
    for r in rows:
        o = r.get("oracle") or {}
        cyc = "" if r.get("cycle") is None else f"{r['cycle']:.3f}"
        cpu_s = "" if r.get("cpu") is None else f"{r['cpu']:.1f}"
        why = r.get("message", "") if r.get("status") != "planned" else o.get("detail", "")
        lines.append(f"{r['cell']:<34} {r.get('spots', ''):>5} {r.get('status', ''):<10} {cpu_s:>7} {cyc:>8} "
                     f"{o.get('verdict', '-'):<10} {why[:120]}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="corpus folder (default: a temporary one)")
    ap.add_argument("--cells", type=Path, nargs="*", default=None, help="plan these cells instead")
    ap.add_argument("--quick", action="store_true", help="a handful of small cells (CI's smoke run)")
    ap.add_argument("--oracle-time", type=float, default=2.0, help="CPU s per RRT-Connect query")
    ap.add_argument("--cpu-limit", type=int, default=900, help="CPU s per cell (plan and oracle)")
    ap.add_argument("--no-oracle", action="store_true")
    ap.add_argument("--no-plan", action="store_true")
    ap.add_argument("--json", type=Path, default=None, help="write every cell's result here")
    ap.add_argument("--one", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--result", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        _child(args.one, args.result, args.oracle_time, args.cpu_limit, not args.no_plan, not args.no_oracle)
        return
    import corpus_cells

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.out or Path(tmp)
        if args.cells:
            cells = list(args.cells)
        elif args.quick:
            cells = corpus_cells.write_corpus(folder, seed=args.seed, indices=corpus_cells.QUICK, max_spots=8)
        else:
            cells = corpus_cells.write_corpus(folder, args.count, args.seed)
        results = folder / "results"
        results.mkdir(parents=True, exist_ok=True)
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            rows = list(pool.map(lambda p: _run(p, results, args), cells))
        if args.json:
            args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
        print(report(rows))


if __name__ == "__main__":
    main()

"""The planner on the generated corpus, judged by an oracle that is not the planner (not a test):

    python tests/bench/bench_corpus.py [--count 200] [--seed 0] [--max-spots 80] [--jobs 2] [--out DIR]
        [--quick] [--oracle-checks 3000] [--cpu-limit 900] [--no-baselines | --baselines-every K] [--resume]
        [--cells CELL.yaml ...]

Cells come from `corpus_cells.py` (written into --out, default a temporary folder), or are given.
Each cell is planned in a fresh single-threaded process (`plan_cell`, CPU seconds of that process;
the imports are not counted), then judged by the oracle and re-planned by both baselines in the
same process, each stage within its CPU limit (the kernel's RLIMIT_CPU):

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
  collision world's swept check, at most `--oracle-checks` collision queries per query: a count,
  not a clock) where no straight move reaches the stop, at most 6 failed queries per stop.
  Configurations are chained forward: up to 3 per spot per IK branch are tried, each from the 3
  nearest reached at the previous stop, and the chain goes on from up to 4 reached.

So "feasible by the oracle" is a proof (the chain is a plan in the given order, which every
seam admits), and "infeasible by the oracle" only means the oracle found no way (for spots
without a free configuration, a proof over the grid). The baselines, planned with the same
detours and timing: the published method (paper 003 for the given order: the DP over every
orientation sample and branch, `PlanOptions(given_order=True)`) and teach-in (given order,
nominal orientation, first branch, `PlanOptions(baseline=True)`).

Printed: cells planned, feasible and infeasible by the oracle, every cell the oracle connects but
the planner does not (with the planner's reason), planning CPU per cell (median, 90th percentile,
max), the cycle against the rest-to-rest lower bound (`robomax bench`'s) and against both
baselines, per family, and a row per cell. `--quick`: two small cells, as CI runs it;
without OMPL installed, the oracle only tries straight moves and reports a pair it cannot join
straight as unknown.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import signal
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
KEEP = 4                     # reached configurations per stop the chain goes on from
RRT_PER_STOP = 6             # failed RRT-Connect queries before a stop is given up


# ----------------------------------------------------------------------------------------------
# The oracle


@dataclass
class OracleVerdict:
    verdict: str                         # feasible | infeasible | unknown
    detail: str = ""
    cpu: float = 0.0
    rrt_queries: int = 0
    rrt_checks: int = 0                  # collision queries the RRT-Connect queries spent
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
    values per angle with the ends included; nearest the nominal orientation first. A seam whose gun
    may stand on either side (docs/cell-files.md, `sides: either`) has them all again on the other
    side: the nominal frame turned half a turn about its x axis (z = +n)."""
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
    nominals = [R0, R0 @ np.diag([1.0, -1.0, -1.0])] if seam.either_side else [R0]
    out = []
    for R in nominals:
        for a, b, g in angles:
            T = np.eye(4)
            T[:3, :3] = R @ _rot(0, a) @ _rot(1, b) @ _rot(2, g)
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
    (None without OMPL: unknown). Each RRT-Connect query stops after `budget` collision queries
    (states and swept motions): a count, not a clock, so a verdict does not depend on the load."""

    def __init__(self, world: Any, robot: Any, budget: int, seed: int) -> None:
        self.world, self.budget = world, budget
        self.lo, self.hi = np.asarray(robot.limits.lower, dtype=float), np.asarray(robot.limits.upper, dtype=float)
        self.dof = robot.dof
        self.rrt_queries = self.straight = self.rrt_checks = 0
        self.ompl: tuple[Any, Any] | None
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
        """Whether RRT-Connect joins qa to qb (the straight move is tried by the caller)."""
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
        spent = [0]

        def values(state: Any) -> np.ndarray:
            return np.array([state[k] for k in range(dof)])

        def state_free(state: Any) -> bool:
            spent[0] += 1
            return bool(world.is_free(values(state)))

        def motion_free(s1: Any, s2: Any) -> bool:
            spent[0] += 1
            return bool(world.check_segment(values(s1), values(s2)).free)

        si.setStateValidityChecker(state_free)
        validator = _swept_validator(ob, si, motion_free)
        si.setMotionValidator(validator)
        si.setup()
        setup = og.SimpleSetup(si)
        start, goal = space.allocState(), space.allocState()
        for k in range(dof):
            start[k], goal[k] = float(qa[k]), float(qb[k])
        setup.setStartAndGoalStates(start, goal)
        setup.setPlanner(og.RRTConnect(si))
        solved = setup.solve(ob.PlannerTerminationCondition(lambda: spent[0] >= self.budget))
        self.rrt_checks += spent[0]
        return bool(solved) and bool(setup.haveExactSolutionPath())


def _swept_validator(ob: Any, si: Any, motion_free: Any) -> Any:
    """An OMPL motion validator whose every motion is the collision world's swept check."""

    class Swept(ob.MotionValidator):  # type: ignore[misc]
        def checkMotion(self, s1: Any, s2: Any) -> bool:          # OMPL's name
            return bool(motion_free(s1, s2))

    return Swept(si)


def oracle(cell: Any, robot: Any, budget: int = 3000, seed: int = 0) -> OracleVerdict:
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
    conn = Connector(world, robot, budget, seed)
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
        sources = {i: np.argsort(np.max(np.abs(src - qs[i]), axis=1), kind="stable")[:SOURCES] for i in pick}
        now: list[np.ndarray] = []
        # Straight moves suffice on most pairs; a few reached configurations keep the chain open.
        for i in pick:
            if any(conn.straight_free(src[k], qs[i]) for k in sources[i]):
                now.append(qs[i])
                if len(now) >= KEEP:
                    break
        # Else RRT-Connect between the nearest pairs, at most RRT_PER_STOP failed queries.
        failed = 0
        for i in pick if not now else ():
            for k in sources[i]:
                got = conn.connect(src[k], qs[i])
                if got:
                    now.append(qs[i])
                    break
                unknown |= got is None
                failed += 1
            if len(now) >= KEEP or failed >= RRT_PER_STOP:
                break
        if not now:
            cpu = time.process_time() - t0
            move = f"{previous} -> {name}"
            if unknown:
                return OracleVerdict("unknown", f"no straight move {move} (OMPL not installed)", cpu,
                                     conn.rrt_queries, conn.rrt_checks, conn.straight, failed_move=move)
            return OracleVerdict("infeasible", f"no connection found {move}", cpu, conn.rrt_queries,
                                 conn.rrt_checks, conn.straight, failed_move=move)
        reached, previous = now, name
    return OracleVerdict("feasible", "", time.process_time() - t0, conn.rrt_queries, conn.rrt_checks, conn.straight)


# ----------------------------------------------------------------------------------------------
# One cell, in its own process


class _OverCpu(Exception):
    """A stage used up its CPU seconds (SIGXCPU at RLIMIT_CPU's soft limit)."""


_OVER = [False]         # set by the handler: the exception may surface wrapped (inside numba code)


def _on_xcpu(signum: int, frame: Any) -> None:
    _OVER[0] = True
    raise _OverCpu


def _cpu_now() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _limited(seconds: float, stage: Any) -> tuple[Any, bool]:
    """stage() within `seconds` more CPU seconds of this process: (its value, True), or (None,
    False) when the kernel's CPU limit stopped it."""
    resource.setrlimit(resource.RLIMIT_CPU, (math.ceil(_cpu_now() + seconds), resource.RLIM_INFINITY))
    _OVER[0] = False
    try:
        return stage(), True
    except Exception:
        if _OVER[0]:
            return None, False
        raise
    finally:
        resource.setrlimit(resource.RLIMIT_CPU, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))


BASELINES = {
    # paper 003 for the given order: the DP over every orientation sample and branch
    "published": {"given_order": True},
    # what a teach-in gives: given order, nominal orientation, first branch
    "teach_in": {"baseline": True},
}


def run_one(path: Path, args: argparse.Namespace, save: Any = lambda data: None) -> dict[str, Any]:
    """Plan, bound, judge and re-plan by the baselines one cell, calling save(row) after each stage
    (a stage stopped at its CPU limit is recorded as such; the row keeps what came before)."""
    import robomax_py as rm
    from robomax_py.app.bench import lower_bound

    signal.signal(signal.SIGXCPU, _on_xcpu)
    cell = rm.load_cell(path)
    spec = cell.spec
    meta_file = path.with_suffix(".meta.json")
    meta = json.loads(meta_file.read_text()) if meta_file.is_file() else {}
    out: dict[str, Any] = {"cell": spec.name, "path": str(path), **meta,
                           "spots": sum(len(s.spots) for s in spec.seams), "seams": len(spec.seams)}
    planned = False
    if not args.no_plan:
        t0 = time.process_time()
        result, done = _limited(args.cpu_limit, lambda: rm.plan_cell(cell))
        cpu = time.process_time() - t0
        if not done:
            out.update(status="cpu_limit", message=f"stopped after {args.cpu_limit} CPU s", cpu=cpu, cycle=None)
        else:
            planned = result.status == "planned"
            out.update(status=result.status, message=result.message, cpu=cpu,
                       cycle=round(result.cycle_time, 3) if planned else None,
                       rounds=None if result.stats is None else result.stats.rounds)
            if planned:
                out["bound"] = round(lower_bound(result, cell.robot.limits), 3)
        save(out)
    if not args.no_oracle:
        verdict, done = _limited(args.oracle_cpu, lambda: oracle(spec, cell.robot, args.oracle_checks))
        out["oracle"] = asdict(verdict) if done else asdict(OracleVerdict(
            "unknown", f"oracle stopped after {args.oracle_cpu} CPU s", args.oracle_cpu))
        save(out)
    if planned and not args.no_baselines:
        for name, overrides in BASELINES.items():
            t0 = time.process_time()
            base, done = _limited(args.cpu_limit, lambda o=overrides: rm.plan_cell(cell, rm.PlanOptions(**o)))
            got: dict[str, Any] = {"cpu": round(time.process_time() - t0, 3)}
            if not done:
                got.update(status="cpu_limit")
            else:
                got.update(status=base.status, cycle=round(base.cycle_time, 3) if base.status == "planned" else None,
                           message="" if base.status == "planned" else base.message[:300])
            out[name] = got
            save(out)
    return out


def _child(path: Path, result: Path, args: argparse.Namespace) -> None:
    def save(data: dict[str, Any]) -> None:
        result.write_text(json.dumps(data), encoding="utf-8")

    save(run_one(path, args, save))
    sys.stdout.flush()
    os._exit(0)          # OMPL's bindings report leaks at interpreter exit; nothing is left to clean


def _run(path: Path, folder: Path, args: argparse.Namespace, k: int = 0) -> dict[str, Any]:
    result = folder / f"{path.stem}.result.json"
    if args.resume and result.is_file():
        done: dict[str, Any] = json.loads(result.read_text())
        if done.get("finished"):
            return done
    cmd = [sys.executable, __file__, "--one", str(path), "--result", str(result),
           "--oracle-checks", str(args.oracle_checks), "--oracle-cpu", str(args.oracle_cpu),
           "--cpu-limit", str(args.cpu_limit)]
    baselines = not args.no_baselines and k % args.baselines_every == 0
    cmd += [flag for flag, on in (("--no-oracle", args.no_oracle), ("--no-plan", args.no_plan),
                                  ("--no-baselines", not baselines)) if on]
    env = {**os.environ, "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    result.unlink(missing_ok=True)
    t0 = time.perf_counter()
    ran = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    data: dict[str, Any] = json.loads(result.read_text()) if result.is_file() else {"cell": path.stem, "path": str(path)}
    if ran.returncode != 0:
        data.setdefault("status", "error")
        data["error"] = f"exit {ran.returncode}: " + (ran.stderr.strip().splitlines() or ["(no output)"])[-1]
    data["wall"] = round(time.perf_counter() - t0, 3)
    data["finished"] = True
    result.write_text(json.dumps(data), encoding="utf-8")
    print(f"{data['cell']}: {data.get('status')} {data.get('cpu', float('nan')):.1f} s; oracle "
          f"{(data.get('oracle') or {}).get('verdict', '-')}", file=sys.stderr, flush=True)
    return data


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def _spread(values: list[float], digits: int = 3) -> str:
    if not values:
        return "-"
    return (f"median {_pct(values, 50):.{digits}f}, 10-90 % {_pct(values, 10):.{digits}f}-{_pct(values, 90):.{digits}f}, "
            f"range {min(values):.{digits}f}-{max(values):.{digits}f} (n={len(values)})")


def _ratio(r: dict[str, Any], baseline: str) -> float | None:
    base = r.get(baseline) or {}
    if r.get("cycle") is None or base.get("cycle") is None:
        return None
    return float(r["cycle"]) / float(base["cycle"])


def report(rows: list[dict[str, Any]]) -> str:
    rows = sorted(rows, key=lambda r: str(r.get("cell")))
    planned = [r for r in rows if r.get("status") == "planned"]
    verdict = {r["cell"]: (r.get("oracle") or {}).get("verdict", "-") for r in rows}
    feasible = [r for r in rows if verdict[r["cell"]] == "feasible"]
    infeasible = [r for r in rows if verdict[r["cell"]] == "infeasible"]
    unknown = [r for r in rows if verdict[r["cell"]] == "unknown"]
    missed = [r for r in feasible if r.get("status") not in ("planned", None)]        # None: not planned here
    beyond = [r for r in planned if verdict[r["cell"]] not in ("feasible", "-")]
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
    oracle_rows = [r["oracle"] for r in rows if r.get("oracle")]
    if oracle_rows:
        oracle_cpu = [float(o["cpu"]) for o in oracle_rows]
        lines.append(f"oracle CPU per cell: median {_pct(oracle_cpu, 50):.1f} s, max {max(oracle_cpu):.1f} s; "
                     f"RRT-Connect queries {sum(o.get('rrt_queries', 0) for o in oracle_rows)}")
    cycles = [float(r["cycle"]) for r in planned if r.get("cycle") is not None]
    if cycles:
        per_spot = [float(r["cycle"]) / r["spots"] for r in planned if r.get("cycle") is not None]
        lines.append(f"cycle: median {_pct(cycles, 50):.2f} s (range {min(cycles):.2f}-{max(cycles):.2f} s), "
                     f"median {_pct(per_spot, 50):.2f} s per spot")
        bound = [float(r["cycle"]) / float(r["bound"]) for r in planned if r.get("bound")]
        lines.append(f"cycle / rest-to-rest lower bound: {_spread(bound)}")
    for name, what in (("published", "published method (given order, DP over every candidate)"),
                       ("teach_in", "teach-in (given order, nominal orientation, first branch)")):
        tried = [r for r in planned if r.get(name)]
        if not tried:
            continue
        ratios = [x for x in (_ratio(r, name) for r in tried) if x is not None]
        failed = [r for r in tried if (r.get(name) or {}).get("status") != "planned"]
        lines.append(f"cycle / {what}: {_spread(ratios)}; {len(failed)} of {len(tried)} cells not planned by it")
    if missed:
        lines.append("feasible by the oracle, not planned:")
        for r in missed:
            lines.append(f"  {r['cell']}: {r.get('status')}: {r.get('message', '')[:300]}")
    if beyond:
        lines.append("planned, oracle found no way (the oracle's limits, or a contradiction where a spot has no "
                     "free configuration):")
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
    lines.append(f"{'cell':<34} {'spots':>5} {'status':<10} {'cpu s':>7} {'cycle s':>8} {'/bound':>6} {'/publ':>6} "
                 f"{'/teach':>6} {'oracle':<10} reason")
    for r in rows:
        o = r.get("oracle") or {}
        cyc = "" if r.get("cycle") is None else f"{r['cycle']:.3f}"
        cpu_s = "" if r.get("cpu") is None else f"{r['cpu']:.1f}"
        per_cell: list[float | None] = [None if not r.get("bound") or r.get("cycle") is None else r["cycle"] / r["bound"],
                  _ratio(r, "published"), _ratio(r, "teach_in")]
        shown = ["" if x is None else f"{x:.3f}" for x in per_cell]
        why = (r.get("message", "") or r.get("error", "")) if r.get("status") != "planned" else o.get("detail", "")
        lines.append(f"{r['cell']:<34} {r.get('spots', ''):>5} {r.get('status', ''):<10} {cpu_s:>7} {cyc:>8} "
                     f"{shown[0]:>6} {shown[1]:>6} {shown[2]:>6} {o.get('verdict', '-'):<10} {why[:120]}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-spots", type=int, default=80, help="spots per generated cell at most")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="corpus folder (default: a temporary one)")
    ap.add_argument("--cells", type=Path, nargs="*", default=None, help="plan these cells instead")
    ap.add_argument("--quick", action="store_true", help="two small cells (CI's smoke run)")
    ap.add_argument("--oracle-checks", type=int, default=3000,
                    help="collision queries per RRT-Connect query (states and swept motions)")
    ap.add_argument("--oracle-cpu", type=int, default=600, help="CPU s for the oracle per cell")
    ap.add_argument("--cpu-limit", type=int, default=900, help="CPU s per plan (the planner's and each baseline's)")
    ap.add_argument("--no-oracle", action="store_true")
    ap.add_argument("--no-plan", action="store_true")
    ap.add_argument("--no-baselines", action="store_true", help="skip re-planning by the two baselines")
    ap.add_argument("--baselines-every", type=int, default=1, metavar="K",
                    help="re-plan by the baselines only every K-th cell (they take about as long as the plan)")
    ap.add_argument("--resume", action="store_true", help="keep the finished results already in --out")
    ap.add_argument("--json", type=Path, default=None, help="write every cell's result here")
    ap.add_argument("--one", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--result", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        _child(args.one, args.result, args)
        return
    import corpus_cells

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.out or Path(tmp)
        if args.cells:
            cells = list(args.cells)
        elif args.quick:
            cells = corpus_cells.write_corpus(folder, seed=args.seed, indices=corpus_cells.QUICK, max_spots=8)
        else:
            cells = corpus_cells.write_corpus(folder, args.count, args.seed, max_spots=args.max_spots)
        results = folder / "results"
        results.mkdir(parents=True, exist_ok=True)
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            rows = list(pool.map(lambda kp: _run(kp[1], results, args, kp[0]), enumerate(cells)))
        if args.json:
            args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
        print(report(rows))


if __name__ == "__main__":
    main()

"""The learned C-space model against the paper's, and planning in it (a script, not a test).

    python tests/bench/bench_learned_cspace.py [CELL] [--training standard|coarse] [--points 400]
        [--neurons 8] [--spacing 0.1] [--inflation 0.06] [--resolution 40] [--samples 32] [--plan]
    python tests/bench/bench_learned_cspace.py CELL --quick        # a smoke run, seconds

Pashkevich & Kozhevnikov (2003) turned their cell (a KR 125 with a gun, a Gazelle cabin, its fixture)
into 400 obstacle points, 296 of them in the robot's reach (N'), trained their RBF network from
k' = 7-8 hidden neurons up to an error threshold, planned a move in the synthesised map and wrote
an SRCL program from it. For CELL (default: the reference cell), on the map the planner builds
(`plan.learned_detour`: its wrist and its A1-A3 box), this prints:

1. each model's size and cost: points, points in reach, neurons, output weights, training checks
   and CPU seconds (as stored with the model when it came from the cache), map CPU seconds:
   - ours: surface points `--spacing` apart, the network grown until it fits;
   - the paper's network: the same points, at most `--neurons` neurons;
   - the paper's points: `--points` points spread over the surfaces (farthest-point sampling of
     points DENSE_M apart), at most `--neurons` neurons, a sphere that covers the surfaces between
     them (its radius the measured cover: the farthest dense point from its nearest kept one, plus
     the dense points' own cover radius, plus the clearance and the inflation);
   - the paper's points at our radius: as above with our sphere radius (surfaces not covered);
2. accuracy on held-out samples: a product of `--samples` random values per axis of the map's box
   (seeded; on no training or map grid), each checked exactly against the cell's objects:
   false free (blocked, the map says free: the dangerous error) and false blocked (free space the
   map loses), as counts and shares of the exactly blocked and free samples;
3. detours: each move of the file's order (nominal candidates, home at both ends) that the exact
   swept check blocks, searched in each map and in the exact map of the same grid (the same search
   over the exact masks). Where a learned map finds none and the exact one does it says why,
   measured: no checked way into or out of the map (near the stops: its blocked share of the
   exactly free cells, and the exactly blocked share of the cells it calls free), every path it
   found refused by the exact check until
   the repairs ran out (false free), or no path (false blocked along the exact map's path: its
   blocked share of that path's cells);
4. with `--plan`: the cell planned with `planner.detours: learned` (ours) and with the default,
   cycle and CPU seconds, and the learned plan's program verified as `robomax verify` does.

CPU seconds of this process. Models are cached (ROBOMAX_CACHE); `--quick` trains on a toy grid into
a temporary folder, 16^3 cells, 12^3 samples.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import dataclasses
import itertools
import tempfile
import time
from pathlib import Path

import numpy as np

from robomax_py.cspace import (
    CSpaceGrid,
    cover_radius,
    exact_map,
    learned_map,
    learned_model,
    surface_points,
)
from robomax_py.cspace.learned import TrainingSettings
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.learned_detour import (
    ENTRY_POOL,
    MAX_REPAIRS,
    LearnedDetours,
    MapFigures,
    map_grid,
    map_wrist,
    training_settings,
)
from robomax_py.spec import CellSpec, LearnedMapSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import Scene, build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
PAPER_POINTS, PAPER_IN_REACH, PAPER_NEURONS = 400, 296, "7-8 at the start, grown to the error threshold"
# --quick: a training grid ~10x coarser than `coarse`, enough to run every step.
TOY_TRAINING = TrainingSettings(q1_step_deg=20.0, q23_step_deg=12.0, d_step=0.2, band_deg=40.0)


DENSE_M = 0.05             # m between the surface points the paper's few points are chosen from


@dataclasses.dataclass(frozen=True)
class Variant:
    name: str
    points: np.ndarray        # (P, 3) m, robot base frame
    radius: float             # m, the training sphere's
    settings: TrainingSettings


def few_points(scene: Scene, count: int) -> tuple[np.ndarray, float]:
    """`count` points spread over the surfaces (farthest-point sampling of points DENSE_M apart,
    from the first), and how far a surface point can be from the nearest of them (m, measured)."""
    from scipy.spatial import cKDTree

    dense = surface_points(scene, DENSE_M)
    if len(dense) <= count:
        return dense, cover_radius(DENSE_M)
    kept = [0]
    gap = np.linalg.norm(dense - dense[0], axis=1)
    while len(kept) < count:
        kept.append(int(np.argmax(gap)))
        gap = np.minimum(gap, np.linalg.norm(dense - dense[kept[-1]], axis=1))
    far, _ = cKDTree(dense[kept]).query(dense)
    return dense[kept], float(far.max()) + cover_radius(DENSE_M)


def nominal_stops(cell: CellSpec, spots: list[SpotCandidates]) -> list[tuple[str, np.ndarray]]:
    """Home, each spot's nominal candidate (file order), home."""
    stops = [("home", np.asarray(cell.home, dtype=float))]
    for c in spots:
        if len(c):
            k = int(np.lexsort((c.column, c.orient))[0])
            stops.append((c.name, c.q_app[k]))
    return [*stops, ("home", stops[0][1])]


def held_out(grid: CSpaceGrid, samples: int, rng: np.random.Generator) -> CSpaceGrid:
    """A product of random values per axis within the grid's box, at its wrist."""
    axes = tuple(np.sort(rng.uniform(a[0], a[-1], samples)) for a in grid.axes)
    return CSpaceGrid(axes=axes, wrist=grid.wrist)  # type: ignore[arg-type]


def search(detours: LearnedDetours, world: CollisionWorld, qa: np.ndarray, qb: np.ndarray) -> tuple[str, str]:
    """One detour search: what it found, or why it found nothing as the search counted it
    ("found", "no_entry", "no_path" or "gave_up"), and a line saying so."""
    before = dict(detours.counts)
    det, checks = detours.query(world, qa, qb)
    if det is not None:
        return "found", f"found, {len(det.waypoints)} waypoints, est. {det.time_estimate:.2f} s ({checks:,} checks)"
    why = next(k for k in ("no_entry", "gave_up", "no_path") if detours.counts[k] > before.get(k, 0))
    text = {"no_entry": "no checked way into or out of the map", "no_path": "no path in the map",
            "gave_up": f"{MAX_REPAIRS} paths in a row refused by the exact check"}[why]
    return why, f"none: {text} ({checks:,} checks)"


def why_not(why: str, learned: LearnedDetours, exact: LearnedDetours, world: CollisionWorld, qa: np.ndarray,
            qb: np.ndarray) -> str:
    """Why the learned map has no detour where the exact map of the same grid has one, measured."""
    if why == "no_entry":
        lost, wrong = [], []
        vel = np.asarray(exact.limits.velocity)[:3]

        def nearest(mask: np.ndarray, q: np.ndarray) -> np.ndarray:
            cells = np.flatnonzero(mask)
            cost = np.max(np.abs(exact.configs[cells, :3] - q[:3]) / vel, axis=1)
            return cells[np.argsort(cost, kind="stable")[:ENTRY_POOL]]

        for q in (qa, qb):
            lost.append(100.0 * float((~learned.free[nearest(exact.free, q)]).mean()))
            wrong.append(100.0 * float((~exact.free[nearest(learned.free, q)]).mean()))
        return (f"near the stops it blocks {lost[0]:.0f} % / {lost[1]:.0f} % of the {ENTRY_POOL} exactly free cells "
                f"nearest them (false blocked), and {wrong[0]:.0f} % / {wrong[1]:.0f} % of the {ENTRY_POOL} cells it "
                "calls free nearest them are blocked (false free)")
    ends = [exact.entry(world, q)[0] for q in (qa, qb)]
    assert ends[0] is not None and ends[1] is not None
    cells = exact.path(ends[0], ends[1])
    if cells is None:
        return "the exact map's path is gone too"
    blocked = int((~learned.free[cells]).sum())
    along = f"it blocks {blocked} of the exact path's {len(cells)} cells ({100.0 * blocked / len(cells):.0f} %)"
    if why == "gave_up":
        return f"false free: the cells it called free along its paths were not, {MAX_REPAIRS} times; {along}"
    return f"false blocked along the way: {along}"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("cell", nargs="?", default=str(REFERENCE_CELL))
    parser.add_argument("--training", choices=("standard", "coarse"), default="coarse")
    parser.add_argument("--points", type=int, default=PAPER_POINTS, help="the paper's model: at most this many points")
    parser.add_argument("--neurons", type=int, default=8, help="the paper's model: at most this many hidden neurons")
    parser.add_argument("--spacing", type=float, default=0.1, help="ours: m between surface points")
    parser.add_argument("--inflation", type=float, default=0.06)
    parser.add_argument("--resolution", type=int, default=40)
    parser.add_argument("--samples", type=int, default=32, help="held-out values per axis (samples^3 in all)")
    parser.add_argument("--plan", action="store_true", help="also plan the cell with detours: learned and verify it")
    parser.add_argument("--quick", action="store_true", help="smoke run: toy training grid, 16^3 cells, 12^3 samples")
    args = parser.parse_args()
    if args.quick:
        args.resolution, args.samples = 16, 12

    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    planning = dataclasses.replace(cell, dynamic=())
    scene = build_scene(planning, robot)
    world = CollisionWorld(robot, scene, cell.process.clearance)
    spots = [c for s in range(len(cell.seams)) for c in seam_candidates(cell, robot, world, s)[0]]
    wrist = map_wrist([c for c in spots if len(c)], robot.limits)
    grid = map_grid(np.asarray(cell.home), [c for c in spots if len(c)], robot.limits, wrist, args.resolution)
    spec = LearnedMapSpec(training=args.training)
    settings = TOY_TRAINING if args.quick else training_settings(spec)
    capped = dataclasses.replace(settings, max_neurons=args.neurons)
    ours_r = cell.process.clearance + cover_radius(args.spacing) + args.inflation
    ours_points = surface_points(scene, args.spacing)
    paper_points, paper_cover = few_points(scene, args.points)
    paper_r = cell.process.clearance + paper_cover + args.inflation
    variants = [
        Variant("ours", ours_points, ours_r, settings),
        Variant(f"paper's network (<= {args.neurons} neurons)", ours_points, ours_r, capped),
        Variant(f"paper's points ({len(paper_points)}), covered", paper_points, paper_r, capped),
        Variant(f"paper's points ({len(paper_points)}), our radius", paper_points, ours_r, capped),
    ]
    print(f"cell {cell.name}: map wrist {np.degrees(wrist).round(1).tolist()} deg, {args.resolution}^3 cells over "
          f"A1-A3 {[[round(float(np.degrees(a[0])), 1), round(float(np.degrees(a[-1])), 1)] for a in grid.axes]} deg; "
          f"training {'toy (--quick)' if args.quick else args.training}; CPU seconds of one process")

    c0 = time.process_time()
    exact = exact_map(world, grid)
    touching = exact.self_contact
    exact_cpu = time.process_time() - c0
    rng = np.random.default_rng(7)
    test_grid = held_out(grid, args.samples, rng)
    truth = exact_map(world, test_grid).obstacle
    print(f"exact map: {int(exact.obstacle.sum()):,} of {grid.size:,} cells blocked by objects, "
          f"{int((touching & ~exact.obstacle).sum()):,} by the arm itself, {exact.checks:,} checks, {exact_cpu:.2f} s")
    print(f"held-out: {test_grid.size:,} samples, {int(truth.sum()):,} blocked by objects (exact)")

    maps: list[tuple[Variant, LearnedDetours]] = []
    print(f"\n{'model':40s} {'points':>8s} {'reach':>7s} {'radius':>7s} {'neurons':>7s} {'weights':>8s} "
          f"{'train checks':>13s} {'train s':>8s} {'map s':>6s} {'false free':>16s} {'false blocked':>18s}")
    print(f"{'paper (Pashkevich & Kozhevnikov 2003)':40s} {PAPER_POINTS:8d} {PAPER_IN_REACH:7d} {'':>7s} "
          f"{PAPER_NEURONS}")
    folder = Path(tempfile.mkdtemp()) if args.quick else None        # a smoke run keeps no model
    for v in variants:
        model, cached = learned_model(cell, robot, wrist, v.radius, v.settings, folder)
        t0 = time.process_time()
        points = v.points
        m = learned_map(model, points, grid)
        map_cpu = time.process_time() - t0
        said = learned_map(model, points, test_grid).obstacle
        ff, fb = int((truth & ~said).sum()), int((~truth & said).sum())
        in_reach = int((model.base.coordinates(points)[0] <= model.d_max).sum())
        figures = MapFigures(len(points), in_reach, v.radius, cached, map_cpu)
        maps.append((v, LearnedDetours(grid, m.obstacle, touching, robot.limits, model, figures)))
        print(f"{v.name:40s} {len(points):8,} {in_reach:7,} {v.radius:7.3f} {len(model.centres):7d} "
              f"{model.weights.size:8,} {model.train_checks:13,} {model.train_cpu_seconds:8.1f} {map_cpu:6.2f} "
              f"{ff:6,} {100.0 * ff / max(1, int(truth.sum())):8.2f} % {fb:8,} {100.0 * fb / max(1, int((~truth).sum())):8.2f} %",
              flush=True)

    exact_search = LearnedDetours(grid, exact.obstacle, touching, robot.limits, maps[0][1].model, maps[0][1].figures)
    stops = nominal_stops(cell, spots)
    print("\ndetours for the blocked moves of the file's order (nominal candidates):")
    for (na, qa), (nb, qb) in itertools.pairwise(stops):
        if world.check_segment(qa, qb).free:
            continue
        best, line = search(exact_search, world, qa, qb)
        print(f"  {na} -> {nb}:\n    {'exact map (same grid and search)':40s} {line}")
        for v, detours in maps:
            why, line = search(detours, world, qa, qb)
            if why != "found" and best == "found":
                line += f"; {why_not(why, detours, exact_search, world, qa, qb)}"
            print(f"    {v.name:40s} {line}")
    for v, detours in [(Variant("exact map", ours_points, ours_r, settings), exact_search), *maps]:
        r = detours.report()
        print(f"  {v.name}: {r.searches} searches, {r.found} found, {r.refused_segments} path segments refused by "
              f"the exact check (repaired), {r.refused_entries} entry legs refused")
    if args.plan:
        plan_both(cell, robot, spec)


def plan_both(cell: CellSpec, robot: object, spec: LearnedMapSpec) -> None:
    """The cell planned with detours: learned and with the default; the learned program verified."""
    from robomax_py.app.api import LoadedCell, verify_program, write_programs
    from robomax_py.plan import plan_cell

    print("\nplanning:")
    for detours in ("learned", "both"):
        planner = dataclasses.replace(cell.planner, detours=detours, learned=spec)
        loaded = LoadedCell(dataclasses.replace(cell, planner=planner), robot)  # type: ignore[arg-type]
        t0 = time.process_time()
        result = plan_cell(loaded.spec, loaded.robot)
        seconds = time.process_time() - t0
        line = f"  detours: {detours:8s} {result.status}, cycle {result.cycle_time:.3f} s, {seconds:.1f} s CPU"
        if result.status == "planned" and detours == "learned":
            with tempfile.TemporaryDirectory() as out:
                written = write_programs(loaded, result, out)
                report = verify_program(loaded, written.by_dialect["srcl"][0])
            line += f"; srcl verified: {'clean' if report.clean else report.violations[0].detail}"
        if result.stats is not None and result.stats.learned is not None:
            m = result.stats.learned
            line += f"; {m.found} of {m.searches} searches found, {m.refused_segments} segments refused"
        print(line if result.status == "planned" else f"{line}: {result.message}", flush=True)


if __name__ == "__main__":
    main()

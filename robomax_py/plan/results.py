"""What planning returns: options, per-spot plans and failures, transitions, statistics, the result."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from typing import Any, Literal

from robomax_py._typing import FloatArray
from robomax_py.plan.spline_moves import CartesianChoice, SplineMoves
from robomax_py.plan.waiting import WaitPlan
from robomax_py.program import ToolLoad
from robomax_py.spec import CellSpec, ControllerSetup
from robomax_py.timing import (
    Trajectory,
)
from robomax_py.world.motion import Clearance

PlanStatus = Literal["planned", "infeasible"]
"""`PlanResult.status`: "planned" (every spot, a checked trajectory) or "infeasible" (`message` says why)."""

TransitionKind = Literal["move", "detour"]
"""`Transition.kind`: a straight joint move between two stops, or a detour through via points."""

FailureReason = Literal["unreachable", "joint_limit", "collision", "approach_blocked", "pinned_config",
                        "pinned_orientation"]
"""`SpotFailure.reason`, the dominant reason a spot has no candidate: no IK solution at any allowed
orientation; every solution beyond a joint limit (at the spot or the approach point); in collision;
the approach line blocked or leaving the spot's IK branch; no solution in the pinned configuration;
none at the pinned orientation."""

PlanStage = Literal["candidates", "sequencing", "timing", "verify"]
"""The stages a `Progress` callback is told about, in the order they run."""

STAGE_LABELS: dict[str, str] = {
    "candidates": "candidates (IK x orientation grid)",
    "sequencing": "sequencing rounds",
    "timing": "timing moves",
    "verify": "final check",
}
"""What each stage does, in a few words (the CLI's progress bars, `ProgressEvent.label`)."""

Progress = Callable[[str, int, int], None]
"""progress(stage, done, total): called as a long stage advances ("candidates", "sequencing",
"timing", "verify"); the CLI draws progress bars from it. total may grow (sequencing rounds)."""


def _no_progress(stage: str, done: int, total: int) -> None:
    pass


# Heights (m, world z) tried for up-across-down detours over clamps, lowest first.

@dataclass(frozen=True, slots=True)
class PlanOptions:
    """How to plan; every field has a production default, so `PlanOptions()` plans as `robomax plan`.

    Build one with the fields to change, e.g. ``PlanOptions(given_order=True, speed=0.5)``, or
    derive one with `dataclasses.replace`. Fields:

    - `baseline`: plan teach-in, the baseline an integrator programs by hand: the cell file's spot
      order, the nominal orientation where feasible, the first feasible IK branch.
    - `given_order`: the published method: the spots in the cell file's order, the DP still choosing
      among every candidate (orientation sample and IK branch), with the same detours and timing.
    - `speed`: global override in (0, 1] of every programmed speed (`plan --speed`); None takes the
      cell's `planner.speed` (default 1.0).
    - `tcp_speed`: m/s on approach and retract lines, before the override; None takes the cell's
      `planner.tcp_speed` (default 0.5).
    - `detour_speed`: speed fraction of detour moves, before the override; None takes the cell's
      `planner.detour_speed` (default 1.0).
    - `detours`: where detours are searched: "roadmap", "cspace" (the local A1-A3 map), "both", or
      "learned" (the learned C-space map alone, `plan.learned_detour`); None takes the cell's
      `planner.detours`.
    - `detour_moves`: "ptp" (joint-space moves between detour points) or "lin" (straight TCP lines
      through via points, joint-space only where none is found); None takes the cell's
      `planner.detour_moves`.
    - `detour_tcp_speed`: m/s on the LIN lines of detours, before the override; None takes the
      cell's `planner.detour_tcp_speed` (default 1.0).
    - `dynamic`: how dynamic objects are planned around: "timed" (time-aware moves) or "rest"
      (waits at rest); None takes the cell's `planner.dynamic`. "astar" is the paper's classical
      A* as a baseline (docs/paper-001.md): the time-aware search's graph with time ignored, then a
      stop at rest wherever its route meets a dynamic object at its time.
    - `transfers`: how a pick-and-place cell's carried moves are planned: "moves" (as every other
      move: straight, or a detour where that is blocked) or "associative" (Diane and Anikina's
      table, k-NN graph, Dijkstra route and Jacobian interpolation, `plan.associative`); None
      takes the cell's `planner.transfers`.
    - `roadmap_nodes`, `roadmap_k`: size of the detour roadmap and the neighbours each node is
      joined to.
    - `straight_tries`: blocked straight moves between two spots before that pair takes detours only.
    - `max_rounds`: sequencing rounds (optimise, verify, repair) before giving up.
    - `max_evaluations`: DP evaluations per sequencing round.
    - `order_candidates`: candidates per spot the order search sees (the exact DP then uses all).
    - `probe_neighbours`: nearest spots per spot whose straight move is probed up front.
    - `jerk_limited`: PTP moves and detour legs timed jerk-limited (ruckig); False: toppra
      (velocity and acceleration limits only).
    - `blend`: fly by detour corners and approach points on checked G2 blends where that is faster.
    - `cartesian_moves`: "lin" or "spline" (a junction between two spots as one smooth Bézier TCP
      path where that is faster, `plan.spline_junction`); None takes the cell's
      `planner.cartesian_moves`.
    """

    baseline: bool = False
    given_order: bool = False
    speed: float | None = None
    tcp_speed: float | None = None
    detour_speed: float | None = None
    detours: str | None = None
    detour_moves: str | None = None
    detour_tcp_speed: float | None = None
    dynamic: str | None = None
    transfers: str | None = None
    roadmap_nodes: int = 600
    roadmap_k: int = 12
    straight_tries: int = 12
    max_rounds: int = 80
    max_evaluations: int = 400
    order_candidates: int = 32
    probe_neighbours: int = 6
    jerk_limited: bool = True
    blend: bool = True
    cartesian_moves: str | None = None

    @property
    def method(self) -> str:
        """"optimised", or the baseline these options plan: "published" or "teach-in" (`METHODS`)."""
        return "teach-in" if self.baseline else "published" if self.given_order else "optimised"


@dataclass(frozen=True, slots=True)
class ResolvedOptions(PlanOptions):
    """Options with every value the cell may supply filled in (`resolved_options`): what the planner
    and the program writer work with, so a speed is always a number there. The defaults are the
    cell file's (`planner` section)."""

    speed: float = 1.0
    tcp_speed: float = 0.5
    detour_speed: float = 1.0
    detours: str = "both"
    detour_moves: str = "ptp"
    detour_tcp_speed: float = 1.0
    dynamic: str = "timed"
    transfers: str = "moves"
    cartesian_moves: str = "lin"


# The methods `plan --baseline` and the benchmarks compare, each as the options that plan it (every
# one with the same candidates, detours and timing): the optimiser; the published method (paper 003's
# planner for the given order: the DP over every orientation sample and IK branch); teach-in.
METHODS: dict[str, dict[str, Any]] = {"optimised": {}, "published": {"given_order": True}, "teach-in": {"baseline": True}}


def method_options(method: str, options: PlanOptions | None = None) -> PlanOptions:
    """`options` (default: the defaults) set to plan by `method`, a key of `METHODS`."""
    return replace(options or PlanOptions(), **METHODS[method])


def method_suffix(method: str) -> str:
    """What a baseline's files add to the cell's name ("_published", "_teach_in"), so that a
    baseline never replaces the optimised program; "" for the optimised plan."""
    return "" if method == "optimised" else "_" + method.replace("-", "_")


@dataclass(frozen=True, slots=True, eq=False)
class SpotPlan:
    """One welded spot: where and how."""

    seam: str
    name: str
    angles: FloatArray               # (3,) alpha, beta, gamma, rad
    config: str                      # the controller brand's configuration data at the spot
    q_spot: FloatArray
    q_app: FloatArray
    t_arrive: float
    t_leave: float
    T_spot: FloatArray               # (4, 4) TCP at the spot, robot base frame
    T_app: FloatArray                # (4, 4) TCP at the approach point, robot base frame
    config_app: str = ""             # configuration data at the approach point (where the retract ends)
    weld_time: float = 0.0           # s, as the program states it
    gun: int = 1
    schedule: int = 1
    interlocks: tuple[str, ...] = ()  # clamp signals the program waits for before moving to this spot
    action: Literal["grip", "release"] | None = None   # tending stations: a gripper action instead of a weld


@dataclass(frozen=True, slots=True)
class SpotFailure:
    seam: str
    name: str
    reason: FailureReason
    detail: str


@dataclass(frozen=True, slots=True, eq=False)
class Stage:
    """A stop inside a transition: the robot halts at waypoint `index` and waits there.

    wait None: it halts and goes on at once. A time-aware route is timed in pieces that stop where
    its search waits (`timed_moves`); where the stop alone lets the way clear, no wait is added, but
    the robot still stops there, and the program must say so (no fly-by), or it runs another motion.
    """

    index: int
    wait: WaitPlan | None


@dataclass(frozen=True, slots=True, eq=False)
class Transition:
    """The joint path between two stops (home or an approach point); kind 'move' or 'detour'."""

    kind: TransitionKind
    waypoints: FloatArray            # (m, n), both ends included
    label: str
    checks: int = 0                  # collision checks spent finding this detour (0 for a straight move)
    blend_radius: float = 0.0        # rad: detour corners passed on G2 blends of this radius; 0: stops at each
    flyby_radius: float = 0.0        # rad: the retract -> move and move -> approach joins flown by; 0: stops
    wait: WaitPlan | None = None     # a wait at rest before it, for a dynamic obstacle to clear
    stages: tuple[Stage, ...] = ()   # stops inside it, where the robot waits or halts (time-aware planning)
    # Where a fly-by's lines end beyond the approach points (junction.Extension); None: there.
    retract_T: FloatArray | None = None     # (4, 4) the retract's target, robot base frame
    retract_q: FloatArray | None = None     # the configuration there
    approach_q: FloatArray | None = None    # the configuration the approach line starts from
    # What it carries (pick and place) and, where limits of the load slow it, the overrides it is
    # timed and written with: PTP speed and acceleration fractions, its lines' TCP speed (m/s).
    part: str | None = None
    speed: float | None = None              # None: the plan's (`planner.speed`, `detour_speed`)
    accel: float = 1.0
    tcp_speed: float | None = None          # None: the plan's (`planner.tcp_speed`)
    # A detour of straight TCP lines (`planner.detour_moves: lin`): the TCP pose each line ends at,
    # one per waypoint after the first ((m - 1, 4, 4), robot base frame, as the program states
    # them), the configuration data there and the lines' TCP speed (m/s, as written). None: the
    # moves between the waypoints are joint moves (PTP).
    lin_targets: FloatArray | None = None
    lin_configs: tuple[str, ...] = ()
    lin_speed: float = 0.0
    # `planner.cartesian_moves: spline`: the junction as one smooth Bézier TCP path where that was
    # chosen (None: as above), and how it was chosen (None: no spline was tried).
    spline: SplineMoves | None = None
    choice: CartesianChoice | None = None


@dataclass(frozen=True, slots=True)
class OrderChoice:
    """Which spot order an optimised plan kept: the searched one, or the cell file's own order
    planned by the published method (the DP over every candidate, same detours and timing), kept
    where its timed cycle is shorter. `given_cycle` is None where the file's order was not timed;
    `note` then says why."""

    kept: str                        # "searched" | "given"
    searched_cycle: float | None     # s; None where the searched tour failed its timing or check
    given_cycle: float | None        # s
    note: str = ""

    def describe(self) -> str:
        """One line: "searched (x s, kept) / as given (y s)" and, where it was not timed, why."""
        def part(name: str, cycle: float | None, kept: bool) -> str:
            what = "not timed" if cycle is None else f"{cycle:.3f} s"
            return f"{name} ({what}{', kept' if kept else ''})"
        line = (part("searched", self.searched_cycle, self.kept == "searched") + " / "
                + part("as given", self.given_cycle, self.kept == "given"))
        return line + (f": {self.note}" if self.note else "")


@dataclass(frozen=True, slots=True)
class LearnedMapReport:
    """The learned C-space map a plan searched its detours in (`planner.detours: learned`), and what
    the exact check made of the paths it found."""

    wrist: tuple[float, ...]        # rad, A4-A6 held fixed over the map
    resolution: int                 # samples per axis of A1-A3
    blocked_by_objects: int         # cells the learned model blocks
    blocked_by_itself: int          # cells free of objects where the arm touches itself (checked exactly)
    points: int                     # surface points the objects became
    points_in_reach: int            # of them, those the arm can touch (the paper's N')
    sphere_radius: float            # m, the training sphere's: clearance + cover radius + inflation
    neurons: int                    # hidden neurons of the network
    weights: int                    # output weights of the network
    training_cached: bool           # the model came from the cache (its training cost is as stored)
    training_cpu_seconds: float
    training_checks: int
    map_cpu_seconds: float          # the map from the model, and the exact self-contact mask
    searches: int                   # detour searches in the map
    found: int                      # detours offered, every segment passed by the exact check
    refused_segments: int           # map path segments the exact check refused (each repaired)
    refused_entries: int            # legs from a stop into the map the exact check refused
    no_entry: int                   # searches with no leg into or out of the map passing the check
    no_path: int                    # searches where the map (with its repairs) held no path
    gave_up: int                    # searches that repaired MAX_REPAIRS refused segments and stopped


@dataclass(frozen=True, slots=True)
class PlanStats:
    candidates: int
    candidate_checks: int
    sequencing_checks: int
    roadmap_checks: int
    verify_checks: int
    detours: int
    rounds: int
    dp_evaluations: int
    seconds: dict[str, float] = field(default_factory=dict)
    # `planner.detour_moves: lin`: detour searches that tried straight TCP lines, those that found
    # them, and the plan's detours made of such lines (the others are joint-space).
    tcp_detour_searches: int = 0
    tcp_detours_found: int = 0
    lin_detours: int = 0
    learned: LearnedMapReport | None = None     # `planner.detours: learned` only


@dataclass(frozen=True, slots=True, eq=False)
class PlanResult:
    cell: str
    robot: str
    status: PlanStatus
    message: str
    spots: tuple[SpotPlan, ...] = ()
    failures: tuple[SpotFailure, ...] = ()
    transitions: tuple[Transition, ...] = ()
    trajectory: Trajectory | None = None
    stats: PlanStats | None = None
    baseline: bool = False           # planned by a baseline method (`options.method` says which)
    joint_names: tuple[str, ...] = ()
    prismatic: tuple[bool, ...] = ()         # per joint: prismatic (m), else revolute (rad)
    tool: str = ""
    T_flange_tcp: FloatArray | None = None   # (4, 4)
    tool_load: ToolLoad | None = None        # the tool's stated load, which some dialects declare
    T_world_base: FloatArray | None = None   # (4, 4)
    T_root_controller: FloatArray | None = None   # (4, 4) the controller's base in the URDF root frame
    controller: ControllerSetup = field(default_factory=ControllerSetup)   # the cell's `robot.controller`: frames, inputs, weld style
    home: FloatArray | None = None
    options: ResolvedOptions = ResolvedOptions()
    weld_time: float = 0.0
    clearance: Clearance | None = None       # the smallest distance the planned motion keeps, and where
    order: OrderChoice | None = None         # optimised plans: the searched order or the file's, and why

    @property
    def tending(self) -> bool:
        """Whether the stops are gripper actions at tending stations rather than welds."""
        return any(s.action is not None for s in self.spots)

    @property
    def method(self) -> str:
        return self.options.method

    @property
    def cycle_time(self) -> float:
        return float("nan") if self.trajectory is None else self.trajectory.duration


def resolved_options(cell: CellSpec, options: PlanOptions) -> ResolvedOptions:
    """The options with every speed left None taken from the cell's `planner` section."""
    p = cell.planner
    given = {f.name: getattr(options, f.name) for f in fields(PlanOptions)}
    return ResolvedOptions(**{
        **given,
        "speed": p.speed if options.speed is None else options.speed,
        "tcp_speed": p.tcp_speed if options.tcp_speed is None else options.tcp_speed,
        "detour_speed": p.detour_speed if options.detour_speed is None else options.detour_speed,
        "detours": p.detours if options.detours is None else options.detours,
        "detour_moves": p.detour_moves if options.detour_moves is None else options.detour_moves,
        "detour_tcp_speed": p.detour_tcp_speed if options.detour_tcp_speed is None else options.detour_tcp_speed,
        "dynamic": p.dynamic if options.dynamic is None else options.dynamic,
        "transfers": p.transfers if options.transfers is None else options.transfers,
        "cartesian_moves": p.cartesian_moves if options.cartesian_moves is None else options.cartesian_moves,
    })



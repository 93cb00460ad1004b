"""What planning returns: options, per-spot plans and failures, transitions, statistics, the result."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

from robomax_py._typing import FloatArray
from robomax_py.plan.waiting import WaitPlan
from robomax_py.spec import CellSpec, ControllerSetup
from robomax_py.timing import (
    Trajectory,
)
from robomax_py.world.motion import Clearance

Progress = Callable[[str, int, int], None]
"""progress(stage, done, total): called as a long stage advances ("candidates", "sequencing",
"timing", "verify"); the CLI draws progress bars from it. total may grow (sequencing rounds)."""


def _no_progress(stage: str, done: int, total: int) -> None:
    pass


# Heights (m, world z) tried for up-across-down detours over clamps, lowest first.

@dataclass(frozen=True, slots=True)
class PlanOptions:
    """How to plan; every field has a production default."""

    # Teach-in, the baseline an integrator programs by hand: the cell file's order, the nominal
    # orientation where feasible, the first feasible branch.
    baseline: bool = False
    # The spots in the cell file's order, the DP still choosing among every candidate (orientation
    # sample and branch) with the same detours and timing: paper 003's OptTrag for a given order.
    given_order: bool = False
    # Speeds; None takes the cell's `planner` values (defaults 1.0, 0.5 m/s, 1.0).
    speed: float | None = None       # global override in (0, 1] of every programmed speed
    tcp_speed: float | None = None   # m/s on approach and retract lines (before the override)
    detour_speed: float | None = None  # speed fraction of detour moves (before the override)
    detours: str | None = None       # "roadmap", "cspace" or "both"; None takes the cell's planner.detours
    dynamic: str | None = None       # "timed" or "rest"; None takes the cell's planner.dynamic
    roadmap_nodes: int = 600
    roadmap_k: int = 12
    straight_tries: int = 12         # blocked straight moves between two spots before detours only
    max_rounds: int = 80             # sequencing rounds (optimise, verify, repair)
    max_evaluations: int = 400       # DP evaluations per sequencing round
    order_candidates: int = 32       # candidates per spot the order search sees (exact DP then uses all)
    probe_neighbours: int = 6        # nearest spots per spot whose straight move is probed up front
    jerk_limited: bool = True        # PTP moves and detour legs with ruckig; False: toppra (vel/acc only)
    blend: bool = True               # fly by detour corners and approach points on checked G2 blends where faster

    @property
    def method(self) -> str:
        """"optimised", or the baseline these options plan: "published" or "teach-in" (`METHODS`)."""
        return "teach-in" if self.baseline else "published" if self.given_order else "optimised"


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
    action: str | None = None        # tending stations: "grip" or "release" instead of a weld


@dataclass(frozen=True, slots=True)
class SpotFailure:
    seam: str
    name: str
    reason: str                      # unreachable | joint_limit | collision | approach_blocked
    detail: str


@dataclass(frozen=True, slots=True, eq=False)
class Stage:
    """A stop inside a transition: the robot halts at waypoint `index` and waits there."""

    index: int
    wait: WaitPlan


@dataclass(frozen=True, slots=True, eq=False)
class Transition:
    """The joint path between two stops (home or an approach point); kind 'move' or 'detour'."""

    kind: str
    waypoints: FloatArray            # (m, n), both ends included
    label: str
    checks: int = 0                  # collision checks spent finding this detour (0 for a straight move)
    blend_radius: float = 0.0        # rad: detour corners passed on G2 blends of this radius; 0: stops at each
    flyby_radius: float = 0.0        # rad: the retract -> move and move -> approach joins flown by; 0: stops
    wait: WaitPlan | None = None     # a wait at rest before it, for a dynamic obstacle to clear
    stages: tuple[Stage, ...] = ()   # stops inside it where the robot waits (time-aware planning)
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


@dataclass(frozen=True, slots=True, eq=False)
class PlanResult:
    cell: str
    robot: str
    status: str                      # "planned" | "infeasible"
    message: str
    spots: tuple[SpotPlan, ...] = ()
    failures: tuple[SpotFailure, ...] = ()
    transitions: tuple[Transition, ...] = ()
    trajectory: Trajectory | None = None
    stats: PlanStats | None = None
    baseline: bool = False           # planned by a baseline method (`options.method` says which)
    joint_names: tuple[str, ...] = ()
    tool: str = ""
    T_flange_tcp: FloatArray | None = None   # (4, 4)
    T_world_base: FloatArray | None = None   # (4, 4)
    T_root_controller: FloatArray | None = None   # (4, 4) the controller's base in the URDF root frame
    controller: ControllerSetup = field(default_factory=ControllerSetup)   # the cell's `robot.controller`: frames, inputs, weld style
    home: FloatArray | None = None
    options: PlanOptions = PlanOptions()
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


def resolved_options(cell: CellSpec, options: PlanOptions) -> PlanOptions:
    """The options with every speed left None taken from the cell's `planner` section."""
    p = cell.planner
    return replace(
        options,
        speed=p.speed if options.speed is None else options.speed,
        tcp_speed=p.tcp_speed if options.tcp_speed is None else options.tcp_speed,
        detour_speed=p.detour_speed if options.detour_speed is None else options.detour_speed,
        detours=p.detours if options.detours is None else options.detours,
        dynamic=p.dynamic if options.dynamic is None else options.dynamic,
    )



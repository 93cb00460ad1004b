"""`robomax plan STATION` end to end on a small crossing station (each of two robots welds a spot on
the other's side), planned once for the file's tests, another spot order found shorter than waiting
there; and the lower bound held to real plans of small stations and of one robot."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.plan import PlanOptions
from robomax_py.program import SetSignal, WaitFor
from robomax_py.robot import RobotModel
from robomax_py.spec_station import StationSpec
from robomax_py.station.bound import half_line_time, spot_work
from robomax_py.station.pipeline import StationOptions, StationPlan, plan_station
from robomax_py.station.reach import robot_reach

DATA = Path(__file__).parents[1] / "data" / "station"
CROSSING = DATA / "crossing.yaml"
TWO = DATA / "two_robots.yaml"


@pytest.fixture(scope="module")
def planned(crossing_station_plan: dict[str, str]) -> dict[str, str]:
    return crossing_station_plan


@pytest.mark.slow
def test_writes_every_robots_programs_and_the_station(planned: dict[str, str]) -> None:
    for robot in ("r1", "r2"):
        for ext in (".src", ".dat", ".srcl", ".json"):
            assert f"crossing_{robot}{ext}" in planned
    summary = json.loads(planned["crossing.station.json"])
    assert summary["format"] == "robomax.station/1"
    assert summary["lower_bound"]["value"] <= summary["makespan"]
    welded = sorted(s for r in summary["robots"] for s in r["spots"])
    assert welded == sorted(f"{seam}/{spot}" for seam, spot in
                            [("front_rail", "f1"), ("front_rail", "f4"), ("left_rail", "l1"), ("left_rail", "l4"),
                             ("right_rail", "r1"), ("right_rail", "r4")])
    spots = {r["name"]: set(r["spots"]) for r in summary["robots"]}
    assert "left_rail/l1" in spots["r2"] and "left_rail/l4" in spots["r1"]     # as the file allows
    for r in summary["robots"]:
        traj = json.loads(planned[f"crossing_{r['name']}.json"])
        assert traj["cycle_time"] == pytest.approx(r["own_cycle"], abs=1e-6)
        waited = sum(w["seconds"] for w in traj["station"]["waits"])
        assert waited == pytest.approx(r["waits"], abs=1e-5)
        assert r["end"] == pytest.approx(r["own_cycle"] + r["waits"], abs=1e-5)
    assert max(r["end"] for r in summary["robots"]) == pytest.approx(summary["makespan"], abs=1e-5)


@pytest.mark.slow
def test_interlocks_are_stated_in_both_programs(planned: dict[str, str]) -> None:
    from robomax_py.export import DIALECTS

    summary = json.loads(planned["crossing.station.json"])
    assert summary["interlocks"], "the crossing station needs an interlock"
    station = load_station(CROSSING)
    for lock in summary["interlocks"]:
        assert lock["signal"] == f"{lock['leader']}_{lock['zone']}_clear"
        leader, waiter = station.robot(lock["leader"]), station.robot(lock["waiter"])
        assert lock["leader_output"] in leader.interlock_outputs.numbers()
        assert lock["waiter_input"] in waiter.interlock_inputs.numbers()
        for robot, kind in ((lock["leader"], SetSignal), (lock["waiter"], WaitFor)):
            name = f"crossing_{robot}.srcl"
            model = load_cell_robot(station.robot(robot).cell)
            program = DIALECTS["srcl"].parse({".srcl": planned[name]}, name, model).program
            found = [i for i in program.instructions if isinstance(i, kind) and i.signal == lock["signal"]]
            assert found, f"{kind.__name__} {lock['signal']} missing in {name}"
        krl = planned[f"crossing_{lock['leader']}.src"]
        assert f"$OUT[{lock['leader_output']}]=TRUE" in krl and f"$OUT[{lock['leader_output']}]=FALSE" in krl
        assert f"SIGNAL {lock['signal']} $IN[{lock['waiter_input']}]" in planned[f"crossing_{lock['waiter']}.src"]


def _small_station(tmp: Path, keep: list[str], only: dict[str, str]) -> Path:
    data = yaml.safe_load(TWO.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((TWO.parent / obj["mesh"]).resolve())
    for seam in data["seams"]:
        seam.pop("robots", None)
        seam["spots"] = [dict(s, **({"robots": [only[s["name"]]]} if s["name"] in only else {}))
                         for s in seam["spots"] if s["name"] in keep]
        for s in seam["spots"]:
            s.pop("robots", None) if s["name"] not in only else None
    data["seams"] = [s for s in data["seams"] if s["spots"]]
    path = tmp / "small.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


SPOTS = ["f1", "f4", "l1", "l4", "r1", "r4"]


def _own_bounds(station: StationSpec, models: dict[str, RobotModel], plan: StationPlan) -> dict[str, float]:
    """Each robot's bound on its own cycle for the spots it welds in `plan` (`SpotWork.tour_bound`)."""
    out = {}
    for p in plan.robots:
        work = spot_work(robot_reach(station, p.robot, models[p.robot]), half_line_time(p.cell, PlanOptions()))
        out[p.robot] = work.tour_bound([(s.seam, s.name) for s in (p.result.spots if p.result else ())])
    return out


@pytest.mark.slow
@settings(max_examples=3, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(keep=st.lists(st.sampled_from(SPOTS), min_size=2, max_size=3, unique=True),
       pin=st.dictionaries(st.sampled_from(["l1", "l4", "r1"]), st.sampled_from(["r1", "r2"]), max_size=1))
def test_lower_bound_below_every_plan(tmp_path: Path, keep: list[str], pin: dict[str, str]) -> None:
    """The bound holds whatever the method (min-max here: the cheapest to plan), and each robot's
    own cycle is at least its tour's bound."""
    only = {"f1": "r1", "f4": "r1", "r4": "r2", **pin}
    station = load_station(_small_station(tmp_path, keep, only))
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    plan = plan_station(station, models, StationOptions(method="minmax"))
    assert plan.status == "planned", plan.message
    assert plan.bound.value <= plan.makespan
    for p in plan.robots:                       # each robot's own tour: at least its spots' round trips
        if p.result is not None:
            assert p.own_cycle >= max(s.weld_time for s in p.result.spots)
    own = _own_bounds(station, models, plan)
    for p in plan.robots:
        assert own[p.robot] <= p.own_cycle, p.robot


@pytest.mark.slow
def test_the_bound_of_one_robot_is_below_its_cycle(tmp_path: Path) -> None:
    """A station of one robot is the single-robot cell: its bound, and the robot's tour bound, are
    below the single-robot planner's cycle."""
    data = yaml.safe_load(TWO.read_text())
    data["robots"] = data["robots"][:1]
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((TWO.parent / obj["mesh"]).resolve())
    for seam in data["seams"]:
        seam.pop("robots", None)
        seam["spots"] = [{k: v for k, v in s.items() if k != "robots"} for s in seam["spots"] if s["name"] in ("f1", "f4", "l4")]
    data["seams"] = [s for s in data["seams"] if s["spots"]]
    path = tmp_path / "one.yaml"
    path.write_text(yaml.safe_dump(data))
    station = load_station(path)
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    plan = plan_station(station, models, StationOptions(method="minmax"))
    assert plan.status == "planned", plan.message
    (robot,) = plan.robots
    assert robot.result is not None and len(robot.result.spots) == 3
    assert plan.makespan == pytest.approx(robot.own_cycle, abs=1e-9)
    assert 0 < plan.bound.value <= robot.own_cycle
    assert plan.bound.partition > plan.bound.single          # the tour's legs count, not one round trip
    assert _own_bounds(station, models, plan)["r1"] <= robot.own_cycle


@pytest.mark.slow
def test_another_order_beats_waiting_on_the_crossing_station(planned: dict[str, str],
                                                              shared_once: Callable[[str, Callable[[], Any]], Any]) -> None:
    """On the crossing station r2, which ends last, waits for r1 to leave the zone it enters first:
    the full method (what `robomax plan` runs) welds r2's spots in another order and ends sooner than
    the min-max assignment with waiting only."""
    def waiting_only() -> float:
        station = load_station(CROSSING)
        models = {r.name: load_cell_robot(r.cell) for r in station.robots}
        return float(plan_station(station, models, StationOptions(method="minmax")).makespan)

    waiting = shared_once("station-crossing-minmax:" + CROSSING.read_text(), waiting_only)
    summary = json.loads(planned["crossing.station.json"])
    assert summary["order_changes"], "the full method kept no order change"
    # The changes listed are those the programs weld: each robot's last change is its program's order.
    programs = {r["name"]: r["spots"] for r in summary["robots"]}
    assert all(programs[c["robot"]] == c["spots"] for c in {c["robot"]: c for c in summary["order_changes"]}.values())
    assert isinstance(summary["orders_skipped"], int) and summary["orders_tried"] >= 1
    assert summary["makespan"] < 0.9 * waiting        # 14.29 s waiting, 11.00 s reordered when written
    assert summary["lower_bound"]["value"] <= summary["makespan"]


def test_plot_replays_the_written_programs_into_a_gantt_chart(planned: dict[str, str]) -> None:
    """`--plot` on a station: the programs just written replayed together (one chart per dialect
    set: SRCL's, then `<station>.<ext>` for the next, KRL here), the command's exit 0 saying the
    replay was clean."""
    png = "89504e470d0a1a0a"
    charts = {name: head for name, head in planned.items() if name.endswith(".gantt.png")}
    assert charts == {"crossing.gantt.png": png, "crossing.src.gantt.png": png}


@pytest.mark.slow
def test_the_nearest_robots_assignment_is_planned_where_the_min_max_ones_wait(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The min-max estimate knows nothing of the other robot: here it is made to cross (r1 welds
    l4, nearer r2's base, and r2 welds l1, nearer r1's), and the re-assignment with the waits as
    costs is made to give the same. The nearest-robot assignment is then planned too and kept, being
    shorter (14.58 s crossing, 10.13 s not, when written)."""
    from robomax_py.station import pipeline
    from robomax_py.station.assign import Assignment

    station = load_station(TWO)
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    crossing = Assignment({"r1": (("front_rail", "f1"), ("front_rail", "f4"), ("left_rail", "l4"), ("right_rail", "r1")),
                           "r2": (("left_rail", "l1"), ("right_rail", "r4"))}, {"r1": 1.0, "r2": 1.0})
    monkeypatch.setattr(pipeline, "assign", lambda *args, **kwargs: crossing)
    plan = plan_station(station, models)
    assert plan.status == "planned" and plan.rounds == 1
    near = {r: set(spots) for r, spots in plan.assignment.spots.items()}
    assert near == {"r1": {("front_rail", "f1"), ("front_rail", "f4"), ("left_rail", "l1"), ("right_rail", "r1")},
                    "r2": {("left_rail", "l4"), ("right_rail", "r4")}}
    # Not planned where a robot's own cycle is predicted to reach the best makespan: the crossing
    # plan is kept, the longer.
    monkeypatch.setattr(pipeline, "_predicted_longest", lambda *args, **kwargs: float("inf"))
    skipped = plan_station(station, models)
    assert skipped.rounds == 0
    assert {r: set(s) for r, s in skipped.assignment.spots.items()} == {r: set(s) for r, s in crossing.spots.items()}
    assert plan.makespan < skipped.makespan - 1.0


def test_the_prediction_of_another_assignments_longest_own_cycle() -> None:
    """Each robot's planned own cycle scaled by its estimated tour there over its estimated tour
    now; a robot idle now counts its estimate."""
    from types import SimpleNamespace

    from robomax_py.station.assign import Assignment
    from robomax_py.station.pipeline import _predicted_longest

    def robot(name: str, own: float, spots: list[str]) -> SimpleNamespace:
        done = [SimpleNamespace(seam="s", name=n) for n in spots]
        return SimpleNamespace(robot=name, own_cycle=own, result=SimpleNamespace(spots=done))

    plan = SimpleNamespace(robots=(robot("r1", 10.0, ["a", "b"]), robot("r2", 0.0, [])))
    other = Assignment({"r1": (("s", "a"),), "r2": (("s", "b"), ("s", "c"))}, {"r1": 0.0, "r2": 0.0})
    tour = {("r1", 2): 4.0, ("r1", 1): 2.0, ("r2", 0): 0.0, ("r2", 2): 7.0}
    longest = _predicted_longest(plan, other, lambda r, order: tour[(r, len(order))])  # type: ignore[arg-type]
    assert longest == pytest.approx(max(10.0 * 2.0 / 4.0, 7.0))

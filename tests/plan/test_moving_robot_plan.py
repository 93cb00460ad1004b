"""Another robot replaying a trajectory file in the arm's way (tests/data/moving/two_robots.yaml):
the time-aware plan is written, its programs read back and rebuilt as planned (the proof of
`publish`), and `verify` finds them clean.

Its route round the sweeping arm is timed in pieces that stop where the search waited; where the
stop alone lets the arm pass, no wait is added, and the program must still stop there: flown by,
it ran 11 ms faster than the motion checked against the other arm, and the write was refused."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.publish import publish
from robomax_py.verify import verify_program

CELL = Path(__file__).resolve().parents[1] / "data" / "moving" / "two_robots.yaml"
FORMATS = ("srcl", "krl")        # robomax's own language, and a controller's with its own fly-by terms


def _written() -> dict[str, Any]:
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    files, checked = publish(result, cell, robot, FORMATS)      # ExportError when a program does not prove
    halts = [(k, s.index) for k, t in enumerate(result.transitions) for s in t.stages if s.wait is None]
    return {"status": result.status, "files": files, "halts": halts,
            "differences": {c.format: c.difference for c in checked}}


@pytest.fixture(scope="module")
def written(shared_once: Callable[[str, Callable[[], Any]], Any]) -> dict[str, Any]:
    key = "moving-two-robots " + CELL.read_text() + (CELL.parent / "sweep.json").read_text()
    out: dict[str, Any] = shared_once(key, _written)
    return out


@pytest.mark.slow
def test_the_route_round_the_other_robot_is_written_and_verifies_clean(written: dict[str, Any],
                                                                      tmp_path: Path) -> None:
    assert written["status"] == "planned"
    # The proof's own tolerances (tolerances.DEFAULT: rebuilt_*), not wider ones.
    assert all(d.within() for d in written["differences"].values()), written["differences"]
    # The route halts without waiting somewhere (the case this cell is here for).
    assert written["halts"]
    for name, text in written["files"].items():
        (tmp_path / name).write_text(text)
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    for main in ("two_robots.srcl", "two_robots.src"):
        report = verify_program(cell, robot, tmp_path / main)
        assert report.clean, (main, report.violations)


@pytest.mark.slow
def test_the_halt_without_a_wait_is_written_as_a_stop(written: dict[str, Any]) -> None:
    """In SRCL a joint move that flies by says FLYBY; the move to the halting waypoint does not,
    and no WAIT follows it (the robot goes on at once)."""
    lines = [line.strip() for line in written["files"]["two_robots.srcl"].splitlines()]
    moves = [i for i, line in enumerate(lines) if line.startswith("MOVE PTP")]
    stops = [i for i in moves[1:-1] if "FLYBY" not in lines[i] and not lines[i + 1].startswith("{ wait")]
    assert len(stops) == len(written["halts"]), (stops, written["halts"])

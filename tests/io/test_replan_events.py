"""The replanning event grammar (`robomax replan --event`): what it reads, what it refuses, and a
cell with the events applied (on the shipped tending cell: two machines whose doors are closed
[0, 9], [16, 25], [32, 41] (cnc1) and [3, 12], [19, 28], [35, 44] (cnc2))."""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.errors import EventError
from robomax_py.io.cell import load_cell
from robomax_py.io.replan_events import (
    Appear,
    Late,
    Remove,
    Windows,
    apply_events,
    parse_event,
)
from robomax_py.spec import Box, CellSpec, Cylinder, Sphere

REPO = Path(__file__).resolve().parents[2]
TOL_S = 1e-9


@pytest.fixture(scope="module")
def cell() -> CellSpec:
    return _shipped()


def _windows(cell: CellSpec, name: str) -> tuple[tuple[float, float], ...]:
    d = next(d for d in cell.dynamic if d.name == name)
    assert d.present is not None
    return d.present


def test_a_machine_named_means_its_door(cell: CellSpec) -> None:
    ev = parse_event("late:cnc1=+4", cell)
    assert isinstance(ev, Late) and ev.name == "cnc1_door" and ev.seconds == pytest.approx(4.0)
    assert parse_event("late:cnc1_door=2.5", cell) == Late("late:cnc1_door=2.5", "cnc1_door", 2.5)


def test_late_delays_the_window_in_progress_or_next(cell: CellSpec) -> None:
    before = _windows(cell, "cnc1_door")
    # At 5 s the first machining [0, 9] is in progress: it ends 4 s later, the others stay.
    after = _windows(apply_events(cell, (parse_event("late:cnc1=4", cell),), 5.0), "cnc1_door")
    assert after[0] == pytest.approx((before[0][0], before[0][1] + 4.0), abs=TOL_S)
    assert after[1:] == before[1:]
    # At 12 s the door is open: the next machining [16, 25] ends later.
    after = _windows(apply_events(cell, (parse_event("late:cnc1=4", cell),), 12.0), "cnc1_door")
    assert after[0] == before[0]
    assert after[1] == pytest.approx((before[1][0], before[1][1] + 4.0), abs=TOL_S)


def test_late_into_the_next_window_merges_them(cell: CellSpec) -> None:
    before = _windows(cell, "cnc1_door")
    gap = before[1][0] - before[0][1]
    after = _windows(apply_events(cell, (parse_event(f"late:cnc1={gap + 1}", cell),), 1.0), "cnc1_door")
    assert len(after) == len(before) - 1
    assert after[0] == pytest.approx((before[0][0], before[1][1]), abs=TOL_S)


def test_late_after_the_last_window_is_refused(cell: CellSpec) -> None:
    with pytest.raises(EventError, match="nothing to delay"):
        apply_events(cell, (parse_event("late:cnc1=4", cell),), 50.0)


def test_window_replaces_and_none_empties(cell: CellSpec) -> None:
    ev = parse_event("window:cnc1_door=30-36, 50-56", cell)
    assert isinstance(ev, Windows) and ev.windows == ((30.0, 36.0), (50.0, 56.0))
    assert _windows(apply_events(cell, (ev,), 10.0), "cnc1_door") == ((30.0, 36.0), (50.0, 56.0))
    changed = apply_events(cell, (parse_event("window:cnc2=none", cell),), 10.0)
    assert _windows(changed, "cnc2_door") == ()
    assert next(m for m in changed.machines if m.name == "cnc2").windows == ()


def test_appear_now_and_for_good_is_static_else_dynamic(cell: CellSpec) -> None:
    now = parse_event("appear:crate box=0.3,0.3,0.3 xyz=1,0,1 rpy=0,0,45", cell)
    assert isinstance(now, Appear) and isinstance(now.obj.shape, Box)
    np.testing.assert_allclose(now.obj.T_world_object[:3, 3], [1, 0, 1], atol=1e-12)
    np.testing.assert_allclose(now.obj.T_world_object[0, 1], -math.sin(math.radians(45)), atol=1e-12)
    changed = apply_events(cell, (now,), 10.0)
    assert "crate" in {o.name for o in changed.objects} and "crate" not in {d.name for d in changed.dynamic}
    later = parse_event("appear:ball sphere=0.1 xyz=0,-1,1 from=20 until=30", cell)
    assert isinstance(later, Appear) and isinstance(later.obj.shape, Sphere)
    assert _windows(apply_events(cell, (later,), 10.0), "ball") == ((20.0, 30.0),)
    post = parse_event("appear:post cylinder=0.05,1 xyz=0.5,0.5,0.5 from=12", cell)
    assert isinstance(post, Appear) and isinstance(post.obj.shape, Cylinder)
    assert _windows(apply_events(cell, (post,), 10.0), "post") == ((12.0, math.inf),)


def test_remove_static_dynamic_and_a_machines_door(cell: CellSpec) -> None:
    assert parse_event("remove:cnc2", cell) == Remove("remove:cnc2", "cnc2_door")
    changed = apply_events(cell, (parse_event("remove:conveyor", cell), parse_event("remove:cnc2", cell)), 3.0)
    assert "conveyor" not in {o.name for o in changed.objects}
    assert [d.name for d in changed.dynamic] == ["cnc1_door"]


BAD = [
    ("late:cnc9=+4", "unknown dynamic object or machine 'cnc9'"),
    ("late:conveyor=4", "unknown dynamic object or machine 'conveyor'"),
    ("late:cnc1=nan", "plain decimal"),
    ("late:cnc1=inf", "plain decimal"),
    ("late:cnc1=1e999", "outside"),
    ("late:cnc1=0", "outside"),
    ("late:cnc1=-3", "outside"),
    ("late:cnc1=0x10", "plain decimal"),
    ("late:cnc1=1_000", "plain decimal"),
    ("late:cnc1", "expected late:NAME="),
    ("late:cnc1=__import__('os')", "plain decimal"),
    ("window:cnc1_door=36-30", "not after its start"),
    ("window:cnc1_door=30-36,34-40", "time order"),
    ("window:cnc1_door=30", "expected a window"),
    ("window:cnc1_door=99999999-100000000", "outside"),
    ("appear:conveyor box=1,1,1 xyz=0,0,0", "already has"),
    ("appear:crate box=1,1 xyz=0,0,0", "3 comma-separated"),
    ("appear:crate box=1,1,1", "xyz"),
    ("appear:crate xyz=0,0,0", "exactly one shape"),
    ("appear:crate box=1,1,1 sphere=1 xyz=0,0,0", "exactly one shape"),
    ("appear:crate box=1,1,1e9 xyz=0,0,0", "outside"),
    ("appear:crate box=1,1,1 xyz=0,0,nan", "plain decimal"),
    ("appear:crate box=1,1,1 xyz=0,0,0 colour=red", "unexpected"),
    ("appear:crate box=1,1,1 xyz=0,0,0 from=5 until=4", "until is not after from"),
    ("appear:../etc box=1,1,1 xyz=0,0,0", "expected a name"),
    ("remove:nothing_here", "unknown object"),
    ("explode:cnc1", "unknown event kind"),
    ("cnc1 late 4", "expected KIND:"),
    ("", "expected KIND:"),
    ("late:" + "x" * 600, "longer than"),
]


@pytest.mark.parametrize(("text", "problem"), BAD)
def test_bad_events_name_the_option_and_the_problem(cell: CellSpec, text: str, problem: str) -> None:
    with pytest.raises(EventError) as caught:
        parse_event(text, cell)
    message = str(caught.value)
    assert message.startswith("--event: ")
    assert problem in message


@functools.cache
def _shipped() -> CellSpec:
    return load_cell(REPO / "cells" / "tending.yaml")


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=120) | st.from_regex(r"(late|window|appear|remove):[a-z0-9_=,.+\- ]{0,40}", fullmatch=True))
def test_any_text_is_an_event_or_an_event_error(text: str) -> None:
    """No input escapes as another exception (a ValueError of float(), an IndexError ...)."""
    try:
        parse_event(text, _shipped())
    except EventError:
        pass

"""The preview's overlay: its markup (escaping, legend from the palette), its facts, where it goes."""

from __future__ import annotations

import html
import json
import re
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import meshcat
import numpy as np
import pytest

from robomax_py.app import palette
from robomax_py.app.preview import populate
from robomax_py.app.preview_overlay import (
    DATA_ID,
    OverlayFacts,
    inject,
    legend_keys,
    overlay_facts,
    overlay_html,
    script_json,
)
from robomax_py.app.preview_program import ShownProgram, ShownSpot, home_program
from robomax_py.app.preview_server import read_overlay
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.timing.trajectory import Phase

SmallCell = Callable[..., Path]   # conftest.write_small_cell
HOSTILE = '<script>alert("x")</script> & </script><!-- \u2028 \'quoted\''


def legend_of(page: str) -> list[tuple[str, str, str]]:
    """(key, colour, label) of each legend entry in an overlay's markup, in order."""
    items = re.findall(r'<li data-key="([^"]*)"><span class="rmx-swatch" style="background:([^"]*)"></span>([^<]*)</li>', page)
    return [(k, c, html.unescape(label)) for k, c, label in items]


def data_of(page: str) -> Any:
    """The overlay's JSON block, parsed as the page's script does."""
    found = re.search(rf'<script type="application/json" id="{DATA_ID}">(.*?)</script>', page, re.DOTALL)
    assert found is not None
    return json.loads(found.group(1))


def facts(**changes: Any) -> OverlayFacts:
    legend = tuple((k, label, palette.hex_colour(c)) for k, (label, c) in palette.LEGEND.items())
    base = OverlayFacts("cell_a", "cell_a.json", 12.5, legend, (("seam1", "s1", 1.0, 1.5), ("seam1", "s2", 3.0, 3.4)))
    return replace(base, **changes)


def test_the_cell_name_is_escaped_in_markup_and_data() -> None:
    page = overlay_html(facts(cell=HOSTILE, program=HOSTILE, spots=((HOSTILE, HOSTILE, 1.0, 2.0),)))
    # The only </script> closes the overlay's own two scripts; no markup of the name gets through.
    assert page.count("</script>") == 2 and "<script>alert" not in page and "<!--" not in page
    shown = re.search(r'<div id="robomax-cell" class="rmx-cell">([^<]*)</div>', page)
    assert shown is not None and html.unescape(shown.group(1)) == HOSTILE
    data = data_of(page)
    assert data["cell"] == data["program"] == HOSTILE and data["spots"] == [[HOSTILE, HOSTILE, 1.0, 2.0]]
    assert data["duration"] == 12.5
    assert all(c not in script_json(HOSTILE) for c in "<>&")


def test_the_legend_is_the_palettes_colours_and_words() -> None:
    page = overlay_html(facts())
    assert legend_of(page) == [(k, palette.hex_colour(c), label) for k, (label, c) in palette.LEGEND.items()]
    got = {k: c for k, c, _ in legend_of(page)}
    assert got["robot"] == palette.hex_colour(palette.ROBOT)
    assert got["part"] == palette.hex_colour(palette.ROLE_COLOURS["part"])
    assert got["spot"] == palette.hex_colour(palette.SPOT)
    assert got["detour"] == palette.hex_colour(palette.PHASE_COLOURS["detour"])
    # Every role and every phase drawn as a line has its entry.
    assert set(palette.ROLE_COLOURS) <= set(palette.LEGEND)
    drawn_kinds = set(palette.PHASE_COLOURS) - {"weld", "wait"}
    assert set().union(*palette.PATH_LEGEND_KINDS.values()) == drawn_kinds
    for key, kinds in palette.PATH_LEGEND_KINDS.items():
        assert all(palette.phase_colour(k) == palette.LEGEND[key][1] for k in kinds)


def test_the_controls_are_on_the_page_with_the_cycle_time() -> None:
    page = overlay_html(facts())
    for element in ('id="robomax-play"', 'id="robomax-scrub"', 'id="robomax-time"', 'id="robomax-spot"'):
        assert element in page
    assert 'max="12.500"' in page and "0.00 s / 12.50 s" in page
    assert "http:" not in page and "https:" not in page and " src=" not in page     # nothing fetched


def test_inject_puts_the_fragment_before_the_last_body_end() -> None:
    page = "<html><body><script>var s = '</body>';</script>\n</body></html>"
    assert inject(page, "<p>x</p>") == "<html><body><script>var s = '</body>';</script>\n<p>x</p></body></html>"
    assert inject("<p>no body</p>", "<i>x</i>") == "<p>no body</p><i>x</i>"


def test_read_overlay_takes_one_json_line_and_leaves_the_rest(tmp_path: Path) -> None:
    import os

    read_end, write_end = os.pipe()
    try:
        os.write(write_end, json.dumps("<b>é</b>\n").encode("ascii") + b"\nafter")
        assert read_overlay(read_end) == "<b>é</b>\n"
        assert os.read(read_end, 100) == b"after"
        os.close(write_end)
        write_end = -1
        assert read_overlay(read_end) is None
    finally:
        os.close(read_end)
        if write_end >= 0:
            os.close(write_end)
    bad_read, bad_write = os.pipe()
    try:
        os.write(bad_write, b"[1, 2]\n")
        with pytest.raises(ValueError, match="not a JSON string"):
            read_overlay(bad_read)
    finally:
        os.close(bad_read)
        os.close(bad_write)


class Recorder:
    """A meshcat window that keeps the lowered commands instead of sending them to a server."""

    def __init__(self) -> None:
        self.commands: list[dict[str, Any]] = []

    def send(self, command: Any) -> None:
        self.commands.append(command.lower())


def test_the_legend_names_what_the_scene_draws(tmp_path: Path, write_small_cell: SmallCell) -> None:
    cell = load_cell(write_small_cell(tmp_path, "small_cell"))
    robot = load_cell_robot(cell)
    home = np.asarray(cell.home, dtype=float)
    t = np.array([0.0, 1.0, 2.0, 2.5])
    q = np.stack([home, home + 0.05, home + 0.1, home + 0.1])
    phases = (Phase("approach", "", 0.0, 1.0, 0, 1), Phase("detour", "", 1.0, 2.0, 1, 2), Phase("weld", "", 2.0, 2.5, 2, 3))
    spot = cell.seams[0].spots[0]
    program = ShownProgram("/some/folder/small_cell.json", t, q, phases, (ShownSpot(cell.seams[0].name, spot.name, 2.0, 2.5),))
    content = populate(meshcat.Visualizer(window=Recorder()), cell, robot, program)
    keys = legend_keys(cell, program)
    assert keys == ({"robot", "tool_body", "tool_tips", "spot"} | {role for _, role, _ in content.objects}
                    | {kind for _, kind, _ in content.path_lines})
    shown = overlay_facts(cell, program)
    assert shown.cell == cell.name and shown.program == "small_cell.json" and shown.duration == 2.5
    assert [k for k, _, _ in shown.legend] == [k for k in palette.LEGEND if k in keys]
    assert shown.spots == ((cell.seams[0].name, spot.name, 2.0, 2.5),)
    # At home: no path, no spot times; with the voxel map drawn, its entry.
    at_home = overlay_facts(cell, home_program(cell), voxels=True)
    legend = {k for k, _, _ in at_home.legend}
    assert "voxel" in legend and not legend & set(palette.PATH_LEGEND_KINDS)
    assert at_home.spots == () and at_home.program == "home" and at_home.duration == 0.0

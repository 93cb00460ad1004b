"""The preview in a real browser: headless Debian chromium driven by Playwright.

The `--html` page is opened from disk with the network features of the browser off; the test asserts
the scene really drew (pixels in the robot's colour inside the canvas), that nothing but the page
itself and its inline data was requested, and that the console shows no errors. The served preview
(`robomax preview CELL`, on loopback) is opened at the URL it prints: the page's WebSocket, which
carries the browser's own Origin, gets the scene and it draws.

On both pages the overlay is checked as a person sees it: the cell's name and the legend on screen,
Play advancing the time readout, the slider setting the animation's time (read back from meshcat's
animator and from the readout, not from the wall clock) and the spot at that time named.

Skips when /usr/bin/chromium (or the playwright package) is missing, unless ROBOMAX_REQUIRE_BROWSER
is set (CI sets it): then it fails. Playwright never downloads a browser here.
"""

from __future__ import annotations

import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from robomax_py.app import palette
from robomax_py.app.cli import EXIT_OK, app

pytestmark = pytest.mark.slow

SmallCell = Callable[..., Path]   # conftest.write_small_cell
Served = Any                      # tests/app/conftest.Served
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
VIEWPORT = {"width": 1000, "height": 700}
SETTLE_MS = 2500                 # the viewer draws the scene and starts the animation
POLL_MS = 50                     # between two looks at the page while waiting for it to change
POLL_TRIES = 200                 # looks before giving up (a bound on tries, not a deadline)
MIN_ROBOT_FRACTION = 0.01        # of the canvas' pixels in the robot's colour
runner = CliRunner()


def _browser_or_skip() -> Any:
    """playwright.sync_api, or skip (fail when ROBOMAX_REQUIRE_BROWSER is set) if it cannot run."""
    problem = None
    if not CHROMIUM.is_file():
        problem = f"{CHROMIUM} not found (apt-get install chromium)"
    try:
        from playwright import sync_api
    except ImportError:
        problem = problem or "the playwright package is not installed (pip install -e '.[test]')"
        sync_api = None
    if problem is not None:
        if os.environ.get("ROBOMAX_REQUIRE_BROWSER"):
            pytest.fail(f"ROBOMAX_REQUIRE_BROWSER is set but {problem}")
        pytest.skip(problem)
    return sync_api


def robot_coloured(rgb: np.ndarray) -> np.ndarray:
    """(h, w, 3) uint8 -> (h, w) bool: pixels of palette.ROBOT's hue under any shading.

    Lambert shading scales the channels together, so the ratios of the orange stay: red bright,
    green between 35 % and 80 % of red, blue below 35 % of red.
    """
    want = np.array([(palette.ROBOT >> 16) & 0xFF, (palette.ROBOT >> 8) & 0xFF, palette.ROBOT & 0xFF], dtype=float)
    assert want[0] > 200 and 0.35 < want[1] / want[0] < 0.8 and want[2] / want[0] < 0.35   # the rule fits the palette
    r, gr, b = (rgb[..., i].astype(float) for i in range(3))
    return (r > 120) & (gr > 0.35 * r) & (gr < 0.8 * r) & (b < 0.35 * r)


def _poll(page: Any, expression: str, arg: Any = None) -> Any:
    """The first truthy value of a page expression, looking up to POLL_TRIES times."""
    for _ in range(POLL_TRIES):
        value = page.evaluate(expression, arg)
        if value:
            return value
        page.wait_for_timeout(POLL_MS)
    pytest.fail(f"{expression!r} stayed false over {POLL_TRIES} looks")


def _readout(page: Any) -> tuple[float, float]:
    """(current, total) s from the overlay's time readout, "1.23 s / 5.09 s"."""
    text = page.inner_text("#robomax-time")
    current, total = (float(part.strip().removesuffix("s")) for part in text.split("/"))
    return current, total


ANIMATION_TIME = "() => Math.max(0, ...viewer.animator.actions.map(a => a.time))"
SET_SCRUB = """t => { const s = document.getElementById('robomax-scrub');
  s.value = String(t); s.dispatchEvent(new Event('input', {bubbles: true})); }"""


def check_overlay(page: Any, cell_name: str, legend: set[str]) -> None:
    """The overlay of the page open in `page`: visible name and legend, working play and slider."""
    assert page.locator("#robomax-overlay .rmx-info").is_visible()
    assert page.inner_text("#robomax-cell") == cell_name
    items = page.locator("#robomax-legend li")
    shown = {items.nth(i).inner_text().strip(): items.nth(i).locator(".rmx-swatch").evaluate(
        "e => getComputedStyle(e).backgroundColor") for i in range(items.count())}
    labels = {palette.LEGEND[k][0]: palette.LEGEND[k][1] for k in legend}
    assert set(labels) <= set(shown), sorted(set(labels) - set(shown))
    for label, colour in labels.items():
        assert shown[label] == f"rgb({colour >> 16 & 0xFF}, {colour >> 8 & 0xFF}, {colour & 0xFF})", label
    for control in ("#robomax-play", "#robomax-scrub", "#robomax-time", "#robomax-spot"):
        assert page.locator(control).is_visible(), control
    _poll(page, "() => !document.getElementById('robomax-play').disabled")   # the animation has arrived
    total = page.evaluate("viewer.animator.duration")
    assert total > 1.0 and _readout(page)[1] == pytest.approx(total, abs=0.006)

    # Hold at 0, then Play: the readout and the animation's clock move on.
    if page.inner_text("#robomax-play") == "Pause":
        page.click("#robomax-play")
    page.evaluate(SET_SCRUB, 0.0)
    assert page.inner_text("#robomax-play") == "Play"
    assert _readout(page)[0] == 0.0 and page.evaluate(ANIMATION_TIME) == 0.0
    page.click("#robomax-play")
    assert page.inner_text("#robomax-play") == "Pause"
    _poll(page, "() => parseFloat(document.getElementById('robomax-time').textContent) > 0.2")
    page.click("#robomax-play")
    assert page.inner_text("#robomax-play") == "Play"
    held = page.evaluate(ANIMATION_TIME)
    assert 0.2 < held < total and _readout(page)[0] == pytest.approx(held, abs=0.006)

    # The slider sets the animation's time: into the first spot's weld, which the overlay names.
    seam, name, t_arrive, t_leave = page.evaluate(
        "JSON.parse(document.getElementById('robomax-overlay-data').textContent).spots[0]")
    t_weld = (t_arrive + t_leave) / 2
    page.evaluate(SET_SCRUB, t_weld)
    assert page.evaluate(ANIMATION_TIME) == pytest.approx(t_weld, abs=1e-3)
    _poll(page, "t => Math.abs(parseFloat(document.getElementById('robomax-time').textContent) - t) < 0.006", t_weld)
    assert page.inner_text("#robomax-spot") == f"spot 1 of 2: {name} ({seam}), welding"
    page.evaluate(SET_SCRUB, total)
    assert page.evaluate(ANIMATION_TIME) == pytest.approx(total, abs=1e-3)
    _poll(page, "() => document.getElementById('robomax-spot').textContent.endsWith(', welded')")
    assert _readout(page) == pytest.approx((total, total), abs=0.006)


# What the small cell's planned program draws (its legend entries).
SMALL_CELL_LEGEND = {"robot", "tool_body", "tool_tips", "part", "clamp", "fixture", "spot", "approach", "retract", "detour"}


def test_html_preview_draws_the_robot_offline_without_console_errors(tmp_path: Path, write_small_cell: SmallCell) -> None:
    sync_api = _browser_or_skip()
    from PIL import Image

    cell = write_small_cell(tmp_path, "small_cell")
    out = tmp_path / "programs"
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out)])
    assert result.exit_code == EXIT_OK, result.output
    page_file = tmp_path / "small_cell.html"
    result = runner.invoke(app, ["preview", str(cell), str(out / "small_cell.json"), "--html", str(page_file)])
    assert result.exit_code == EXIT_OK, result.output

    errors: list[str] = []
    requests: list[str] = []
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport=VIEWPORT)
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("request", lambda r: requests.append(r.url))
            page.goto(page_file.resolve().as_uri())
            page.wait_for_selector("canvas")
            page.wait_for_timeout(SETTLE_MS)
            box = page.locator("canvas").first.bounding_box()
            shot = page.screenshot()
            check_overlay(page, "small_cell", SMALL_CELL_LEGEND)
        finally:
            browser.close()

    assert errors == [], errors
    assert all(u.startswith(("file:", "data:")) for u in requests), [u for u in requests if not u.startswith(("file:", "data:"))]
    assert box is not None and box["width"] > 100 and box["height"] > 100
    image = np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"))
    x0, y0 = int(box["x"]), int(box["y"])
    canvas = image[y0:y0 + int(box["height"]), x0:x0 + int(box["width"])]
    (tmp_path / "screenshot.png").write_bytes(shot)
    fraction = float(np.mean(robot_coloured(canvas)))
    assert fraction > MIN_ROBOT_FRACTION, f"{fraction:.4f} of the canvas in the robot's colour: the scene did not draw"
    # Not a blank canvas: many distinct colours (shaded meshes, grid, path).
    assert len(np.unique(canvas.reshape(-1, 3)[::7], axis=0)) > 200


def _draw_in_browser(sync_api: Any, url: str, tmp_path: Path,
                     then: Callable[[Any], None] | None = None) -> tuple[list[str], list[str], float, int]:
    """Open `url`, let it draw, (`then(page)`,) and return the console errors, the URLs requested, the
    fraction of the canvas in the robot's colour and the number of distinct colours (sampled)."""
    from PIL import Image

    errors: list[str] = []
    requests: list[str] = []
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport=VIEWPORT)
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("request", lambda r: requests.append(r.url))
            page.goto(url)
            page.wait_for_selector("canvas")
            page.wait_for_timeout(SETTLE_MS)
            box = page.locator("canvas").first.bounding_box()
            shot = page.screenshot()
            if then is not None:
                then(page)
        finally:
            browser.close()
    assert box is not None and box["width"] > 100 and box["height"] > 100
    (tmp_path / "screenshot.png").write_bytes(shot)
    image = np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"))
    x0, y0 = int(box["x"]), int(box["y"])
    canvas = image[y0:y0 + int(box["height"]), x0:x0 + int(box["width"])]
    return errors, requests, float(np.mean(robot_coloured(canvas))), len(np.unique(canvas.reshape(-1, 3)[::7], axis=0))


def test_served_preview_draws_the_robot_over_its_websocket(tmp_path: Path, write_small_cell: SmallCell,
                                                           serve_preview: Callable[..., Served],
                                                           free_port: Callable[..., int]) -> None:
    sync_api = _browser_or_skip()
    cell = write_small_cell(tmp_path, "small_cell")
    out = tmp_path / "programs"
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out)])
    assert result.exit_code == EXIT_OK, result.output
    served = serve_preview(cell, str(out / "small_cell.json"), "--port", str(free_port()))
    assert served.url.startswith("http://127.0.0.1:")
    errors, requests, fraction, colours = _draw_in_browser(
        sync_api, served.url, tmp_path, then=lambda page: check_overlay(page, "small_cell", SMALL_CELL_LEGEND))
    assert errors == [], errors
    origin = served.url.removesuffix("/static/")
    assert all(u.startswith((origin + "/", "data:")) for u in requests), requests
    assert fraction > MIN_ROBOT_FRACTION, f"{fraction:.4f} of the canvas in the robot's colour: the scene did not arrive"
    assert colours > 200
    assert served.stop()[0] == 0

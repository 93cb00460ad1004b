"""Regenerate docs/preview.png: the `robomax preview --html` page of the reference cell, in headless chromium.

    python docs/preview_png.py [PROGRAM] [--cell CELL] [--out docs/preview.png] [--time T]

PROGRAM is a `.json` or `.srcl` written by `robomax plan CELL -o DIR`; without it the reference cell is
planned into a temporary folder first (about a minute). The animation is paused at T seconds (default:
when the middle spot of the program is welded) with the page's own slider, so the picture shows the
overlay as a person sees it: cell name, legend, time and spot. Needs Debian's chromium
(/usr/bin/chromium) and the `playwright` package (`pip install -e '.[test]'`); no browser is downloaded.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
REFERENCE_CELL = REPO.parent / "shared" / "cells" / "reference" / "cabin_flange.yaml"
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
VIEWPORT_PX = (1280, 800)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("program", nargs="?", type=Path, help="program written by robomax plan (.json or .srcl)")
    parser.add_argument("--cell", type=Path, default=REFERENCE_CELL)
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "preview.png")
    parser.add_argument("--time", type=float, default=None, help="program time to show, s")
    args = parser.parse_args()

    from playwright.sync_api import sync_playwright

    from robomax_py.app.preview import write_html
    from robomax_py.app.preview_program import load_program
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.io.files import write_atomic_bytes

    with tempfile.TemporaryDirectory() as tmp:
        cell = load_cell(args.cell)
        program = args.program
        if program is None:
            subprocess.run([sys.executable, "-m", "robomax_py.app.cli", "plan", str(args.cell), "-o", tmp], check=True)
            program = Path(tmp) / f"{cell.name}.json"
        robot = load_cell_robot(cell)
        shown = load_program(program, cell, robot)
        t_show = args.time
        if t_show is None:
            t_show = shown.spots[len(shown.spots) // 2].t_arrive if shown.spots else 0.0
        page_file = Path(tmp) / "preview.html"
        write_html(page_file, cell, robot, shown)
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
            try:
                page = browser.new_page(viewport={"width": VIEWPORT_PX[0], "height": VIEWPORT_PX[1]})
                page.goto(page_file.as_uri())
                page.wait_for_function("!document.getElementById('robomax-play').disabled")
                # Moving the slider holds the animation there, as it does under a person's hand.
                page.evaluate("t => { const s = document.getElementById('robomax-scrub'); s.value = String(t);"
                              " s.dispatchEvent(new Event('input', {bubbles: true})); }", t_show)
                page.wait_for_timeout(800)
                png = page.screenshot()
            finally:
                browser.close()
    write_atomic_bytes(args.out, png)
    print(f"wrote {args.out} ({cell.name}, {Path(program).name}, t = {t_show:.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

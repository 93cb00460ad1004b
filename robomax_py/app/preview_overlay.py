"""What the preview page shows over the 3-D view: the cell's name, a legend, the clock and controls.

meshcat's page has the scene and, behind "Open Controls", its own animation panel. The overlay adds,
always on screen:

- top left: the cell's name and the program shown, and a legend of the colours drawn (from
  `palette.LEGEND`, only the entries this cell and program draw);
- bottom: a play/pause button, a slider over the program's clock, the time (current / cycle, s) and
  the spot at that time: the one being welded, else the last one welded.

It is one HTML fragment (style, markup, script; nothing fetched) put before the page's `</body>`, in
the `--html` file by `preview.write_html` and in the served page by `preview_server`. It drives
meshcat's animation through the page's `viewer.animator` (meshcat 0.3.2): `play()`, `pause()`,
`seek(t)`, `duration`, and its `actions`, whose `time` is the animation's clock. Text from the cell
(its name, spot and seam names) reaches the page escaped: HTML-escaped in the markup, and in a JSON
block whose `<`, `>` and `&` are written as \\u escapes, read by the script and shown as text only.
"""

from __future__ import annotations

import html
import json
from dataclasses import dataclass
from pathlib import PurePath

from robomax_py.app import palette
from robomax_py.app.preview_program import ShownProgram
from robomax_py.spec import CellSpec

# Element ids (the browser test and docs/preview_png.py find the controls by them).
OVERLAY_ID = "robomax-overlay"
DATA_ID = "robomax-overlay-data"


@dataclass(frozen=True, slots=True)
class OverlayFacts:
    """What the overlay states about one preview.

    cell : the cell's name. program : the program file's name, without its folder ("home" for none).
    duration : cycle time, s. legend : ((key, label, '#rrggbb'), ...) in `palette.LEGEND`'s order.
    spots : ((seam, name, t_arrive, t_leave), ...) in weld order, s on the program's clock.
    """

    cell: str
    program: str
    duration: float
    legend: tuple[tuple[str, str, str], ...]
    spots: tuple[tuple[str, str, float, float], ...]


def legend_keys(cell: CellSpec, program: ShownProgram, voxels: bool = False) -> set[str]:
    """The `palette.LEGEND` keys of what `preview.populate` draws for this cell and program."""
    keys = {"robot", "tool_body", "tool_tips"}
    keys.update(palette.object_role(o) for o in cell.objects)
    if cell.dynamic:
        keys.add("dynamic")
    if any(seam.spots for seam in cell.seams):
        keys.add("spot")
    if len(program.t) >= 2:
        drawn = {p.kind for p in program.phases if p.kind != "weld" and p.i_end > p.i_start}
        keys.update(k for k, kinds in palette.PATH_LEGEND_KINDS.items() if drawn.intersection(kinds))
    if voxels:
        keys.add("voxel")
    return keys


def overlay_facts(cell: CellSpec, program: ShownProgram, voxels: bool = False) -> OverlayFacts:
    """The overlay's facts for a preview of `program` in `cell` (`voxels`: the voxel map is drawn)."""
    keys = legend_keys(cell, program, voxels)
    legend = tuple((k, label, palette.hex_colour(colour)) for k, (label, colour) in palette.LEGEND.items() if k in keys)
    spots = tuple((s.seam, s.name, float(s.t_arrive), float(s.t_leave)) for s in program.spots)
    # The file's name only: the page may be shown to others, the folder it was planned into is noise.
    return OverlayFacts(cell.name, PurePath(program.name).name, program.duration, legend, spots)


def script_json(value: object) -> str:
    """JSON safe inside a <script> element: no `<`, `>` or `&` (so no `</script>` or `<!--`)."""
    text = json.dumps(value, ensure_ascii=True, allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def overlay_html(facts: OverlayFacts) -> str:
    """The overlay fragment (style, markup and script) for `facts`."""
    esc = html.escape
    legend = "".join(
        f'<li data-key="{esc(key)}"><span class="rmx-swatch" style="background:{esc(colour)}"></span>{esc(label)}</li>'
        for key, label, colour in facts.legend)
    data = {"cell": facts.cell, "program": facts.program, "duration": facts.duration,
            "spots": [list(s) for s in facts.spots]}
    return (
        f"<style>{_CSS}</style>\n"
        f'<div id="{OVERLAY_ID}">\n'
        f'<div class="rmx-panel rmx-info">'
        f'<div id="robomax-cell" class="rmx-cell">{esc(facts.cell)}</div>'
        f'<div id="robomax-program" class="rmx-program">program: {esc(facts.program)}</div>'
        f'<ul id="robomax-legend" class="rmx-legend">{legend}</ul></div>\n'
        f'<div class="rmx-panel rmx-bar">'
        f'<button id="robomax-play" type="button" disabled>Play</button>'
        f'<input id="robomax-scrub" type="range" min="0" max="{facts.duration:.3f}" step="0.001" value="0" disabled '
        f'aria-label="program time, s">'
        f'<span id="robomax-time" class="rmx-time">0.00 s / {facts.duration:.2f} s</span>'
        f'<span id="robomax-spot" class="rmx-spot"></span></div>\n'
        f"</div>\n"
        f'<script type="application/json" id="{DATA_ID}">{script_json(data)}</script>\n'
        f"<script>{_JS}</script>\n"
    )


def inject(page: str, fragment: str) -> str:
    """`page` with `fragment` put just before its last `</body>` (at its end when it has none)."""
    at = page.rfind("</body>")
    if at < 0:
        return page + fragment
    return page[:at] + fragment + page[at:]


_CSS = """
#robomax-overlay { position: fixed; inset: 0; pointer-events: none; z-index: 10;
  font: 13px/1.35 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; color: #1d2125; }
#robomax-overlay .rmx-panel { position: absolute; pointer-events: auto; background: rgba(255,255,255,0.88);
  border: 1px solid rgba(0,0,0,0.15); border-radius: 6px; box-shadow: 0 1px 4px rgba(0,0,0,0.15); }
#robomax-overlay .rmx-info { top: 10px; left: 10px; max-width: 300px; padding: 8px 12px; }
#robomax-overlay .rmx-cell { font-size: 17px; font-weight: 600; overflow-wrap: anywhere; }
#robomax-overlay .rmx-program { color: #555; margin-bottom: 6px; overflow-wrap: anywhere; }
#robomax-overlay .rmx-legend { list-style: none; margin: 0; padding: 0; }
#robomax-overlay .rmx-legend li { display: flex; align-items: center; gap: 7px; margin: 2px 0; }
#robomax-overlay .rmx-swatch { flex: none; width: 14px; height: 14px; border-radius: 3px; border: 1px solid rgba(0,0,0,0.3); }
#robomax-overlay .rmx-bar { left: 10px; right: 10px; bottom: 10px; padding: 8px 12px;
  display: flex; align-items: center; gap: 12px; flex-wrap: wrap; }
#robomax-overlay .rmx-bar button { min-width: 64px; padding: 4px 10px; font: inherit; font-weight: 600; cursor: pointer; }
#robomax-overlay .rmx-bar input[type=range] { flex: 1 1 240px; min-width: 120px; }
#robomax-overlay .rmx-time { font-variant-numeric: tabular-nums; white-space: nowrap; }
#robomax-overlay .rmx-spot { white-space: nowrap; overflow: hidden; text-overflow: ellipsis; max-width: 45%; }
"""

# Reads meshcat's animator each animation frame. meshcat, when the animation runs out, pauses it and
# rewinds its actions to 0 while the scene still shows the last frame: the overlay then seeks to the
# end, so that the scene, the slider and the readout agree. Play at the end starts from 0.
_JS = """
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("robomax-overlay-data").textContent);
  var play = document.getElementById("robomax-play");
  var scrub = document.getElementById("robomax-scrub");
  var readout = document.getElementById("robomax-time");
  var spotText = document.getElementById("robomax-spot");
  var shown = 0, wasPlaying = false, ready = false;

  function animator() {
    var v = window.viewer;
    return v && v.animator && v.animator.duration > 0 ? v.animator : null;
  }
  function actionTime(a) {
    var t = 0;
    a.actions.forEach(function (x) { t = Math.max(t, x.time); });
    return t;
  }
  function spotAt(t) {
    var s = data.spots, last = -1;
    for (var i = 0; i < s.length; i++) { if (s[i][2] <= t + 1e-9) { last = i; } }
    if (s.length === 0) { return data.program === "home" ? "robot at home (no program)" : "no spots"; }
    if (last < 0) { return "next spot: " + s[0][1] + " (" + s[0][0] + "), 1 of " + s.length; }
    var welding = t <= s[last][3] + 1e-9;
    return "spot " + (last + 1) + " of " + s.length + ": " + s[last][1] + " (" + s[last][0] + ")"
      + (welding ? ", welding" : ", welded");
  }
  function seek(a, t) {
    shown = Math.max(0, Math.min(a.duration, t));
    a.seek(shown);
    a.display_progress(shown);           // meshcat's own panel shows the same time
  }
  function show(a) {
    var total = a ? a.duration : data.duration;
    readout.textContent = shown.toFixed(2) + " s / " + total.toFixed(2) + " s";
    if (document.activeElement !== scrub || (a && a.playing)) { scrub.value = String(shown); }
    play.textContent = a && a.playing ? "Pause" : "Play";
    spotText.textContent = spotAt(shown);
  }
  function tick() {
    var a = animator();
    if (a) {
      if (!ready) {
        ready = true;
        scrub.max = String(a.duration);
        play.disabled = false;
        scrub.disabled = false;
      }
      var t = actionTime(a);
      if (!a.playing && wasPlaying && t === 0 && shown > 0) {
        seek(a, a.duration);             // ran out: meshcat rewound its actions, the scene shows the end
      } else {
        shown = t;                       // playing, or paused (by either panel) where it stands
      }
      wasPlaying = a.playing;
    }
    show(a);
    window.requestAnimationFrame(tick);
  }
  play.addEventListener("click", function () {
    var a = animator();
    if (!a) { return; }
    if (a.playing) {
      a.pause();
      shown = actionTime(a);
    } else {
      if (shown >= a.duration - 1e-6) { seek(a, 0); }
      a.play();
    }
    wasPlaying = a.playing;
    show(a);
  });
  scrub.addEventListener("input", function () {
    var a = animator();
    if (!a) { return; }
    if (a.playing) { a.pause(); wasPlaying = false; }   // scrubbing holds the animation
    seek(a, parseFloat(scrub.value));
    show(a);
  });
  show(null);
  window.requestAnimationFrame(tick);
})();
"""


__all__ = ["DATA_ID", "OVERLAY_ID", "OverlayFacts", "inject", "legend_keys", "overlay_facts", "overlay_html", "script_json"]

"""The dialects robomax ships, as the `robomax_py.dialects` entry points name them (pyproject.toml).

`export.DIALECTS` loads every dialect registered under that entry point group; these objects are
also its fallback when the package's own entry points are not installed (a source checkout run
without `pip install -e`).
"""

from __future__ import annotations

from robomax_py.export import fanuc, inform, kawasaki_as, krl, rapid, srcl, urscript
from robomax_py.export.dialect import Dialect

__all__ = ["AS", "FANUC", "INFORM", "KRL", "RAPID", "SHIPPED", "SRCL", "URSCRIPT"]

SRCL = Dialect("srcl", (".srcl",), "", srcl.adapt, srcl.write, srcl.parse, splines=True, six_axes=False)
KRL = Dialect("krl", (".src", ".dat"), "kuka", krl.adapt, krl.write, krl.parse, krl.frame_name,
              (krl.FRAMES_FILE,), krl.FILE_ENCODING, program_name=krl.program_name, splines=True,
              signals=krl.SIGNALS)
RAPID = Dialect("rapid", (".mod",), "abb", rapid.adapt, rapid.write, rapid.parse, companions=(rapid.FRAMES_FILE,),
                program_name=rapid.program_name, named_frames_only=True)
FANUC = Dialect("fanuc", (".ls",), "fanuc", fanuc.adapt, fanuc.write, fanuc.parse, fanuc.frame_name,
                (fanuc.FRAMES_FILE,), program_name=fanuc.program_name,
                shared=tuple(f"{name}.ls" for name in fanuc.ROUTINES), signals=fanuc.SIGNALS)
URSCRIPT = Dialect("urscript", (".script",), "ur", urscript.adapt, urscript.write, urscript.parse,
                   signals=urscript.SIGNALS)
INFORM = Dialect("inform", (".jbi",), "yaskawa", inform.adapt, inform.write, inform.parse, inform.frame_name,
                 program_name=inform.program_name, shared=tuple(f"{name}{inform.EXT}" for name in inform.ROUTINES),
                 needs=inform.needs, signals=inform.SIGNALS)
AS = Dialect("as", (".as", ".pg"), "kawasaki", kawasaki_as.adapt, kawasaki_as.write, kawasaki_as.parse,
             kawasaki_as.frame_name, any_extension=True, signals=kawasaki_as.SIGNALS)

# In the order files are written (after the trajectory file).
SHIPPED: tuple[Dialect, ...] = (SRCL, KRL, RAPID, FANUC, URSCRIPT, INFORM, AS)

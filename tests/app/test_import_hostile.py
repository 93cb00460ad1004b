"""Robot packages as untrusted data: a seeded suite of hostile packages, each imported with
`robomax import-urdf` and held to its expected outcome, and imports killed at random instants.

Every package is the FANUC M-20iA support package of tests/data/rosi (with fanuc_resources) in a
workspace folder given as `--packages`, with one hostile change: a xacro expression that would run
code or read a file, a macro bomb, a file name that leaves the package or the output folder, a
visual mesh named like a collision mesh, missing or non-finite geometry, an oversized file, or
absurd joint limits. Files outside the workspace (`outside/`, a secret the package tries to read)
sit beside it. For each case: the exit code, the message (naming the file and the element), the
listing of the whole test folder before and after (a refusal writes nothing anywhere; a success
adds the output folder only), and no side effect (the file a command would have made).

`python tests/app/test_import_hostile.py` prints the figures: cases per class, outcomes, the
slowest refusal (CPU s).
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.app.import_urdf import MARKER_TEXT, STAGING_MARKER, import_urdf
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import load_robot

ROSI = Path(__file__).parent.parent / "data" / "rosi"
PACKAGES = ("fanuc_m20ia_support", "fanuc_resources")
SEED = 30
# Bounds the bomb cases run under (the defaults, 30 s and 1024 MB, would only make them slower).
BOMB_CPU_S, BOMB_MB = 2, 256
runner = CliRunner()


@dataclass(frozen=True)
class Layout:
    """Where a case's files are: `ws` the workspace given as --packages, `pkg` the support package,
    `outside` a folder beside the workspace, `out` the robot folder to write."""

    root: Path
    ws: Path
    pkg: Path
    outside: Path
    out: Path
    sentinel: Path      # what a command run from the package would create

    @property
    def macro(self) -> Path:
        return self.pkg / "urdf" / "m20ia_macro.xacro"

    @property
    def source(self) -> Path:
        return self.pkg / "urdf" / "m20ia.xacro"

    def edit_macro(self, old: str, new: str, count: int = 1) -> None:
        text = self.macro.read_text()
        assert old in text, old
        self.macro.write_text(text.replace(old, new, count))

    def hostile_xacro(self, body: str, name: str = "hostile.xacro") -> Path:
        """A source that builds the arm and adds `body`."""
        path = self.pkg / "urdf" / name
        path.write_text(f'<?xml version="1.0"?>\n<robot name="fanuc_m20ia" xmlns:xacro="http://wiki.ros.org/xacro">\n'
                        f'  <xacro:include filename="$(find fanuc_m20ia_support)/urdf/m20ia_macro.xacro"/>\n'
                        f'  <xacro:fanuc_m20ia prefix=""/>\n  {body}\n</robot>\n')
        return path


def _layout(root: Path) -> Layout:
    ws = root / "ws"
    for name in PACKAGES:
        shutil.copytree(ROSI / name, ws / name)
    outside = root / "outside"
    outside.mkdir()
    (outside / "secret.yaml").write_text("secret: outside-the-package-4711\n")
    (outside / "secret.stl").write_bytes((ws / PACKAGES[0] / "meshes/m20ia/collision/link_1.stl").read_bytes())
    (outside / "evil.xacro").write_text('<robot xmlns:xacro="http://wiki.ros.org/xacro"><secret/></robot>\n')
    return Layout(root, ws, ws / PACKAGES[0], outside, root / "robots" / "m20ia", root / "pwned")


def _box_stl(size: float, nan: bool = False) -> bytes:
    """A binary STL of an axis-aligned cube of edge `size` (m); one vertex NaN when `nan`."""
    import trimesh

    mesh = trimesh.creation.box(extents=[size] * 3)
    triangles = mesh.vertices[mesh.faces].copy()
    if nan:
        triangles[0, 0, 0] = np.nan
    out = bytearray(b"\0" * 80 + struct.pack("<I", len(triangles)))
    for tri in triangles:
        out += struct.pack("<12fH", 0, 0, 0, *tri.ravel(), 0)
    return bytes(out)


def _sparse(path: Path, size: int) -> None:
    """A file of `size` bytes that takes no disk space (never read by a correct import)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as f:
        f.truncate(size)


@dataclass(frozen=True)
class Case:
    cls: str
    name: str
    make: Callable[[Layout], Path]          # builds the hostile change; returns the source to import
    exit_code: int
    words: tuple[str, ...]                  # the message names these (file, element, problem)
    bomb: bool = False

    @property
    def id(self) -> str:
        return f"{self.cls}/{self.name}"


def _cases(seed: int) -> list[Case]:
    """The hostile packages; `seed` picks the link, joint, depth and names each case uses."""
    rng = np.random.default_rng(seed)
    links = [f"link_{k}" for k in range(1, 7)]
    joints = [f"joint_{k}" for k in range(1, 7)]

    def pick(items: list[str]) -> str:
        return str(items[int(rng.integers(len(items)))])

    cases: list[Case] = []

    def add(cls: str, name: str, make: Callable[[Layout], Path], exit_code: int, *words: str, bomb: bool = False) -> None:
        cases.append(Case(cls, name, make, exit_code, words, bomb))

    def expr(body: str) -> Callable[[Layout], Path]:
        return lambda lay: lay.hostile_xacro(body.replace("SENTINEL", str(lay.sentinel)))

    # -- xacro that would run code
    code = "code-executing xacro"
    add(code, "attribute chain to subclasses", expr("<x a=\"${''.__class__.__mro__[1].__subclasses__()}\"/>"), 2,
        "hostile.xacro", "${''.__class__", "'.__subclasses__' is not allowed")
    add(code, "os.system through function globals",
        expr("<x a=\"${xacro.load_yaml.__globals__['os'].system('touch SENTINEL')}\"/>"), 2,
        "hostile.xacro", "${xacro.load_yaml.__globals__", "'.__globals__' is not allowed")
    add(code, "__import__", expr("<x a=\"${__import__('os').system('touch SENTINEL')}\"/>"), 2,
        "hostile.xacro", "${__import__(", "'__import__' is not allowed")
    add(code, "comprehension over subclasses",
        expr("<x a=\"${[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'catch_warnings'][0]()"
             "._module.__builtins__['__import__']('os').system('touch SENTINEL')}\"/>"), 2,
        "hostile.xacro", "'.__builtins__' is not allowed")
    add(code, "comprehension", expr("<x a=\"${[c.__init__ for c in [1]]}\"/>"), 2, "hostile.xacro",
        "a comprehension is not allowed")
    add(code, "lambda globals", expr("<x a=\"${(lambda: 0).__globals__}\"/>"), 2, "hostile.xacro", "'.__globals__'")
    add(code, "python namespace", expr("<x a=\"${python.vars(xacro)}\"/>"), 2, "hostile.xacro",
        "name 'python' is not defined")
    add(code, "method of a str", expr("<x a=\"${'x'.join(xacro.tokenize('a b'))}\"/>"), 2,
        "hostile.xacro", "'.join' of a str is not allowed")
    add(code, "$(eval) import", expr('<x a="$(eval __import__)"/>'), 2, "hostile.xacro", "'__import__' is not allowed")
    add(code, "$(eval) attribute walk", expr('<x a="$(eval dirname.__globals__)"/>'), 2, "hostile.xacro",
        "'.__globals__' is not allowed")
    add(code, "$(env)", expr('<x a="$(env HOME)"/>'), 2, "hostile.xacro", "$(env HOME)", "environment")
    add(code, "$(optenv)", expr('<x a="$(optenv PATH nothing)"/>'), 2, "hostile.xacro", "$(optenv PATH", "environment")

    def yaml_unit_tag(lay: Layout) -> Path:
        (lay.pkg / "config" / "evil.yaml").write_text(f"a: !degrees __import__('os').system('touch {lay.sentinel}')\n")
        return lay.hostile_xacro("<x a=\"${xacro.load_yaml('../config/evil.yaml').a}\"/>")

    add(code, "YAML unit tag", yaml_unit_tag, 2, "'__import__' is not allowed")

    # -- xacro that would read files outside the package folders
    read = "file-reading xacro"
    add(read, "load_yaml /etc/passwd", expr("<x a=\"${xacro.load_yaml('/etc/passwd')}\"/>"), 2,
        "hostile.xacro", "${xacro.load_yaml('/etc/passwd')}", "/etc/passwd is outside the package folders")
    depth = int(rng.integers(3, 9))
    add(read, f"load_yaml ../ x{depth}", expr(f"<x a=\"${{xacro.load_yaml('{'../' * depth}outside/secret.yaml')}}\"/>"),
        2, "hostile.xacro", "xacro.load_yaml('../", "is outside the package folders")
    add(read, "load_yaml $(find)/..", expr("<x a=\"${xacro.load_yaml('$(find fanuc_m20ia_support)/../../outside/"
                                           "secret.yaml')}\"/>"), 2, "hostile.xacro", "secret.yaml is outside")

    def yaml_symlink(lay: Layout) -> Path:
        (lay.pkg / "config" / "link.yaml").symlink_to(lay.outside / "secret.yaml")
        return lay.hostile_xacro("<x a=\"${xacro.load_yaml('../config/link.yaml')}\"/>")

    add(read, "load_yaml symlink out", yaml_symlink, 2, "hostile.xacro", "secret.yaml is outside")

    def yaml_fifo(lay: Layout) -> Path:
        os.mkfifo(lay.pkg / "config" / "fifo.yaml")
        return lay.hostile_xacro("<x a=\"${xacro.load_yaml('../config/fifo.yaml')}\"/>")

    add(read, "load_yaml of a FIFO", yaml_fifo, 2, "hostile.xacro", "fifo.yaml is not a regular file")
    add(read, "include ../../", expr('<xacro:include filename="../../../outside/evil.xacro"/>'), 2,
        "hostile.xacro", "include ../../../outside/evil.xacro", "is outside the package folders")
    add(read, "include /etc/passwd", expr('<xacro:include filename="/etc/passwd"/>'), 2,
        "hostile.xacro", "include /etc/passwd", "outside")
    add(read, "include glob /etc/*", expr('<xacro:include filename="/etc/*.conf"/>'), 2,
        "hostile.xacro", "include /etc/*.conf", "/etc is outside")
    add(read, "include $(find)/..", expr('<xacro:include filename="$(find fanuc_m20ia_support)/../../outside/'
                                         'evil.xacro"/>'), 2, "hostile.xacro", "evil.xacro is outside")
    add(read, "$(find ..)", expr('<xacro:include filename="$(find ..)/outside/evil.xacro"/>'), 2,
        "hostile.xacro", "$(find ..)", "not a package name")
    add(read, "$(find) outside the folders", expr('<xacro:include filename="$(find outside)/evil.xacro"/>'), 2,
        "hostile.xacro", "no package 'outside' in the package folders given")

    def include_symlink(lay: Layout) -> Path:
        (lay.pkg / "urdf" / "link.xacro").symlink_to(lay.outside / "evil.xacro")
        return lay.hostile_xacro('<xacro:include filename="link.xacro"/>')

    add(read, "include symlink out", include_symlink, 2, "hostile.xacro", "include link.xacro", "evil.xacro is outside")

    # -- bombs (run with --xacro-cpu-s BOMB_CPU_S --xacro-mb BOMB_MB)
    bomb = "macro bomb"
    doubling = "".join(f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>' for k in range(1, 25))
    add(bomb, "2^24 expansions", expr(f'<xacro:macro name="m0"><link name="x"/></xacro:macro>{doubling}<xacro:m24/>'),
        2, "hostile.xacro", "xacro expansion exceeds", bomb=True)
    strings = "".join(f'<xacro:property name="s{k}" value="${{s{k - 1} + s{k - 1}}}"/>' for k in range(1, 40))
    add(bomb, "string doubling", expr(f'<xacro:property name="s0" value="xxxxxxxx"/>{strings}<x a="${{s39}}"/>'), 2,
        "hostile.xacro", "${s", "items (at most 1000000)", bomb=True)
    nested = "".join(f'<xacro:property name="l{k}" value="${{[l{k - 1}] * 1000}}"/>' for k in range(1, 6))
    add(bomb, "nested lists", expr(f'<xacro:property name="l0" value="${{[0] * 1000}}"/>{nested}<x a="${{l5}}"/>'), 2,
        "hostile.xacro", "xacro expansion exceeds", bomb=True)
    add(bomb, "huge power", expr('<x a="${9 ** 9 ** 9}"/>'), 2, "hostile.xacro", "${9 ** 9 ** 9}", "bits", bomb=True)
    add(bomb, "self-recursive macro", expr('<xacro:macro name="r"><xacro:r/></xacro:macro><xacro:r/>'), 2,
        "hostile.xacro", "nest too deeply", bomb=True)
    laughs = "".join(f'<!ENTITY l{k} "&l{k - 1};&l{k - 1};&l{k - 1};&l{k - 1};&l{k - 1};&l{k - 1};&l{k - 1};'
                     f'&l{k - 1};&l{k - 1};&l{k - 1};">' for k in range(1, 10))

    def billion_laughs(lay: Layout) -> Path:
        path = lay.pkg / "urdf" / "hostile.xacro"
        path.write_text(f'<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY l0 "lol">{laughs}]>\n'
                        '<robot name="x" xmlns:xacro="http://wiki.ros.org/xacro"><link name="&l9;"/></robot>\n')
        return path

    add(bomb, "billion laughs", billion_laughs, 2, "hostile.xacro", "amplification", bomb=True)

    # -- every field that names a file: the mesh filenames (includes and YAML above)
    escape = "path escape"
    deep = int(rng.integers(4, 9))
    victim = pick(links)

    def mesh_uri(kind: str, uri: str, link: str = victim) -> Callable[[Layout], Path]:
        def make(lay: Layout) -> Path:
            old = f"package://fanuc_m20ia_support/meshes/m20ia/{kind}/{link}.stl"
            lay.edit_macro(old, uri.replace("OUTSIDE", str(lay.outside)))
            return lay.source
        return make

    token = f"escaped_{int(rng.integers(1 << 30)):x}"
    add(escape, f"collision package:// ../ x{deep}", mesh_uri("collision", f"package://fanuc_m20ia_support/{'../' * deep}"
        f"{token}.stl"), 2, "m20ia.xacro", f"link {victim}: collision mesh package://fanuc_m20ia_support/../",
        "leaves its package")
    add(escape, "visual package:// ../", mesh_uri("visual", f"package://fanuc_m20ia_support/../../{token}.stl"), 2,
        "m20ia.xacro", f"link {victim}: visual mesh", "leaves its package")
    add(escape, "collision file:// outside", mesh_uri("collision", "file://OUTSIDE/secret.stl"), 2, "m20ia.xacro",
        f"link {victim}: collision mesh file://", "secret.stl is outside the package folders")
    add(escape, "collision relative ../../../", mesh_uri("collision", "../../../outside/secret.stl"), 2, "m20ia.xacro",
        f"link {victim}: collision mesh ../../../outside/secret.stl", "is outside the package folders")
    add(escape, "package name ..", mesh_uri("collision", "package://../outside/secret.stl"), 2, "m20ia.xacro",
        "'..' is not a package name")
    add(escape, "not a mesh file", mesh_uri("collision", "package://fanuc_m20ia_support/urdf/m20ia.xacro"), 2,
        "m20ia.xacro", f"link {victim}: collision mesh", "not a mesh file")
    add(escape, "URL scheme", mesh_uri("visual", "http://example.com/x.stl"), 2, "m20ia.xacro",
        "only package://, file:// and relative paths")

    def mesh_symlink(lay: Layout) -> Path:
        mesh = lay.pkg / "meshes/m20ia/collision" / f"{victim}.stl"
        mesh.unlink()
        mesh.symlink_to(lay.outside / "secret.stl")
        return lay.source

    add(escape, "mesh symlink out", mesh_symlink, 2, "m20ia.xacro", f"link {victim}: collision mesh",
        "secret.stl is outside")

    add(escape, "texture", expr('<material name="textured"><color rgba="1 1 1 1"/>'
                                '<texture filename="../../../outside/secret.png"/></material>'), 0,
        "material textured: texture ../../../outside/secret.png not imported")

    # -- visual and collision meshes of one file name
    names = "mesh name collision"
    same = pick(links)

    def same_name(lay: Layout) -> Path:
        (lay.pkg / "meshes/m20ia/visual").mkdir(exist_ok=True)
        (lay.pkg / "meshes/m20ia/visual" / f"{same}.stl").write_bytes(_box_stl(2.0))     # much larger than the link
        for kind in ("visual", "collision"):
            lay.edit_macro(f"package://fanuc_m20ia_support/meshes/m20ia/{kind}/{same}.stl",
                           f"../meshes/m20ia/{kind}/{same}.stl")
        return lay.source

    add(names, f"{same}.stl relative", same_name, 0)

    # -- missing and non-finite geometry
    geometry = "missing/NaN geometry"

    def no_collision(lay: Layout) -> Path:
        lay.macro.write_text(re.sub(r"<collision>.*?</collision>", "", lay.macro.read_text(), flags=re.DOTALL))
        return lay.source

    add(geometry, "no <collision> at all", no_collision, 2, "m20ia.xacro", "no <collision> geometry at all, only <visual>")
    bare = pick(links)

    def one_without(lay: Layout) -> Path:
        text = lay.macro.read_text()
        block = re.search(rf'<link name="\$\{{prefix\}}{bare}">.*?</link>', text, re.DOTALL)
        assert block is not None
        lay.macro.write_text(text.replace(block.group(0), re.sub(r"<collision>.*?</collision>", "", block.group(0),
                                                                 flags=re.DOTALL)))
        return lay.source

    add(geometry, f"{bare} without <collision>", one_without, 2, "m20ia.xacro", f"link {bare}",
        "has <visual> but no <collision>")

    def frame_link(lay: Layout) -> Path:
        lay.edit_macro('<link name="${prefix}tool0" />', '<link name="${prefix}tool0" /><link name="${prefix}probe" />'
                       '<joint name="${prefix}probe_slide" type="prismatic"><parent link="${prefix}link_6"/>'
                       '<child link="${prefix}probe"/><axis xyz="0 0 1"/>'
                       '<limit lower="0" upper="0.05" effort="0" velocity="0.1"/></joint>')
        return lay.source

    add(geometry, "moving link with no geometry", frame_link, 0, "link probe moves with joint probe_slide",
        "carry nothing")
    nan_link = pick(links)

    def nan_vertex(lay: Layout) -> Path:
        (lay.pkg / "meshes/m20ia/collision" / f"{nan_link}.stl").write_bytes(_box_stl(0.2, nan=True))
        return lay.source

    add(geometry, f"NaN vertex in {nan_link}", nan_vertex, 2, "m20ia.xacro", f"link {nan_link}",
        "vertices are not finite")

    def missing_collision(lay: Layout) -> Path:
        (lay.pkg / "meshes/m20ia/collision" / f"{victim}.stl").unlink()
        return lay.source

    add(geometry, "collision mesh missing", missing_collision, 2, "m20ia.xacro", f"link {victim}: collision mesh",
        "not found")

    # -- oversized files (sparse: a correct import never reads them)
    size = "oversized file"
    big = pick(links)
    def big_mesh(kind: str, size: int) -> Callable[[Layout], Path]:
        def make(lay: Layout) -> Path:
            _sparse(lay.pkg / "meshes/m20ia" / kind / f"{big}.stl", size)
            return lay.source
        return make

    add(size, "1 GB collision mesh", big_mesh("collision", 1 << 30), 2, "m20ia.xacro", f"link {big}: collision mesh",
        "1024.0 MB is more than the 200 MB allowed")
    add(size, "300 MB visual mesh", big_mesh("visual", 300 << 20), 2, "m20ia.xacro", f"link {big}: visual mesh",
        "300.0 MB is more than the 200 MB allowed")

    def big_include(lay: Layout) -> Path:
        _sparse(lay.pkg / "urdf" / "big.xacro", 21 << 20)
        return lay.hostile_xacro('<xacro:include filename="big.xacro"/>')

    add(size, "21 MB include", big_include, 2, "hostile.xacro", "include big.xacro", "21.0 MB is more than the 20 MB")

    def big_yaml(lay: Layout) -> Path:
        _sparse(lay.pkg / "config" / "big.yaml", 2 << 20)
        return lay.hostile_xacro("<x a=\"${xacro.load_yaml('../config/big.yaml')}\"/>")

    add(size, "2 MB YAML", big_yaml, 2, "hostile.xacro", "xacro.load_yaml", "2.0 MB is more than the 1 MB")

    # -- joint limits
    limits = "joint limits"
    swapped = pick(joints)

    def swap(lay: Layout) -> Path:
        text = lay.macro.read_text()
        m = re.search(rf'name="\$\{{prefix\}}{swapped}".*?<limit lower="([^"]+)" upper="([^"]+)"', text, re.DOTALL)
        assert m is not None
        lay.macro.write_text(text[:m.start(1)] + m.group(2) + text[m.end(1):m.start(2)] + m.group(1) + text[m.end(2):])
        return lay.source

    add(limits, f"lower > upper on {swapped}", swap, 2, "m20ia.xacro", f"joint {swapped}", "> upper")
    for value, words in (("1e-300", "is outside [0.001, 100] rad/s"), ("0", "must be > 0"), ("-3", "must be > 0"),
                         ("nan", "expected a finite number"), ("1e300", "is outside [0.001, 100] rad/s")):
        joint = pick(joints)

        def velocity(lay: Layout, joint: str = joint, value: str = value) -> Path:
            text = lay.macro.read_text()
            m = re.search(rf'name="\$\{{prefix\}}{joint}".*?velocity="([^"]+)"', text, re.DOTALL)
            assert m is not None
            lay.macro.write_text(text[:m.start(1)] + value + text[m.end(1):])
            return lay.source

        add(limits, f"velocity {value} on {joint}", velocity, 2, "m20ia.xacro", f"joint {joint}", words)
    return cases


CASES = _cases(SEED)


def _listing(root: Path) -> dict[str, int]:
    """Every path below `root` with its size (folders 0), symlinks not followed."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = Path(dirpath, n)
            out[str(p.relative_to(root))] = 0 if p.is_dir() and not p.is_symlink() else os.lstat(p).st_size
    return out


@dataclass(frozen=True)
class Outcome:
    exit_code: int
    output: str
    cpu_s: float
    before: dict[str, int]
    after: dict[str, int]


def run_case(case: Case, root: Path) -> tuple[Layout, Outcome]:
    """Build the case's package in `root` and import it with the CLI (in this process; the xacro
    expansion in its child); CPU seconds of both."""
    lay = _layout(root)
    source = case.make(lay)
    before = _listing(root)
    args = ["import-urdf", str(source), "-o", str(lay.out), "--packages", str(lay.ws)]
    if case.bomb:
        args += ["--xacro-cpu-s", str(BOMB_CPU_S), "--xacro-mb", str(BOMB_MB)]
    t0, c0 = time.process_time(), resource.getrusage(resource.RUSAGE_CHILDREN)
    result = runner.invoke(app, args)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = time.process_time() - t0 + (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    return lay, Outcome(result.exit_code, result.output, cpu, before, _listing(root))


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_package(case: Case, tmp_path: Path) -> None:
    lay, got = run_case(case, tmp_path)
    message = " ".join(got.output.split())
    assert got.exit_code == case.exit_code, got.output
    assert "Traceback" not in got.output
    for words in case.words:
        assert words in message, f"{words!r} not in {message!r}"
    assert not lay.sentinel.exists()
    assert not list(tmp_path.parent.glob("escaped_*.stl")) and not list(tmp_path.rglob("escaped_*"))
    written = {k: v for k, v in got.after.items() if k not in got.before}
    if case.exit_code != 0:
        assert got.after == got.before, f"written: {sorted(written)[:5]}"
        return
    out = str(lay.out.relative_to(tmp_path))
    assert {k for k in written if not k.startswith(out + os.sep)} == {"robots", out}
    assert {k: v for k, v in got.after.items() if k in got.before} == got.before
    robot = load_robot(load_robot_spec(lay.out / "robot.yaml"))
    assert robot.collision_model.ngeoms >= 6
    urdf = (lay.out / "m20ia.urdf").read_text()
    assert "outside" not in urdf and "package://" not in urdf and ".." not in urdf
    if case.cls == "mesh name collision":
        _collision_mesh_is_the_collision_one(lay, urdf)


def _collision_mesh_is_the_collision_one(lay: Layout, urdf: str) -> None:
    """The visual and collision meshes of one file name land in two files, each with its own bytes."""
    import xml.etree.ElementTree as ET

    checked = 0
    for link in ET.fromstring(urdf).findall("link"):
        meshes = {kind: [str(m.get("filename")) for el in link.findall(kind) for m in el.iter("mesh")]
                  for kind in ("visual", "collision")}
        if not meshes["collision"]:
            continue
        (collision,), (visual,) = meshes["collision"], meshes["visual"]
        name = Path(collision).name
        assert (lay.out / collision).read_bytes() == (lay.pkg / "meshes/m20ia/collision" / name).read_bytes()
        own_visual = lay.pkg / "meshes/m20ia/visual" / name
        if own_visual.exists():
            assert visual.startswith("meshes/visual/") and collision.startswith("meshes/collision/")
            assert (lay.out / visual).read_bytes() == own_visual.read_bytes() != (lay.out / collision).read_bytes()
            checked += 1
    assert checked == 1


def test_the_suite_covers_every_class() -> None:
    classes = {c.cls for c in CASES}
    assert classes == {"code-executing xacro", "file-reading xacro", "macro bomb", "path escape", "mesh name collision",
                       "missing/NaN geometry", "oversized file", "joint limits"}
    assert len({c.id for c in CASES}) == len(CASES)


# ------------------------------------------------------------------------------ the same rules at load


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("robots")
    return import_urdf(ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro", root / "m20ia", (ROSI,)).folder


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace('velocity="3.054326"', 'velocity="1e-300"', 1), r"joint joint_2: limit velocity 1e-300"),
    (lambda t: t.replace('lower="-2.443461" upper="2.443461"', 'lower="2.443461" upper="-2.443461"', 1),
     r"joint joint_5: limit lower 2\.44346 > upper -2\.44346"),
    (lambda t: re.sub(r"<collision>.*?</collision>", "", t, flags=re.DOTALL), "no <collision> geometry at all"),
])
def test_check_at_load_applies_the_same_rules(imported: Path, tmp_path: Path, edit: Callable[[str], str],
                                              words: str) -> None:
    folder = tmp_path / "m20ia"
    shutil.copytree(imported, folder)
    urdf = folder / "m20ia.urdf"
    urdf.write_text(edit(urdf.read_text()))
    with pytest.raises(RobotModelError, match=words):
        load_robot_spec(folder / "robot.yaml")


def test_robomax_check_refuses_an_absurd_velocity(imported: Path, tmp_path: Path) -> None:
    """Regression: a URDF velocity of 1e-300 passed `check` and ended `plan` in a traceback."""
    folder = tmp_path / "m20ia"
    shutil.copytree(imported, folder)
    urdf = folder / "m20ia.urdf"
    urdf.write_text(urdf.read_text().replace('velocity="3.054326"', 'velocity="1e-300"', 1))
    cell = tmp_path / "cell.yaml"
    cell.write_text(f"""robomax: 1
robot: {{model: {folder / "robot.yaml"}, home: [0, 0, 0, 0, 30, 0]}}
tool: spot_gun_light
objects:
  - {{name: flange, box: [0.002, 0.8, 0.06], pose: {{xyz: [1.05, 0, 0.93]}}, workpiece: true}}
seams:
  - name: flange
    tolerance: {{alpha: 10, beta: 10, gamma: [-180, 180]}}
    spots:
      - {{name: s1, xyz: [1.05, 0, 0.95], normal: [-1, 0, 0], direction: [0, 1, 0]}}
process: {{weld_time: 0.3, approach: 0.03, clearance: 0}}
""")
    result = runner.invoke(app, ["check", str(cell)])
    assert result.exit_code == 2, result.output
    assert "joint joint_2: limit velocity 1e-300 rad/s is outside" in " ".join(result.output.split())


def test_check_at_load_refuses_a_nan_vertex(imported: Path, tmp_path: Path) -> None:
    folder = tmp_path / "m20ia"
    shutil.copytree(imported, folder)
    mesh = next((folder / "meshes/collision").rglob("link_3.stl"))
    mesh.write_bytes(_box_stl(0.2, nan=True))
    with pytest.raises(RobotModelError, match=r"link link_3.*1 of \d+ vertices are not finite"):
        load_robot(load_robot_spec(folder / "robot.yaml"))


def test_check_at_load_warns_about_a_moving_link_without_geometry(imported: Path, tmp_path: Path) -> None:
    folder = tmp_path / "m20ia"
    shutil.copytree(imported, folder)
    # A seventh joint: the closed-form solver is for six.
    description = folder / "robot.yaml"
    description.write_text(re.sub(r"ik:\n(  .*\n)+", "ik:\n  solver: numeric\n", description.read_text()))
    urdf = folder / "m20ia.urdf"
    urdf.write_text(urdf.read_text().replace(
        "</robot>", '<link name="probe"/><joint name="probe_slide" type="prismatic"><parent link="link_6"/>'
                    '<child link="probe"/><limit lower="0" upper="0.05" effort="0" velocity="0.1"/></joint></robot>'))
    robot = load_robot(load_robot_spec(folder / "robot.yaml"))
    assert any("link probe moves with joint probe_slide" in w and "carry nothing" in w for w in robot.warnings)


# ------------------------------------------------------------------------------ staging and kills


def _digest(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_stale_staging_is_cleaned_and_nothing_else(tmp_path: Path) -> None:
    out = tmp_path / "robots" / "m20ia"
    out.parent.mkdir()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                          check=True)
    pid = int(dead.stdout)
    stale = out.parent / f".m20ia.robomax-import-{pid}-abcd1234"
    (stale / "m20ia" / "meshes").mkdir(parents=True)
    (stale / STAGING_MARKER).write_text(f"{MARKER_TEXT}out m20ia\n")
    empty = out.parent / f".m20ia.robomax-import-{pid}-efgh5678"       # killed before its marker
    empty.mkdir()
    half = out.parent / f".m20ia.robomax-import-{pid}-uvwx3456"       # killed while writing its marker
    half.mkdir()
    (half / STAGING_MARKER).write_text(MARKER_TEXT[:20])
    blank = out.parent / f".m20ia.robomax-import-{pid}-yzab7890"      # killed right after creating it
    blank.mkdir()
    (blank / STAGING_MARKER).write_text("")
    foreign = out.parent / f".m20ia.robomax-import-{pid}-cdef1357"    # a marker that is not a prefix of ours
    foreign.mkdir()
    (foreign / STAGING_MARKER).write_text("a note of the user's\n")
    unmarked = out.parent / f".m20ia.robomax-import-{pid}-ijkl9012"   # no marker, not empty: not ours
    (unmarked / "keep").mkdir(parents=True)
    alive = out.parent / f".m20ia.robomax-import-{os.getpid()}-mnop3456"   # a running import's
    alive.mkdir()
    (alive / STAGING_MARKER).write_text(f"{MARKER_TEXT}out m20ia\n")
    lookalike = out.parent / "m20ia.robomax-import-1-abcd1234"        # no leading dot
    lookalike.mkdir()
    import_urdf(ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro", out, (ROSI,))
    assert sorted(p.name for p in out.parent.iterdir()) == sorted(["m20ia", unmarked.name, alive.name, lookalike.name,
                                                                  foreign.name])


def test_a_replacement_killed_between_its_renames_is_put_back(tmp_path: Path) -> None:
    """Where the system cannot exchange two folders, the old one waits in the staging folder; a
    kill there leaves no `out`, and the next import puts the old folder back before it goes on."""
    out = tmp_path / "m20ia"
    import_urdf(ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro", out, (ROSI,))
    (out / "robot.yaml").write_text((out / "robot.yaml").read_text() + "# the user's\n")
    old = _digest(out)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                          check=True)
    stale = tmp_path / f".m20ia.robomax-import-{int(dead.stdout)}-qrst7890"
    stale.mkdir()
    (stale / STAGING_MARKER).write_text(f"{MARKER_TEXT}out m20ia\n")
    os.rename(out, stale / "old")
    with pytest.raises(RobotModelError, match="--force"):
        import_urdf(ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro", out, (ROSI,))
    assert _digest(out) == old and sorted(p.name for p in tmp_path.iterdir()) == ["m20ia"]


KILL_TRIALS = 6


def _import_command(source: Path, out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "robomax_py", "import-urdf", str(source), "-o", str(out), "--packages", str(ROSI),
            *extra]


def _env() -> dict[str, str]:
    import robomax_py

    return {**os.environ, "PYTHONPATH": str(Path(robomax_py.__file__).resolve().parent.parent)}


def kill_trials(root: Path, trials: int, seed: int) -> list[tuple[str, float, str]]:
    """`robomax import-urdf` killed with SIGKILL at seeded instants over its run; half of the trials
    replace a folder (--force). Returns (kind, instant s, outcome) per trial; raises AssertionError
    when a trial leaves anything but the old folder, the new one complete, or none."""
    rng = np.random.default_rng(seed)
    source = ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro"
    reference = root / "reference" / "m20ia"
    t0 = time.monotonic()
    subprocess.run(_import_command(source, reference), env=_env(), check=True, capture_output=True)
    full_s = time.monotonic() - t0          # only to spread the kill instants over a run
    want = _digest(reference)
    results = []
    for trial in range(trials):
        parent = root / f"trial{trial}"
        out = parent / "m20ia"
        replace = trial % 2 == 1
        old = None
        if replace:
            shutil.copytree(reference, out)
            (out / "robot.yaml").write_text((out / "robot.yaml").read_text() + "# an older import\n")
            old = _digest(out)
        instant = float(rng.uniform(0.0, 1.1 * full_s))
        proc = subprocess.Popen(_import_command(source, out, *(["--force"] if replace else [])), env=_env(),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(instant)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if not out.exists():
            outcome = "absent"
        else:
            got = _digest(out)
            assert got in (want, old), f"trial {trial}: a mixed folder"
            outcome = "complete" if got == want else "old"
            if outcome == "complete":
                load_robot(load_robot_spec(out / "robot.yaml"))
        leftovers = sorted(p.name for p in parent.iterdir() if p.name != "m20ia") if parent.exists() else []
        assert all(p.startswith(".m20ia.robomax-import-") for p in leftovers), leftovers
        # The next import succeeds, cleans the stale staging folder and leaves the new folder only.
        done = subprocess.run(_import_command(source, out, "--force"), env=_env(), capture_output=True, text=True,
                              check=False)
        assert done.returncode == 0, done.stderr
        assert _digest(out) == want
        assert sorted(p.name for p in parent.iterdir()) == ["m20ia"]
        results.append(("replace" if replace else "fresh", instant, outcome + (" +staging" if leftovers else "")))
    return results


@pytest.mark.slow
def test_killed_imports_leave_the_old_folder_or_the_new_one(tmp_path: Path) -> None:
    results = kill_trials(tmp_path, KILL_TRIALS, SEED)
    assert len(results) == KILL_TRIALS


def _report() -> None:
    """The figures: cases per class, outcomes, the slowest refusal; kill trials and their outcomes."""
    import tempfile
    from collections import Counter, defaultdict

    per_class: dict[str, Counter[str]] = defaultdict(Counter)
    slowest = (0.0, "")
    for case in CASES:
        with tempfile.TemporaryDirectory() as tmp:
            _lay, got = run_case(case, Path(tmp))
            ok = got.exit_code == case.exit_code and all(w in " ".join(got.output.split()) for w in case.words)
            nothing = got.after == got.before
            outcome = (f"exit {got.exit_code}" + (", nothing written" if nothing else ", folder written")
                       + ("" if ok else " UNEXPECTED"))
            per_class[case.cls][outcome] += 1
            if got.exit_code != 0 and got.cpu_s > slowest[0]:
                slowest = (got.cpu_s, case.id)
            print(f"{case.id:60} {outcome:35} {got.cpu_s:6.2f} CPU s")
    print()
    for cls, outcomes in per_class.items():
        print(f"{cls:25} {sum(outcomes.values()):3} cases: " + "; ".join(f"{n} {o}" for o, n in outcomes.items()))
    print(f"slowest refusal: {slowest[1]} {slowest[0]:.2f} CPU s (bombs run with {BOMB_CPU_S} s / {BOMB_MB} MB)")
    with tempfile.TemporaryDirectory() as tmp:
        for kind, instant, outcome in kill_trials(Path(tmp), KILL_TRIALS, SEED):
            print(f"kill trial ({kind}) at {instant:5.2f} s: {outcome}; the next import succeeded")


if __name__ == "__main__":
    _report()

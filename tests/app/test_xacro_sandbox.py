"""The restricted xacro expansion (`app.xacro_sandbox`, run by `import_urdf.expand`) against xacro
itself: what it allows expands exactly as xacro expands it (the PR2 model of xacro's test suite, the
ROS-Industrial arms, snippets of xacro's `test_xacro.py`), and what could run code or read files is
refused with the file and the expression named.

Snippets are borrowed from github.com/ros/xacro@9d05b0ea7a878511a8615137cd49ade4b0633305
test/test_xacro.py (the installed xacro 2.1.1's branch); the line of each is given.
"""

from __future__ import annotations

import ast
import math
import os
import shutil
import sys
import types
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.app import xacro_sandbox
from robomax_py.app.import_urdf import allowed_folders, expand
from robomax_py.app.xacro_sandbox import FUNCTIONS, Expansion, Refused
from robomax_py.errors import RobotModelError

DATA = Path(__file__).parent.parent / "data"
XACRO_TESTS = DATA / "xacro_tests"           # a folder holding the package `xacro` (its test/ folder)
ROSI = DATA / "rosi"
NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def _unrestricted(source: Path, packages: list[Path]) -> str:
    """xacro 2.1.1 itself on a trusted file, `$(find pkg)` answered from `packages`."""
    import xacro

    def share(name: str) -> str:
        for root in packages:
            if (root / name).is_dir():
                return str(root / name)
        raise LookupError(name)

    mod = types.ModuleType("ament_index_python.packages")
    mod.get_package_share_directory = share  # type: ignore[attr-defined]
    top = types.ModuleType("ament_index_python")
    top.packages = mod  # type: ignore[attr-defined]
    saved = {k: sys.modules.get(k) for k in ("ament_index_python", "ament_index_python.packages")}
    sys.modules["ament_index_python"], sys.modules["ament_index_python.packages"] = top, mod
    try:
        return str(xacro.process_file(str(source)).toprettyxml(indent="  "))
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v


def _restricted(source: Path, packages: list[Path]) -> str:
    return expand(source, allowed_folders(source, packages))


@pytest.mark.slow
def test_pr2_expands_as_xacro_expands_it() -> None:
    # test_xacro.py:395 test_pr2: the PR2 tree (49 files, 8 levels of includes, blocks, macros).
    source = XACRO_TESTS / "xacro/test/robots/pr2/pr2.urdf.xacro"
    got = _restricted(source, [XACRO_TESTS])
    assert got == _unrestricted(source, [XACRO_TESTS])
    assert got.count("<link ") > 80


@pytest.mark.parametrize("arm", ["abb_irb2400_support/urdf/irb2400", "fanuc_m20ia_support/urdf/m20ia",
                                 "kuka_kr120_support/urdf/kr120r2500pro"])
def test_rosi_arms_expand_as_xacro_expands_them(arm: str) -> None:
    source = ROSI / f"{arm}.xacro"
    assert _restricted(source, [ROSI]) == _unrestricted(source, [ROSI])


# (test_xacro.py line, document body, None: the same as xacro | the refusal's words)
SNIPPETS = [
    (798, '<foo function="${1. + sin(pi)}"/>', None),
    (550, '<f v="${0.9 / 2 - 0.2}" />', None),
    (1152, ('<xacro:property name="f" value="1.23"/><xacro:property name="i" value="123"/>'
           '<xacro:property name="s" value="1_2_3"/> float=${f+1} int=${i+1} string=${s}'), None),
    (1140, ('<xacro:property name="l" value="${[0, 1+1, 2]}"/><xacro:property name="t" value="${(0,1+1,2)}"/>'
           '<xacro:property name="d" value="${dict(a=0, b=1+1, c=2)}"/><a list="${l}" tuple="${t}" dict="${d}"/>'), None),
    (1128, '<xacro:property name="l" value="[0, 1+1, 2]"/><a list="${l}"/>', None),
    (503, '<xacro:macro name="foo" params="lst">${lst[-1]}</xacro:macro><xacro:foo lst="${[1,2,3]}"/>', None),
    (509, """<xacro:macro name="foo" params="a='1 -2' c=3"><bar a="${a}" c="${c}"/></xacro:macro><xacro:foo/>""", None),
    (523, ('<xacro:macro name="foo" params="factor"><xacro:property name="foo" value="${21*factor}" scope="parent"/>'
          '</xacro:macro><xacro:foo factor="2"/><a foo="${foo}"/>'), None),
    (423, ('<xacro:macro name="foo"><a>foo</a></xacro:macro><xacro:property name="var" value="foo"/>'
          '<xacro:call macro="${var}"/>'), None),
    (452, ('<xacro:macro name="foo" params="name"><xacro:element xacro:name="${name}"/></xacro:macro>'
          '<xacro:foo name="A"/><xacro:foo name="B"/>'), None),
    (461, ('<xacro:macro name="foo" params="name value"><tag><xacro:attribute name="${name}" value="${value}"/></tag>'
          '</xacro:macro><xacro:foo name="A" value="foo"/>'), None),
    (491, ('<xacro:macro name="inner" params="*the_block"><in_the_inner><xacro:insert_block name="the_block" />'
          '</in_the_inner></xacro:macro><xacro:macro name="outer" params="*the_block"><in_the_outer><xacro:inner>'
          '<xacro:insert_block name="the_block" /></xacro:inner></in_the_outer></xacro:macro><xacro:outer><woot />'
          '</xacro:outer>'), None),
    (703, ('<xacro:if value="false"><a /></xacro:if><xacro:if value="true"><b /></xacro:if>'
          '<xacro:unless value="${3*0}"><c /></xacro:unless>'), None),
    (776, ('<xacro:property name="var" value="useit"/><xacro:if value="${var == \'useit\'}"><foo>bar</foo></xacro:if>'
          '<xacro:if value="${\'use\' in var}"><bar>foo</bar></xacro:if>'), None),
    (870, '<xacro:property name="a" value=" 42 "/><xacro:property name="a2" value="${ 2 * a }"/><a doubled="${a2}"/>',
     None),
    (1050, '<xacro:arg name="foo" default="2"/><a b="$(arg foo)"/>', None),
    (1092, '<xacro:arg name="foo" default="2"/><a b="${xacro.arg(\'foo\')}"/>', None),
    (1247, '<xacro:arg name="foo" default="0.5"/><a a="$(eval 2 * foo)"/>', None),
    (1242, '<xacro:property name="foo" value="$(eval 1 + 2)"/><a a="${2 * foo}"/>', None),
    (1388, '<xacro:property name="settings" value="${xacro.dotify(dict(a=1, b=2))}"/>${settings.a + settings.b}', None),
    (1451, ('<xacro:property name="settings" value="${xacro.load_yaml(\'settings.yaml\')}"/>'
           '${settings.arms.inc2.props.port + 1}'), None),
    (1461, ('<xacro:property name="settings" value="${xacro.load_yaml(\'settings.yaml\')}"/>'
           "${'arms' in settings} ${'baz' in settings}"), None),
    (1470, ('<xacro:property name="l" value="${xacro.load_yaml(\'list.yaml\')}"/>'
           '${l[0][1]} ${l[1][0]} ${l[2].a.A} ${l[2].a.B[0]} ${l[2].a.B[1]} ${l[2].b[0]}'), None),
    (1487, ('<xacro:property name="values" value="${xacro.load_yaml(\'constructors.yaml\')}"/>'
           '<values a="${values.a}" b="${values.b}" c="${values.c}"/>'), None),
    (1416, ('<xacro:property name="settings" value="${xacro.load_yaml(\'settings.yaml\')}"/>'
           '<xacro:include filename="${settings[\'arms\'][\'inc2\'][\'file\']}"/>'
           '<xacro:call macro="${settings[\'arms\'][\'inc2\'][\'macro\']}"/>'), None),
    (630, '<xacro:include filename="include1.xacro" /><xacro:foo/>', None),
    (667, ('<xacro:property name="var" value="main"/><xacro:include filename="include1.xacro" ns="A"/><xacro:include filename="include2.xacro" ns="B"/>'
          '<xacro:A.foo/><xacro:B.foo/><main var="${var}" A="${2*A.var}" B="${B.var+1}"/>'), None),
    (1382, '<xacro:include filename="include3.xacro" ns="C"/><xacro:C.foo/>', None),
    (1397, ('<xacro:property name="prop" value="root"/><xacro:include filename="A.xacro" ns="A"/>'
           '<root prop="${prop}" A.prop="${A.prop}" A.B.prop="${A.B.prop}" /><xacro:A.B.set/><root prop="${prop}"/>'), None),
    (1540, ('<xacro:property name="prop" default="false"/><xacro:unless value="${prop}"><foo/>'
           '<xacro:property name="prop" value="true"/></xacro:unless>'), None),
    # What xacro allows and the restricted evaluator refuses:
    (542, ('<xacro:property name="abc" value="${[1,2,3]}"/><xacro:property name="xyz" '
          'value="${[abc[i]*abc[i] for i in [0,1,2]]}"/>${xyz}'), "a comprehension is not allowed"),
    (1479, "${[2*item.val.x for item in xacro.load_yaml('list2.yaml')]}", "a comprehension is not allowed"),
    (808, "${__import__('math')}", "the name '__import__' is not allowed"),
    (822, '${"".__class__.__base__.__subclasses__()}', "the attribute '.__subclasses__' is not allowed"),
    (1496, ('<xacro:property name="values" value="${xacro.load_yaml(\'constructors_bad2.yaml\')}"/>'
           '<values a="${values.a}" />'), "the name '__import__' is not allowed"),
    (1496, ('<xacro:property name="values" value="${xacro.load_yaml(\'constructors_bad1.yaml\')}"/>'
           '<values a="${values.a}" />'), "name 'os' is not defined"),
]


@pytest.fixture()
def snippet_dir(tmp_path: Path) -> Path:
    """The yaml and xacro files the snippets read, beside them (as xacro's tests run in test/)."""
    for f in (XACRO_TESTS / "xacro/test").iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / f.name)
    return tmp_path


@pytest.mark.parametrize("line, body, refused", SNIPPETS, ids=[f"line{s[0]}-{k}" for k, s in enumerate(SNIPPETS)])
def test_xacro_snippets(snippet_dir: Path, line: int, body: str, refused: str | None) -> None:
    source = snippet_dir / "snippet.xacro"
    source.write_text(f"<a {NS}>{body}</a>")
    if refused is None:
        assert _restricted(source, []) == _unrestricted(source, [])
    else:
        with pytest.raises(RobotModelError, match=refused.replace("(", r"\(").replace(")", r"\)")):
            _restricted(source, [])


# ------------------------------------------------------------------------------ the evaluator in-process


@pytest.fixture()
def expansion(tmp_path: Path) -> Iterator[Expansion]:
    import xacro

    yield Expansion(xacro, [str(tmp_path)], 1_000_000, 1_000_000)


def _evaluate(expansion: Expansion, expr: str, **symbols: object) -> object:
    return expansion.evaluate(expr, {**expansion.symbols, **symbols})


@pytest.mark.parametrize("expr, want", [
    ("1 + 2 * 3 - 4 / 8", 6.5), ("-x ** 2", -4), ("2 ** -1", 0.5), ("7 // 2 + 7 % 2", 4),
    ("radians(180) == pi", True), ("math.atan2(1, 1) * 4", math.pi), ("x if x > 1 else -x", 2),
    ("not x or y", 3.5), ("x and y", 3.5), ("1 < x <= 2", True), ("'a' + 'b' * 2", "abb"),
    ("'%.2f %s' % (x, 'm')", "2.00 m"), ("[1, 2, 3][1:]", [2, 3]), ("{'k': x}['k']", 2),
    ("min(x, y) + max([1, 5]) + abs(-1) + len('abc')", 11), ("int('7') + float('0.5') + round(2.6)", 10.5),
    ("str(bool(0))", "False"), ("floor(2.5) + ceil(2.5) + fabs(-1) + sqrt(4)", 8.0),
    ("sorted([3, 1])", [1, 3]), ("xacro.tokenize('a b,c')", ["a", "b", "c"]),
])
def test_what_xacro_files_use_evaluates(expansion: Expansion, expr: str, want: object) -> None:
    got = _evaluate(expansion, expr, x=2, y=3.5)
    assert got == pytest.approx(want) if isinstance(want, float) else got == want


@pytest.mark.parametrize("expr, words", [
    ("().__class__.__bases__[0].__subclasses__()", "'.__subclasses__'"),
    ("xacro.load_yaml.__globals__['os']", "'.__globals__'"),
    ("math.sin.__self__", "'.__self__'"),
    ("str.join(',', ['a'])", "'.join' of a type"),
    ("x.real", "'.real' of a int"),
    ("'{0.__class__}'.format(1)", "'.format' of a str"),
    ("(lambda: 1)()", "a lambda"),
    ("[c for c in [1]]", "a comprehension"),
    ("{c: 1 for c in [1]}", "a comprehension"),
    ("sum(c for c in [1])", "a generator expression"),
    ("f'{x}'", "an f-string"),
    ("(y := 1)", "an assignment expression"),
    ("max(*[1, 2])", "a * argument"),
    ("dict(**{'a': 1})", "a ** argument"),
    ("__import__('os')", "'__import__'"),
    ("__builtins__", "'__builtins__'"),
    ("{1, 2}", "a set"),
    ("9 ** 9 ** 9", "bits"),
    ("'x' * 10 ** 7", "10000000 items"),
    ("[0] * 10 ** 7", "10000000 items"),
    ("1 << 100", "LShift"),
    ("b'x'", "a bytes literal"),
    ("x()", "calling a int"),
    ("type(1)", "name 'type' is not defined"),
    ("python.vars", "name 'python' is not defined"),
    ("{'__class__': 1}['__class__']", "'__class__'"),
    ("'%s' % ([1],)", "'%' formatting"),
])
def test_anything_else_is_refused(expansion: Expansion, expr: str, words: str) -> None:
    with pytest.raises((Refused, NameError)) as exc:
        _evaluate(expansion, expr, x=2)
    text = exc.value.problem if isinstance(exc.value, Refused) else str(exc.value)
    assert words in text
    if isinstance(exc.value, Refused):
        assert exc.value.where.startswith("${") and expr[:10] in exc.value.where


_numbers = st.one_of(st.integers(-50, 50), st.floats(-1e3, 1e3, allow_nan=False).map(lambda v: round(v, 3)))


@st.composite
def _arith(draw: st.DrawFn, depth: int = 0) -> str:
    if depth > 3 or draw(st.booleans()):
        return repr(draw(_numbers))
    kind = draw(st.sampled_from(["bin", "neg", "call", "if", "cmp"]))
    a, b = draw(_arith(depth + 1)), draw(_arith(depth + 1))
    if kind == "bin":
        return f"({a} {draw(st.sampled_from(['+', '-', '*', '/']))} {b})"
    if kind == "neg":
        return f"-({a})"
    if kind == "call":
        return f"{draw(st.sampled_from(['sin', 'cos', 'atan', 'fabs', 'floor', 'abs']))}({a})"
    if kind == "cmp":
        return f"({a} {draw(st.sampled_from(['<', '<=', '==', '!=', '>']))} {b})"
    return f"({a} if {b} > 0 else {b})"


@settings(max_examples=300, deadline=None)
@given(_arith())
def test_arithmetic_agrees_with_python(expr: str) -> None:
    import xacro

    expansion = Expansion(xacro, [os.getcwd()], 1000, 1000)
    try:
        want = eval(expr, {"__builtins__": {}}, dict(FUNCTIONS))
    except (ZeroDivisionError, OverflowError, ValueError) as exc:
        with pytest.raises(type(exc)):
            expansion.evaluate(expr, dict(expansion.symbols))
        return
    got = expansion.evaluate(expr, dict(expansion.symbols))
    assert got == want or (isinstance(want, float) and math.isnan(want) and math.isnan(got))


def test_the_sandbox_imports_the_standard_library_xacro_and_itself_only() -> None:
    """The child runs as `python -I` and must not import robomax_py (another version may be the one
    installed, and the package imports much): each module of the sandbox imports only the standard
    library, xacro and its siblings (relatively, which `__main__` makes work without robomax_py)."""
    files = sorted(Path(xacro_sandbox.__file__).parent.glob("*.py"))
    assert {f.name for f in files} >= {"__init__.py", "__main__.py", "evaluator.py", "expansion.py", "child.py"}
    for file in files:
        for node in ast.walk(ast.parse(file.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [] if node.level else [str(node.module)]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                assert top in sys.stdlib_module_names or top == "xacro", f"{file.name} imports {name}"

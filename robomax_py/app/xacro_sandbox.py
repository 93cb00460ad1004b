"""xacro expanded as untrusted data: no Python runs from the file, no file outside the allowed
folders is read, and the work is bounded.

xacro evaluates every `${...}` with Python's `eval` (xacro 2.1.1 `safe_eval`: builtins removed and
names starting with `__` refused, which attribute chains and `python.type` / `python.vars` still get
around), reads any file `xacro:include` or `xacro.load_yaml` names, and answers `$(env)` from the
environment. Here the installed xacro does the expansion (macros, blocks, scopes, namespaces, lazy
properties: its semantics, not a re-implementation), with five of its module functions replaced for
the one expansion this process runs:

- `safe_eval` (every `${...}`, and YAML unit tags): `evaluate`, which parses the expression with
  `ast` and evaluates only numbers, strings, booleans, lists, tuples and dicts, names of properties
  and macro parameters, arithmetic, comparison and boolean operators, conditional expressions, `**`
  with a bounded exponent, subscripts, calls of the functions in FUNCTIONS and of `xacro.*` helpers,
  and attribute access on xacro namespaces (`math.pi`, `xacro.load_yaml`, `ns.prop` of an include
  with `ns`) and on YAML data (`settings.arms.port`, xacro's dotted access). Anything else
  (attributes of other values, lambdas, comprehensions, dunder names, f-strings, keyword splats) is
  refused with the file and the expression named.
- `eval_extension` (`$(...)`): `$(find pkg)` answered from the allowed folders only, `$(arg x)`,
  `$(dirname)` (the folder of the file being read) and `$(eval ...)` through `evaluate`; `$(env)`,
  `$(optenv)` and `$(cwd)` are refused (a robot must not depend on the importing machine).
- `parse` (the source and every include) and `get_include_files` (glob patterns): only regular files
  whose real path lies inside an allowed folder, within the size limit.
- `load_yaml`: likewise, within the YAML size limit.
- the global symbol table: only FUNCTIONS, `True`/`False` and the `math` and `xacro` namespaces.

The expansion runs in its own process (`import_urdf.expand` starts this file as a script with
`python -I`), which first caps its own address space (RLIMIT_AS), CPU time (RLIMIT_CPU), file
writes (RLIMIT_FSIZE 0) and child processes (RLIMIT_NPROC 0), and dies with its parent: a macro that
expands 2^24 times or a string of a gigabyte ends that process, not the import. The request comes as
JSON on stdin, the answer goes as JSON to stdout: {"urdf": text} or {"file", "where", "problem",
"kind"}. This module imports nothing from robomax_py (the child must not import the package).
"""

from __future__ import annotations

import ast
import glob
import io
import json
import math
import operator
import os
import re
import stat
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, NoReturn

# Results larger than this many characters (strings) or items (lists, tuples) are refused before
# they are made: a URDF attribute never needs more, and `'x' * 10**9` would otherwise only end at
# the memory limit.
MAX_SEQUENCE = 1_000_000
# `**` with an integer result of more bits than this is refused (`9**9**9` would take minutes);
# float powers overflow to an error on their own.
MAX_POWER_BITS = 4096
# Longest expression text evaluated (the longest in the ROS-Industrial support packages is < 100).
MAX_EXPRESSION_CHARS = 10_000
# Warnings xacro prints (kept to report on failure), characters.
MAX_LOG_CHARS = 20_000

_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
_GLOB_CHARS = re.compile(r"[*?\[]")

# The functions a `${...}` may call, by the names xacro files use (xacro exposes math's names at
# the top level and in `math.`; the builtins are those it has exposed for years, minus `map`,
# `type`, `vars` and the like). Pure functions of numbers and strings only.
_MATH = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "sqrt", "exp", "log",
         "log10", "log2", "pow", "hypot", "radians", "degrees", "floor", "ceil", "trunc", "fabs", "fmod",
         "copysign", "isfinite", "isinf", "isnan")
_MATH_CONSTANTS = ("pi", "e", "tau", "inf", "nan")
_BUILTINS: dict[str, Callable[..., Any]] = {
    "abs": abs, "min": min, "max": max, "int": int, "float": float, "str": str, "bool": bool, "len": len,
    "round": round, "sum": sum, "sorted": sorted, "list": list, "tuple": tuple, "dict": dict,
}
FUNCTIONS: dict[str, Any] = {
    **{name: getattr(math, name) for name in _MATH + _MATH_CONSTANTS},
    **_BUILTINS,
}


class Refused(Exception):
    """Something a robot package may not do: `file` the xacro file, `where` the expression or
    element, `problem` what it tried."""

    def __init__(self, file: str | None, where: str, problem: str) -> None:
        super().__init__(problem)
        self.file = file
        self.where = where
        self.problem = problem


def shown(text: str, limit: int = 160) -> str:
    """An expression or path fit for a one-line message."""
    out = "".join(ch if ch.isprintable() else ascii(ch)[1:-1] for ch in text)
    return out if len(out) <= limit else out[: limit - 5] + " ... "


# ------------------------------------------------------------------------------ the evaluator

_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow,
}
_COMPARE: dict[type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
    ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_, ast.IsNot: operator.is_not,
}
_NOT_ALLOWED: dict[type[ast.AST], str] = {
    ast.Lambda: "a lambda", ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension", ast.GeneratorExp: "a generator expression", ast.JoinedStr: "an f-string",
    ast.NamedExpr: "an assignment expression", ast.Starred: "a * argument", ast.Await: "await",
    ast.Yield: "yield", ast.YieldFrom: "yield", ast.Set: "a set",
}
_PLAIN = (int, float, str, bool, type(None))


class Evaluator:
    """Evaluates xacro expressions without Python's `eval`; see the module docstring.

    `namespaces` are the types whose instances allow `.name` (xacro's NameSpace and its YAML dict
    wrapper), looked up as `value[name]`; `callables` the function objects a call may invoke.
    `locate` gives the file being expanded and the macro context, for a refusal.
    """

    def __init__(self, namespaces: tuple[type, ...], callables: Sequence[Any],
                 locate: Callable[[], tuple[str | None, str]]) -> None:
        self.namespaces = namespaces
        self.callables = {id(f): f for f in callables}
        self.locate = locate

    def __call__(self, expr: str, symbols: Mapping[str, Any]) -> Any:
        text = expr.strip()
        if len(text) > MAX_EXPRESSION_CHARS:
            self._refuse(text, f"the expression has {len(text)} characters (at most {MAX_EXPRESSION_CHARS})")
        try:
            tree = ast.parse(text, mode="eval")
        except SyntaxError as exc:
            raise SyntaxError(f"invalid expression: {exc.msg}") from None
        except (RecursionError, MemoryError):
            self._refuse(text, "the expression nests too deeply")
        return _Run(self, text, symbols).eval(tree.body)

    def _refuse(self, text: str, problem: str) -> NoReturn:
        file, context = self.locate()
        raise Refused(file, f"${{{shown(text)}}}{context}", problem)

    def allowed(self, value: Any) -> bool:
        return isinstance(value, (*_PLAIN, list, tuple, dict)) or id(value) in self.callables


class _Run:
    """One evaluation: the expression text (for messages) and the symbol table."""

    def __init__(self, ev: Evaluator, text: str, symbols: Mapping[str, Any]) -> None:
        self.ev = ev
        self.text = text
        self.symbols = symbols

    def refuse(self, problem: str) -> NoReturn:
        self.ev._refuse(self.text, problem)

    def checked(self, value: Any, what: str) -> Any:
        if not self.ev.allowed(value):
            self.refuse(f"{what} is a {type(value).__name__}, which an expression may not use")
        return value

    def eval(self, node: ast.AST) -> Any:
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            kind = _NOT_ALLOWED.get(type(node), f"'{type(node).__name__}'")
            self.refuse(f"{kind} is not allowed in an expression")
        return method(node)

    # -- leaves
    def _Constant(self, node: ast.Constant) -> Any:
        if not isinstance(node.value, _PLAIN):
            self.refuse(f"a {type(node.value).__name__} literal is not allowed")
        return node.value

    def _Name(self, node: ast.Name) -> Any:
        if node.id.startswith("__"):
            self.refuse(f"the name '{node.id}' is not allowed (names starting with '__')")
        try:
            value = self.symbols[node.id]
        except KeyError:
            raise NameError(f"name '{node.id}' is not defined") from None
        return self.checked(value, f"'{node.id}'")

    # -- containers
    def _List(self, node: ast.List) -> Any:
        return [self.eval(e) for e in node.elts]

    def _Tuple(self, node: ast.Tuple) -> Any:
        return tuple(self.eval(e) for e in node.elts)

    def _Dict(self, node: ast.Dict) -> Any:
        if any(k is None for k in node.keys):
            self.refuse("a ** in a dict literal is not allowed")
        return {self.eval(k): self.eval(v) for k, v in zip(node.keys, node.values) if k is not None}

    # -- operators
    def _BinOp(self, node: ast.BinOp) -> Any:
        op = _BINARY.get(type(node.op))
        if op is None:
            self.refuse(f"the operator {type(node.op).__name__} is not allowed")
        a, b = self.eval(node.left), self.eval(node.right)
        if isinstance(node.op, ast.Pow):
            self._bounded_power(a, b)
        if isinstance(node.op, ast.Mult):
            self._bounded_repeat(a, b)
        formatted = b if isinstance(b, tuple) else (b,)
        if isinstance(node.op, ast.Mod) and isinstance(a, str) and not all(isinstance(x, _PLAIN) for x in formatted):
            self.refuse("'%' formatting takes numbers and strings only")
        result = op(a, b)
        self._bounded_size(result)
        return result

    def _bounded_power(self, a: Any, b: Any) -> None:
        if isinstance(a, int) and isinstance(b, int) and b > 0:
            bits = max(abs(a).bit_length() - 1, 1) * b
            if abs(a) > 1 and bits > MAX_POWER_BITS:
                self.refuse(f"the power has about {bits} bits (at most {MAX_POWER_BITS})")

    def _bounded_repeat(self, a: Any, b: Any) -> None:
        for seq, n in ((a, b), (b, a)):
            if isinstance(seq, (str, list, tuple)) and isinstance(n, int) and len(seq) * n > MAX_SEQUENCE:
                self.refuse(f"the repetition makes {len(seq) * n} items (at most {MAX_SEQUENCE})")

    def _bounded_size(self, value: Any) -> None:
        if isinstance(value, (str, list, tuple)) and len(value) > MAX_SEQUENCE:
            self.refuse(f"the result has {len(value)} items (at most {MAX_SEQUENCE})")

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        value = self.eval(node.operand)
        if isinstance(node.op, ast.Not):
            return not value
        if not isinstance(value, (int, float)):
            self.refuse(f"unary {type(node.op).__name__} of a {type(value).__name__}")
        if isinstance(node.op, ast.USub):
            return -value
        if isinstance(node.op, ast.UAdd):
            return +value
        if isinstance(node.op, ast.Invert) and isinstance(value, int):
            return ~value
        self.refuse(f"the operator {type(node.op).__name__} is not allowed")

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        value: Any = None
        for operand in node.values:
            value = self.eval(operand)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value

    def _Compare(self, node: ast.Compare) -> Any:
        left = self.eval(node.left)
        for op, right_node in zip(node.ops, node.comparators):
            right = self.eval(right_node)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)

    # -- access and calls
    def _Attribute(self, node: ast.Attribute) -> Any:
        if node.attr.startswith("_"):
            self.refuse(f"the attribute '.{node.attr}' is not allowed (names starting with '_')")
        value: Any = self.eval(node.value)
        if not isinstance(value, self.ev.namespaces):
            self.refuse(f"the attribute '.{node.attr}' of a {type(value).__name__} is not allowed (only namespaces "
                        "such as math. and xacro. and data from xacro.load_yaml have attributes here)")
        try:
            found = _item(value, node.attr)
        except (KeyError, AttributeError):
            raise NameError(f"name '{node.attr}' is not defined") from None
        return self.checked(found, f"'.{node.attr}'")

    def _Subscript(self, node: ast.Subscript) -> Any:
        value: Any = self.eval(node.value)
        if not isinstance(value, (str, list, tuple, dict)):
            self.refuse(f"a subscript of a {type(value).__name__} is not allowed")
        if isinstance(node.slice, ast.Slice):
            parts = [None if p is None else self.eval(p) for p in (node.slice.lower, node.slice.upper, node.slice.step)]
            if not all(p is None or isinstance(p, int) for p in parts):
                self.refuse("slice bounds must be integers")
            return value[slice(*parts)]
        index: Any = self.eval(node.slice)
        if not isinstance(index, (int, str, float, bool, tuple)):
            self.refuse(f"an index of type {type(index).__name__} is not allowed")
        if isinstance(index, str) and index.startswith("__"):
            self.refuse(f"the key '{index}' is not allowed (names starting with '__')")
        try:
            found = _item(value, index)
        except AttributeError as exc:       # xacro's YAML wrapper raises AttributeError for a missing key
            raise KeyError(str(exc)) from None
        return self.checked(found, "the item")

    def _Call(self, node: ast.Call) -> Any:
        func = self.eval(node.func)
        if not callable(func) or id(func) not in self.ev.callables:
            self.refuse(f"calling a {type(func).__name__} is not allowed")
        args = [self.eval(a) for a in node.args]
        kwargs = {}
        for kw in node.keywords:
            if kw.arg is None:
                self.refuse("a ** argument is not allowed")
            kwargs[str(kw.arg)] = self.eval(kw.value)
        try:
            result = func(*args, **kwargs)
        except Refused as exc:       # xacro.load_yaml of a file it may not read: name the expression
            self.refuse(exc.problem)
        self._bounded_size(result)
        return self.checked(result, f"the result of {getattr(func, '__name__', 'the call')}()")


def _item(container: Any, key: Any) -> Any:
    """container[key] (a checked container and key; mypy sees the narrowed types otherwise)."""
    return container[key]


# ------------------------------------------------------------------------------ the expansion


class Expansion:
    """One xacro expansion with the replaced functions installed (see the module docstring).

    roots : real paths of the folders files may be read from.
    """

    def __init__(self, xacro: Any, roots: Sequence[str], max_file_bytes: int, max_yaml_bytes: int) -> None:
        self.x = xacro
        self.roots = [os.path.realpath(r) for r in roots]
        self.max_file_bytes = max_file_bytes
        self.max_yaml_bytes = max_yaml_bytes
        self.written: dict[str, str] = {}       # an include's file name as the file wrote it, by its path
        self.original_parse = xacro.parse
        self.original_load_yaml = xacro.load_yaml
        # Bound methods are made once here: a call is allowed by the identity of the function object.
        self.arg_fn, self.dirname_fn, self.find_fn = self.arg, self.dirname, self.find
        helpers = {
            "load_yaml": self.load_yaml, "tokenize": xacro.tokenize, "dotify": xacro.YamlDictWrapper,
            "abs_filename": xacro.abs_filename_spec, "arg": self.arg_fn, "fatal": self.fatal,
            "message": self.message, "warning": self.warning, "error": self.error,
        }
        self.symbols: dict[str, Any] = {**FUNCTIONS, "True": True, "False": False}
        ns_math = xacro.NameSpace()
        ns_math.update({name: getattr(math, name) for name in _MATH + _MATH_CONSTANTS})
        ns_xacro = xacro.NameSpace()
        ns_xacro.update(helpers)
        self.symbols.update(math=ns_math, xacro=ns_xacro)
        self.extension_functions: dict[str, Any] = {
            **FUNCTIONS, "true": True, "false": False, "True": True, "False": False,
            "arg": self.arg_fn, "dirname": self.dirname_fn, "find": self.find_fn,
        }
        callables = [*FUNCTIONS.values(), *helpers.values(), self.dirname_fn, self.find_fn]
        self.evaluate = Evaluator((xacro.NameSpace, xacro.YamlDictWrapper), callables,
                                  lambda: (self.current_file(), self.where_context()))

    # -- where we are, for messages
    def current_file(self) -> str | None:
        stack = self.x.filestack or []
        return next((f for f in reversed(stack) if f), None)

    def where_context(self) -> str:
        macros = self.x.macrostack or []
        if not macros:
            return ""
        m = macros[-1]
        defined = m.history[-1][-1] if m.history and m.history[-1] else None
        name = m.body.getAttribute("name") if m.body is not None else "?"
        return f" (in macro '{name}'" + (f" defined in {defined})" if defined and defined != self.current_file() else ")")

    def refuse(self, where: str, problem: str) -> NoReturn:
        raise Refused(self.current_file(), where + self.where_context(), problem)

    # -- files
    def inside(self, path: str) -> bool:
        real = os.path.realpath(path)
        return any(real == r or real.startswith(r.rstrip(os.sep) + os.sep) for r in self.roots)

    def readable(self, path: str, limit: int, where: str) -> str:
        """The real path of a file the expansion may read, or Refused."""
        if "\x00" in path:
            self.refuse(where, "the path contains a NUL byte")
        if not self.inside(path):
            self.refuse(where, f"{shown(os.path.realpath(path))} is outside the package folders given "
                        "(--packages) and the source's folder")
        real = os.path.realpath(path)
        try:
            st = os.stat(real)
        except OSError as exc:
            raise self.x.XacroException(f"{exc.strerror}: {shown(path)}", exc=exc) from None
        if not stat.S_ISREG(st.st_mode):
            self.refuse(where, f"{shown(real)} is not a regular file")
        if st.st_size > limit:
            self.refuse(where, f"{shown(real)}: {st.st_size / 2**20:.1f} MB is more than the {limit / 2**20:.0f} MB allowed")
        return real

    def parse(self, inp: Any, filename: str | None = None) -> Any:
        """xacro.parse for the source and each include: the file checked, then read."""
        if inp is not None or filename is None:
            return self.original_parse(inp, filename)
        path = os.path.join(self.x.root_dir, filename)
        stack = self.x.filestack or []
        # process_include has pushed the included file already: the file naming it is the one before.
        including = stack[-2] if len(stack) >= 2 else None
        try:
            real = self.readable(path, self.max_file_bytes, f"include {shown(self.written.get(filename, filename))}")
        except Refused as exc:
            raise Refused(including or exc.file, exc.where, exc.problem) from None
        except self.x.XacroException:
            stack.pop()      # as xacro's own parse does, so an optional include is skipped cleanly
            raise
        with open(real, "rb") as f:
            data = f.read(self.max_file_bytes + 1)
        return self.original_parse(data.decode("utf-8"))

    def include_files(self, filename_spec: str, symbols: Any) -> Iterator[str]:
        """xacro.get_include_files: a glob is only expanded inside the allowed folders."""
        written = str(self.x.eval_text(filename_spec, symbols))
        spec = self.x.abs_filename_spec(written)
        self.written[spec] = written
        if _GLOB_CHARS.search(spec):
            fixed = os.path.dirname(spec[: _GLOB_CHARS.search(spec).start()])  # type: ignore[union-attr]
            if not self.inside(fixed):
                self.refuse(f"include {shown(spec)}", f"{shown(os.path.realpath(fixed))} is outside the package "
                            "folders given (--packages) and the source's folder")
            names = sorted(glob.glob(spec))
            if not names:
                self.x.warning(self.x.include_no_matches_msg.format(spec))
        else:
            names = [spec]
        for name in names:
            self.x.all_includes.append(name)
            yield name

    def load_yaml(self, filename: Any) -> Any:
        if not isinstance(filename, str):
            self.refuse("xacro.load_yaml", f"expects a file name, got a {type(filename).__name__}")
        path = self.x.abs_filename_spec(filename)
        real = self.readable(path, self.max_yaml_bytes, f"xacro.load_yaml({shown(filename)!r})")
        return self.original_load_yaml(real)

    # -- $(...)
    def extension(self, text: str) -> Any:
        inner = text[2:-1].strip() if text.startswith("$(") and text.endswith(")") else text
        if inner.startswith("eval ") or inner == "eval":
            args = self.x.substitution_args_context.get("arg", {})
            names = _ChainMap(self.extension_functions, args, self.x.substitution_args.convert_value)
            return str(self.evaluate(inner[5:], names))
        words = inner.split()
        command, args = (words[0], words[1:]) if words else ("", [])
        if command == "find" and len(args) == 1:
            return self.find(args[0])
        if command == "arg" and len(args) == 1:
            return self.arg(args[0])
        if command == "dirname" and not args:
            return self.dirname()
        if command in ("env", "optenv", "cwd"):
            self.refuse(f"$({shown(inner)})", "reads the importing machine's environment; a robot package may not "
                        "depend on it")
        raise self.x.XacroException(f"unknown or malformed substitution $({shown(inner)}) "
                                    "(find PKG, arg NAME, dirname and eval EXPR are supported)")

    def find(self, name: Any) -> str:
        """$(find pkg): the package folder, inside the allowed folders only."""
        if not isinstance(name, str) or not _PACKAGE_NAME.fullmatch(name) or name in (".", ".."):
            self.refuse(f"$(find {shown(str(name))})", "not a package name")
        found = [c for root in self.roots for c in _package_candidates(root, name)
                 if os.path.isdir(c) and self.inside(c)]
        # A ROS package holds package.xml; a folder of the same name inside it (a Python module) does not.
        best = next((c for c in found if os.path.isfile(os.path.join(c, "package.xml"))), found[0] if found else None)
        if best is not None:
            return os.path.realpath(best)
        raise self.x.XacroException(f"$(find {name}): no package '{name}' in the package folders given "
                                    f"(--packages) or the source's folder ({', '.join(self.roots)})")

    def arg(self, name: Any) -> Any:
        args = self.x.substitution_args_context.get("arg", {})
        if name not in args:
            raise self.x.XacroException(f"undefined substitution argument {shown(str(name))}")
        return args[name]

    def dirname(self) -> str:
        current = self.current_file()
        if current is None:
            raise self.x.XacroException("$(dirname): no file")
        return os.path.dirname(os.path.realpath(current))

    # -- xacro's message helpers (no print_location, no file= argument)
    def fatal(self, *args: Any) -> None:
        raise self.x.XacroException(" ".join(map(str, args)))

    def message(self, *args: Any) -> str:
        print(*args, file=sys.stderr)
        return ""

    def warning(self, *args: Any) -> str:
        return self.message("warning:", *args)

    def error(self, *args: Any) -> str:
        return self.message("error:", *args)

    # -- the expansion itself
    def run(self, source: str) -> str:
        x = self.x
        saved = {name: getattr(x, name) for name in ("safe_eval", "eval_extension", "parse", "get_include_files",
                                                     "load_yaml", "_global_symbols")}
        x.safe_eval = lambda expr, symbols, _locals=None: self.evaluate(expr, symbols)
        x.eval_extension = self.extension
        x.parse = self.parse
        x.get_include_files = self.include_files
        x.load_yaml = self.load_yaml
        x._global_symbols = self.symbols
        try:
            doc = x.process_file(source)
            return str(doc.toprettyxml(indent="  "))
        finally:
            for name, value in saved.items():
                setattr(x, name, value)


class _ChainMap(Mapping[str, Any]):
    """$(eval)'s names: the functions, then the xacro arguments (converted as xacro does)."""

    def __init__(self, functions: Mapping[str, Any], args: Mapping[str, Any], convert: Any) -> None:
        self.functions, self.args, self.convert = functions, args, convert

    def __getitem__(self, key: str) -> Any:
        if key in self.functions:
            return self.functions[key]
        return self.convert(self.args[key], "auto")

    def __iter__(self) -> Iterator[str]:
        return iter([*self.functions, *self.args])

    def __len__(self) -> int:
        return len(self.functions) + len(self.args)


def _package_candidates(root: str, name: str) -> Iterator[str]:
    """Where package `name` may be below an allowed folder: the folder itself, a child, or up to
    three levels down (a workspace `src/` holding repositories holding packages)."""
    if os.path.basename(root.rstrip(os.sep)) == name:
        yield root
    yield os.path.join(root, name)
    level = [root]
    for _ in range(3):
        nxt = []
        for d in level:
            try:
                entries = sorted(e for e in os.listdir(d) if not e.startswith("."))
            except OSError:
                continue
            for e in entries:
                p = os.path.join(d, e)
                if os.path.isdir(p) and not os.path.islink(p):
                    if e == name:
                        yield p
                    nxt.append(p)
        level = nxt[:10_000]


# ------------------------------------------------------------------------------ the child process


def _limit(cpu_s: float, memory_bytes: int, parent: int) -> None:
    """Cap this process before it reads anything: CPU seconds, address space, no files written, no
    processes started, no core dump, and die with the parent (Linux)."""
    import resource

    cpu = max(1, math.ceil(cpu_s))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
    resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    try:
        import ctypes
        import signal

        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:      # the parent died before prctl: nobody waits for the answer
        os._exit(1)


class _Log(io.StringIO):
    """stderr kept in memory, at most MAX_LOG_CHARS (xacro's warnings)."""

    def write(self, s: str) -> int:
        room = MAX_LOG_CHARS - self.tell()
        return super().write(s[:room]) if room > 0 else len(s)


def _cause(exc: BaseException) -> BaseException:
    """What ended the expansion, looking inside xacro's wrapping (XacroException.exc, __cause__,
    __context__): a Refused first, else a MemoryError or RecursionError, else `exc` itself."""
    found: list[BaseException] = []
    todo: list[BaseException | None] = [exc]
    while todo and len(found) < 100:
        e = todo.pop()
        if e is None or any(e is f for f in found):
            continue
        found.append(e)
        todo.extend([getattr(e, "exc", None), e.__cause__, e.__context__])
    for kind in (Refused, MemoryError, RecursionError):
        hit = next((e for e in found if isinstance(e, kind)), None)
        if hit is not None:
            return hit
    return exc


def serve(request: Mapping[str, Any]) -> dict[str, Any]:
    """Expand request["source"]; the answer to print (see the module docstring)."""
    import xacro
    import xacro.substitution_args

    expansion = Expansion(xacro, request["roots"], int(request["max_file_bytes"]), int(request["max_yaml_bytes"]))
    log = _Log()
    sys.stderr = log
    try:
        text = expansion.run(request["source"])
    except Exception as exc:  # noqa: BLE001 - xacro raises XacroException, KeyError, NameError, ExpatError, ...
        cause = _cause(exc)
        where = expansion.current_file()
        if isinstance(cause, Refused):
            return {"kind": "refused", "file": cause.file, "where": cause.where, "problem": cause.problem}
        if isinstance(cause, MemoryError):
            return {"kind": "memory", "file": where, "where": None, "problem": "memory"}
        if isinstance(cause, RecursionError):
            return {"kind": "xacro", "file": where, "where": None,
                    "problem": "macros or properties nest too deeply (a macro that calls itself?)"}
        message = " ".join(str(exc).split()) or type(exc).__name__
        return {"kind": "xacro", "file": where, "where": None,
                "problem": f"xacro does not expand: {type(exc).__name__}: {shown(message, 400)}"}
    finally:
        sys.stderr = sys.__stderr__
    if len(text) > int(request["max_output_chars"]):
        return {"kind": "size", "file": request["source"], "where": None,
                "problem": f"the expanded URDF has {len(text)} characters, more than the "
                           f"{int(request['max_output_chars']) / 2**20:.0f} MB allowed"}
    return {"urdf": text, "log": log.getvalue()}


def main() -> int:
    request = json.loads(sys.stdin.buffer.read(1_000_000))
    _limit(float(request["cpu_s"]), int(request["memory_bytes"]), int(request["parent"]))
    try:
        answer = serve(request)
    except MemoryError:
        answer = {"kind": "memory", "file": None, "where": None, "problem": "memory"}
    sys.stdout.write(json.dumps(answer))
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())

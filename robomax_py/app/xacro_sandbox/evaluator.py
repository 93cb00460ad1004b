"""The `${...}` evaluator: xacro expressions evaluated without Python's `eval` (see the package's
docstring for what an expression may do), each refusal naming the file and the expression; and
the limits that bound the work an expression may ask for. Imports only the standard library and its siblings, relatively (see the package's docstring)."""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping, Sequence
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

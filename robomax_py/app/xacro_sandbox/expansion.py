"""One xacro expansion with xacro's own functions replaced (see the package's docstring):
expressions through the evaluator, `$(...)` answered from the allowed folders and arguments only,
every file read checked, and the xacro arguments a package's launch file passes.
Imports only the standard library and its siblings, relatively (see the package's docstring)."""

from __future__ import annotations

import glob
import math
import os
import re
import stat
import sys
from collections.abc import Iterator, Mapping, Sequence
from typing import Any, NoReturn

from .evaluator import _MATH, _MATH_CONSTANTS, FUNCTIONS, Evaluator, Refused, shown

_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
_GLOB_CHARS = re.compile(r"[*?\[]")
# name:=value on a xacro command line; the value runs to a space outside $(...)
_MAPPING = re.compile(r"([A-Za-z_][A-Za-z0-9_]*):=((?:\$\([^()]*\)|[^\s\"'$])+)")


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
        # xacro before 1.14 offered `load_yaml` at the top level only (motoman_es_support's
        # es165_macro.xacro `${load_yaml(joint_velocities_file)}`); xacro still accepts it there.
        self.symbols["load_yaml"] = helpers["load_yaml"]
        self.launch_hints: list[str] = []       # launch-file values for arguments left unset
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
        if not filename.strip():
            self.refuse("xacro.load_yaml('')", "names no file" + self.unset_arguments())
        path = self.x.abs_filename_spec(filename)
        if os.path.isdir(path):
            self.refuse(f"xacro.load_yaml({shown(filename)!r})", "names a folder, not a file" + self.unset_arguments())
        real = self.readable(path, self.max_yaml_bytes, f"xacro.load_yaml({shown(filename)!r})")
        return self.original_load_yaml(real)

    def unset_arguments(self) -> str:
        """The xacro arguments left empty, for a message: a file name built from one names nothing."""
        args = self.x.substitution_args_context.get("arg", {})
        empty = sorted(name for name, value in args.items() if str(value).strip() == "")
        if not empty:
            return ""
        names = ", ".join(empty)
        return (f": the xacro argument {names} is empty (its default); give it with --xacro-arg {empty[0]}:=VALUE"
                + "".join(f"; {hint}" for hint in self.launch_hints))

    # -- the package's launch file
    def launch_defaults(self, source: str, given: Mapping[str, str]) -> tuple[dict[str, str], list[str]]:
        """The xacro arguments the package's `launch/load_<robot>.launch` passes on the xacro command
        line for `source` (ROS-Industrial's convention, motoman_es_support/launch/load_es165.launch
        `joint_velocities_file:=$(find motoman_es_support)/config/joint_velocities_$(arg controller).yaml`),
        but those in `given`; a value is used when its `$(find pkg)` and `$(arg name)` resolve (from
        `given`, else the launch file's own `<arg default|value>`), else it becomes a hint for the
        message should the expansion fail. Returns the values and one note per value used."""
        real = os.path.realpath(source)
        stem = os.path.splitext(os.path.basename(real))[0]
        launch = os.path.join(os.path.dirname(os.path.dirname(real)), "launch", f"load_{stem}.launch")
        if not os.path.isfile(launch) or not self.inside(launch):
            return {}, []
        try:
            import xml.dom.minidom
            import xml.parsers.expat

            with open(self.readable(launch, self.max_file_bytes, "launch file"), "rb") as f:
                dom = xml.dom.minidom.parseString(f.read(self.max_file_bytes + 1))
        except (Refused, OSError, ValueError, self.x.XacroException, xml.parsers.expat.ExpatError):
            return {}, []
        launch_args = {}
        for el in dom.getElementsByTagName("arg"):
            for attr in ("value", "default"):
                if el.hasAttribute(attr):
                    launch_args[el.getAttribute("name")] = el.getAttribute(attr)
                    break
        found: dict[str, str] = {}
        notes: list[str] = []
        for el in dom.getElementsByTagName("*"):
            command = el.getAttribute("command")
            if os.path.basename(real) not in command:
                continue
            for name, raw in _MAPPING.findall(command.split(os.path.basename(real), 1)[1]):
                if name in given or name in found:
                    continue
                value, missing = self.launch_value(raw, {**launch_args, **given})
                if missing is None:
                    found[name] = value
                    notes.append(f"xacro argument {name}:={value} from {launch}")
                else:
                    self.launch_hints.append(f"{launch} passes {name}:={raw} ({missing})")
        return found, notes

    def launch_value(self, raw: str, args: Mapping[str, str]) -> tuple[str, str | None]:
        """A launch file's argument value with `$(find pkg)` and `$(arg name)` resolved, and None;
        or what is missing."""
        missing: list[str] = []

        def one(m: re.Match[str]) -> str:
            words = m.group(1).split()
            if len(words) == 2 and words[0] == "arg":
                if words[1] in args:
                    return str(args[words[1]])
                missing.append(f"the launch argument {words[1]} has no default: --xacro-arg {words[1]}:=VALUE sets it")
            elif len(words) == 2 and words[0] == "find":
                try:
                    return self.find(words[1])
                except (Refused, self.x.XacroException):
                    missing.append(f"no package {words[1]}")
            else:
                missing.append(f"$({shown(m.group(1))}) is not resolved here")
            return ""

        value = re.sub(r"\$\(([^()]*)\)", one, raw)
        return value, "; ".join(missing) if missing else None

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
    def run(self, source: str, args: Mapping[str, str] | None = None) -> str:
        """The expanded URDF of `source`, xacro arguments `args` (name -> value) set as on xacro's
        command line."""
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
            doc = x.process_file(source, mappings=dict(args or {}))
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

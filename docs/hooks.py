"""mkdocs hooks: pages whose content comes from the code, made at every build so they cannot go stale.

A page asks for generated content with a marker line:

    <!-- generated: cli -->          every command of `robomax`, from the typer app
    <!-- generated: keys cell -->    the key tables of a cell file (also robot, tool), from the models
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

import gen_schema

MARKER = re.compile(r"^<!-- generated: (\w+)(?: (\w+))? -->$", re.MULTILINE)


# typer builds click commands (its own copy of click in newer releases), so the objects are read by
# their attributes, not their classes.


def _is_argument(param: Any) -> bool:
    return bool(param.param_type_name == "argument")


def _option_names(param: Any) -> str:
    if _is_argument(param):
        return f"`{param.metavar or param.name.upper()}`"
    names = list(param.opts)
    if getattr(param, "is_flag", False) and param.secondary_opts:
        names = [f"{a} / {b}" for a, b in zip(param.opts, param.secondary_opts)]
    return ", ".join(f"`{n}`" for n in names)


def _usage(arg: Any) -> str:
    word = arg.metavar or arg.name.upper()
    word = word + "..." if arg.nargs == -1 else word
    return word if arg.required else f"[{word}]"


def _cell(text: str) -> str:
    # Brackets escaped: help text such as "[rpy=R,P,Y] [from=T1]" would read as a reference link.
    text = " ".join(text.split()).replace("|", "\\|").replace("[", "\\[").replace("]", "\\]")
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _value_kind(param: Any) -> str:
    if param.metavar:
        return "`" + str(param.metavar).replace("|", "\\|") + "`"
    annotation: Any = getattr(getattr(param, "type_descriptor", None), "annotation", None)
    while getattr(annotation, "__args__", None) and getattr(annotation, "__origin__", None) in (list, tuple):
        annotation = annotation.__args__[0]
    text = getattr(annotation, "__name__", None) or str(annotation or "text")
    return {"str": "text", "int": "integer", "float": "number", "Path": "path"}.get(text, text.replace("pathlib.", ""))


def _param_row(param: Any) -> str:
    kind = "flag" if getattr(param, "is_flag", False) else _value_kind(param)
    if param.multiple or (_is_argument(param) and param.nargs == -1):
        kind += ", repeatable"
    default = ""
    value = param.default
    if not param.required and value is not None and value is not False and value not in ((), []) and not callable(value):
        default = f"`{value}`"
    required = "required" if param.required else ""
    help_text = getattr(param, "help", None) or ""
    return f"| {_option_names(param)} | {kind} | {required or default} | {_cell(help_text)} |"


def cli_reference() -> str:
    """Markdown for every command of the `robomax` app: usage, help text, arguments and options."""
    import typer.main

    from robomax_py.app.cli import app

    root: Any = typer.main.get_command(app)
    ctx = root.context_class(root, info_name="robomax")
    out = [f"The `robomax` program: {_cell(root.help or '')}", ""]
    shared = [p for p in root.params if p.name != "help" and not getattr(p, "hidden", False)]
    if shared:
        out += ["Options before the command name:", "", "| option | type | default | what it does |", "|---|---|---|---|"]
        out += [_param_row(p) for p in shared]
        out.append("")
    for name in sorted(root.list_commands(ctx)):
        cmd = root.get_command(ctx, name)
        if cmd is None or cmd.hidden:
            continue
        usage = " ".join(["[OPTIONS]"] + [_usage(p) for p in cmd.params if _is_argument(p)])
        out += [f"### robomax {name}", "", "```", f"robomax {name} {usage}".rstrip(), "```", ""]
        if cmd.help:
            out += [cmd.help.strip().replace("\b\n", ""), ""]
        params = [p for p in cmd.params if p.name != "help" and not getattr(p, "hidden", False)]
        if params:
            out += ["| argument or option | type | default | what it does |", "|---|---|---|---|"]
            out += [_param_row(p) for p in params]
            out.append("")
    return "\n".join(out)


def generated(what: str, arg: str | None) -> str:
    if what == "cli":
        return cli_reference()
    if what == "keys" and arg in gen_schema.FILES:
        return gen_schema.key_tables(arg)
    raise ValueError(f"docs/hooks.py: unknown marker 'generated: {what} {arg or ''}'")


def on_page_markdown(markdown: str, **_: Any) -> str:
    return MARKER.sub(lambda m: generated(m.group(1), m.group(2)), markdown)

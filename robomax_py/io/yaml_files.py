"""Reading the YAML files people write, and turning schema errors into one located message.

Shared by `cell_io` and `robot_io`, the only modules that know file keys.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from robomax_py.errors import _LocatedError


class _UniqueKeyLoader(yaml.SafeLoader):
    """safe_load that refuses duplicate mapping keys, which plain YAML silently lets the last one win."""


def _construct_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)  # type: ignore[no-untyped-call]
        if key in seen:
            mark = key_node.start_mark
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r} (line {mark.line + 1})", mark
            )
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def read_yaml_mapping(path: Path, error: type[_LocatedError], what: str) -> dict[str, Any]:
    """The top-level mapping of a YAML file, or `error` naming the file and what is wrong."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(path, None, f"{what} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(path, None, f"cannot read {what}: {exc}") from None
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else None
        raise error(path, where, f"not valid YAML: {exc.problem or exc}") from None
    except yaml.YAMLError as exc:
        raise error(path, None, f"not valid YAML: {exc}") from None
    if not isinstance(data, dict):
        raise error(path, None, f"expected a mapping of keys at the top level, got {_kind(data)}")
    return data


def key_path(loc: tuple[int | str, ...]) -> str:
    """('seams', 0, 'spots', 3, 'normal') -> 'seams[0].spots[3].normal'."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def validation_error(
    exc: ValidationError, schema: type[BaseModel], path: Path, error: type[_LocatedError]
) -> _LocatedError:
    """The first schema violation as one located error, with a 'did you mean' for unknown keys."""
    first = exc.errors(include_url=False)[0]
    # Pydantic appends the union member or validator name ('function-after[...]') to locations; drop it.
    loc = tuple(p for p in first["loc"] if not (isinstance(p, str) and "[" in p))
    kind = first["type"]
    if kind == "extra_forbidden":
        known = _fields_at(schema, loc[:-1])
        hint = difflib.get_close_matches(str(loc[-1]), known, n=1, cutoff=0.6)
        suggestion = f"; did you mean '{hint[0]}'?" if hint else (f"; known keys: {', '.join(known)}" if known else "")
        problem = f"unknown key{suggestion}"
    elif kind == "missing":
        problem = "required key is missing"
    else:
        problem = _clean_message(first["msg"])
        if "input" in first and kind not in ("value_error", "assertion_error"):
            problem += f", got {_show(first['input'])}"
    more = len(exc.errors()) - 1
    if more:
        problem += f" (and {more} more problem{'s' if more > 1 else ''})"
    return error(path, key_path(loc) or None, problem)


def _fields_at(schema: type[BaseModel], loc: tuple[int | str, ...]) -> list[str]:
    """Names of the keys allowed at a location of the schema (for 'did you mean')."""
    model: Any = schema
    for part in loc:
        if isinstance(part, int):
            continue
        field = getattr(model, "model_fields", {}).get(part)
        if field is None:
            return []
        model = _inner_model(field.annotation)
        if model is None:
            return []
    fields = getattr(model, "model_fields", {})
    return [f.alias or name for name, f in fields.items()]


def _inner_model(annotation: Any) -> Any:
    """The BaseModel inside list[...] / Optional[...] annotations, if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        found = _inner_model(arg)
        if found is not None:
            return found
    return None


def _clean_message(msg: str) -> str:
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    return msg[:1].lower() + msg[1:]


def _kind(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."

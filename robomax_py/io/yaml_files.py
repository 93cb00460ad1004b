"""Reading the YAML files people write, bounded (`load_yaml`: aliases that expand beyond a bound or
refer to themselves, nesting beyond a depth, complex or non-string keys, integers longer than any
quantity, duplicate keys are refused), and turning schema errors into one located message.

Where PyYAML has libyaml, its C parser composes the document (ten times faster than PyYAML's
Python composer: 5.6 against 55 ms for the reference cell, which every `check` and `plan` reads),
after the nesting depth has been bounded on its events; the checks on keys, integers and aliases
are the same Python code either way.

Shared by `cell_io` and `robot_io`, the only modules that know file keys.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from robomax_py.errors import _LocatedError
from robomax_py.safe_files import LIMITS, read_text


class _GuardedLoader(yaml.SafeLoader):
    """safe_load with bounds: nesting depth, alias expansion, keys, integer length, duplicate keys."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        try:
            if self._depth > LIMITS.yaml_depth:
                raise _too_deep(self.peek_event().start_mark)  # type: ignore[no-untyped-call]
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_MERGE_TAG = "tag:yaml.org,2002:merge"


def _construct_mapping(loader: _GuardedLoader, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        mark = key_node.start_mark
        if key_node.tag == _MERGE_TAG:
            # `<<: *shared` merges another mapping's keys (YAML's merge key, as `yaml.safe_load`
            # reads it; `construct_mapping` below does the merging and refuses a value that is
            # not a mapping): no text to check, but given once, as any key.
            if _MERGE_TAG in seen:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key '<<' (line {mark.line + 1})", mark)
            seen.add(_MERGE_TAG)
            continue
        if not isinstance(key_node, yaml.ScalarNode):
            raise yaml.constructor.ConstructorError(None, None, "a key must be plain text, not a list or mapping", mark)
        key = loader.construct_object(key_node, deep=deep)
        if not isinstance(key, str):
            raise yaml.constructor.ConstructorError(
                None, None, f"key {key_node.value!r} must be text (it reads as {type(key).__name__}; quote it)", mark)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r} (line {mark.line + 1})", mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


def _construct_int(loader: _GuardedLoader, node: yaml.ScalarNode) -> int:
    digits = sum(ch.isdigit() for ch in str(node.value))
    if digits > LIMITS.int_digits:
        raise yaml.constructor.ConstructorError(
            None, None, f"integer of {digits} digits (at most {LIMITS.int_digits})", node.start_mark)
    return int(loader.construct_yaml_int(node))


_GuardedLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
_GuardedLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)

_WITH_LIBYAML: bool = getattr(yaml, "__with_libyaml__", False)

if _WITH_LIBYAML:
    class _FastGuardedLoader(yaml.CSafeLoader):
        """`_GuardedLoader`'s constructors on libyaml's parser and composer. libyaml composes
        recursively in C, so the depth is bounded on the events first (`_check_depth`): a deeply
        nested hostile file must not reach it."""

    _FastGuardedLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
    _FastGuardedLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)


def _check_depth(text: str) -> None:
    """ConstructorError at the first node nested deeper than `LIMITS.yaml_depth`, as
    `_GuardedLoader.compose_node` counts nodes, found on libyaml's events (about 1 µs each)."""
    depth = 0
    for event in yaml.parse(text, Loader=yaml.CSafeLoader):
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > LIMITS.yaml_depth:
                raise _too_deep(event.start_mark)
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1
        elif depth == LIMITS.yaml_depth and isinstance(event, (yaml.ScalarEvent, yaml.AliasEvent)):
            # A scalar at the deepest level is one node deeper than its collection, as
            # `compose_node` counts it.
            raise _too_deep(event.start_mark)


def _too_deep(mark: Any) -> yaml.constructor.ConstructorError:
    """The nesting error at a node's mark (PyYAML's, or libyaml's own Mark type, read alike)."""
    return yaml.constructor.ConstructorError(None, None, f"nested more than {LIMITS.yaml_depth} levels deep", mark)


def _loader(text: str) -> yaml.SafeLoader | yaml.CSafeLoader:
    """The guarded loader for `text`: libyaml's, once the text's characters and depth are checked,
    or PyYAML's Python one where PyYAML has no libyaml."""
    if not _WITH_LIBYAML:
        return _GuardedLoader(text)
    yaml.reader.Reader(text)       # PyYAML's check of the characters: it counts the offset in characters, libyaml in bytes
    _check_depth(text)
    return _FastGuardedLoader(text)


def _expanded_size(root: yaml.Node) -> int:
    """Nodes the document has once every alias is expanded (shared nodes counted each time they
    are used), computed without expanding; ConstructorError for an alias that contains itself."""
    size: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        nid = id(node)
        if done:
            on_path.discard(nid)
            children = _children(node)
            total = 1 + sum(size[id(c)] for c in children)
            size[nid] = min(total, LIMITS.yaml_nodes + 1)
            continue
        if nid in size:
            continue
        if nid in on_path:
            raise yaml.constructor.ConstructorError(None, None, "an alias refers to the node that contains it", node.start_mark)
        on_path.add(nid)
        stack.append((node, True))
        for c in _children(node):
            if id(c) in on_path:
                raise yaml.constructor.ConstructorError(
                    None, None, "an alias refers to the node that contains it (recursive alias)", c.start_mark)
            if id(c) not in size:
                stack.append((c, False))
    return size[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    return []


def load_yaml(text: str, path: Path, error: type[_LocatedError], what: str) -> Any:
    """The document of YAML text under the bounds of `_GuardedLoader` and `FileLimits.yaml_nodes`."""
    try:
        loader = _loader(text)             # the reader refuses control characters here already
        try:
            root = loader.get_single_node()
            if root is None:
                return None
            nodes = _expanded_size(root)
            if nodes > LIMITS.yaml_nodes:
                raise error(path, None, f"{what}: aliases expand to more than {LIMITS.yaml_nodes:,} values")
            return loader.construct_document(root)
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else None
        raise error(path, where, f"not valid YAML: {exc.problem or exc.context or exc}") from None
    except yaml.reader.ReaderError as exc:
        char = f"0x{exc.character:02x}" if isinstance(exc.character, int) else repr(exc.character)
        raise error(path, f"offset {exc.position}", f"not valid YAML: character {char} is not allowed in YAML text") from None
    except yaml.YAMLError as exc:
        raise error(path, None, "not valid YAML: " + " ".join(str(exc).split())) from None
    except RecursionError:
        raise error(path, None, f"{what}: nested too deeply") from None


@dataclass(slots=True)
class _Open:
    """A mapping or sequence being read (`count_items`): its key path (None inside a complex key)
    and, for a mapping, whether its next node is a key and the key of the value being read."""

    is_map: bool
    path: tuple[str, ...] | None
    want_key: bool = True
    key: str | None = None


def count_items(text: str, targets: tuple[tuple[str, ...], ...]) -> dict[tuple[str, ...], int] | None:
    """The items of the sequences at `targets` (key paths; "*" stands for any item of a sequence,
    e.g. ("seams", "*", "spots")), counted from libyaml's parser events without building the
    document: a bound checked before the guarded reader builds a long list (a cell of 10,002 spots,
    1.4 MB: 0.26 s of events, 6.4 s composed in Python; constructing it is Python either way). Aliases
    count as one item each; a list reached only through an alias is not counted (the reader's own
    checks see it). None when PyYAML has no libyaml or the text is not valid YAML (the reader
    then says why)."""
    if not getattr(yaml, "__with_libyaml__", False):
        return None
    counts = dict.fromkeys(targets, 0)
    stack: list[_Open] = []
    try:
        for event in yaml.parse(text, Loader=yaml.CSafeLoader):
            if isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                stack.pop()
                continue
            if not isinstance(event, (yaml.NodeEvent, yaml.CollectionStartEvent)):
                continue                                  # stream and document events
            parent = stack[-1] if stack else None
            path: tuple[str, ...] | None = ()
            if parent is not None and parent.is_map and parent.want_key:
                parent.want_key = False
                parent.key = event.value if isinstance(event, yaml.ScalarEvent) else None
                path = None                               # inside a complex key: nothing counted
                if not isinstance(event, yaml.CollectionStartEvent):
                    continue
            elif parent is not None and parent.is_map:
                parent.want_key = True
                path = None if parent.path is None or parent.key is None else (*parent.path, parent.key)
            elif parent is not None:
                path = None if parent.path is None else (*parent.path, "*")
                if parent.path in counts:
                    counts[parent.path] += 1
            if isinstance(event, yaml.CollectionStartEvent):
                stack.append(_Open(isinstance(event, yaml.MappingStartEvent), path))
    except yaml.YAMLError:
        return None
    return counts


def read_yaml_mapping(path: Path, error: type[_LocatedError], what: str, limit: int) -> dict[str, Any]:
    """The top-level mapping of a YAML file read through the guard (`safe_files.read_text`, at most
    `limit` bytes, then `load_yaml`), or `error` naming the file and what is wrong."""
    data = load_yaml(read_text(path, limit, error, what), path, error, what)
    if not isinstance(data, dict):
        raise error(path, None, f"expected a mapping of keys at the top level, got {_kind(data)}")
    return data


def key_path(loc: tuple[int | str, ...]) -> str:
    """('seams', 0, 'spots', 3, 'normal') -> 'seams[0].spots[3].normal'."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


# At most this many independent problems of one file are listed in one error: enough to fix a file
# in one pass, few enough to read (a list of 2,000 spots all wrong the same way is one mistake).
MAX_LISTED_PROBLEMS = 20


def validation_error(
    exc: ValidationError, schema: type[BaseModel], path: Path, error: type[_LocatedError]
) -> _LocatedError:
    """The schema violations as one located error, with a 'did you mean' for unknown keys: the
    error itself when there is one, else every one (up to MAX_LISTED_PROBLEMS) on its own line. A
    value that fits no member of a union is reported at its own key, by the member its kind fits
    (a mapping by a mapping member, so a misspelt key inside it is named; a list by a list member)."""
    entries = []
    for err in exc.errors(include_url=False):
        # Pydantic names a validator wrapping a value ('function-after[...]') in locations; drop it.
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p.startswith("function-")))
        if err["type"] == "extra_forbidden" and loc:
            # The unknown key is the file's own, whatever its spelling ('Robot' is no member tag).
            loc = (*loc[:-1], _FileKey(loc[-1]))
        entries.append((loc, err))
    return several([error(path, key_path(loc) or None, _problem(err, schema, loc))
                    for loc, err in _fitting_members(entries)], path)


_TYPE_TAGS = frozenset({"int", "float", "str", "bool", "list", "dict", "none"})


class _FileKey(str):
    """A key as the file spells it, where pydantic's location holds it (an unknown key): never
    taken for a union member's tag, which a capital or a '-' would otherwise make it."""

    __slots__ = ()


def _is_member_tag(part: int | str) -> bool:
    """A union member's name pydantic inserts in a location ('constrained-int', 'InputFile', 'str',
    'list[...]'); file keys are lower-case words without '-'."""
    return isinstance(part, str) and not isinstance(part, _FileKey) and ("-" in part or "[" in part or part[:1].isupper() or part in _TYPE_TAGS)


def _value_loc(loc: tuple[int | str, ...]) -> tuple[int | str, ...]:
    """The location of the value an error is about: cut at the first union member tag."""
    for i, part in enumerate(loc):
        if _is_member_tag(part):
            return loc[:i]
    return loc


def _fitting_members(entries: list[tuple[tuple[int | str, ...], Any]]) -> list[tuple[tuple[int | str, ...], Any]]:
    """The errors to report, each with its location free of member tags: of a value that fits no
    member of a union, only the errors of the member its kind fits (the first member when none
    does), unions inside that member chosen alike."""
    groups: dict[tuple[int | str, ...], list[tuple[tuple[int | str, ...], Any]]] = {}
    for loc, err in entries:
        groups.setdefault(_value_loc(loc), []).append((loc, err))
    out: list[tuple[tuple[int | str, ...], Any]] = []
    seen: list[tuple[int | str, ...]] = []
    for value, group in groups.items():
        if any(value[:len(s)] == s or s[:len(value)] == value for s in seen):
            continue                     # the same value, seen through another member of a union
        seen.append(value)
        tagged = [(loc, err) for loc, err in group if len(loc) > len(value)]
        if not tagged:
            out += group
            continue
        given = next((err["input"] for loc, err in tagged if len(loc) == len(value) + 1 and "input" in err), None)
        members = list(dict.fromkeys(loc[len(value)] for loc, _ in tagged))
        member = next((m for m in members if _member_kind(m) == _input_kind(given)), members[0])
        out += _fitting_members([(value + loc[len(value) + 1:], err) for loc, err in tagged
                                 if loc[len(value)] == member])
    return out


def _member_kind(tag: int | str) -> str:
    text = str(tag)
    if text[:1].isupper() or text.startswith("dict["):
        return "mapping"
    return "list" if text.startswith(("list[", "tuple[")) or text in ("list", "tuple") else "scalar"


def _input_kind(value: Any) -> str:
    if isinstance(value, dict):
        return "mapping"
    return "list" if isinstance(value, (list, tuple)) else "scalar"


def several(errors: list[_LocatedError], file: str | Path, more: bool = False) -> _LocatedError:
    """One error of independent ones: the error itself when there is one, else a list naming each
    with its file and key (`more`: further problems may follow, not looked for)."""
    if len(errors) == 1 and not more:
        return errors[0]
    shown = errors[:MAX_LISTED_PROBLEMS]
    lines = "".join(f"\n  {e}" for e in shown)
    tail = ""
    if more or len(errors) > len(shown):
        tail = f"\n  (listed the first {len(shown)}; fix these and check again for more)"
    return type(errors[0])(file, None, f"{len(errors) if not tail else str(len(shown)) + ' or more'} problems:"
                                       f"{lines}{tail}")


def _problem(err: Any, schema: type[BaseModel], loc: tuple[int | str, ...]) -> str:
    kind = err["type"]
    if kind == "extra_forbidden":
        known = _fields_at(schema, loc[:-1])
        hint = difflib.get_close_matches(str(loc[-1]), known, n=1, cutoff=0.6)
        suggestion = f"; did you mean '{hint[0]}'?" if hint else (f"; known keys: {', '.join(known)}" if known else "")
        return f"unknown key{suggestion}"
    if kind == "missing":
        return "required key is missing"
    problem = _clean_message(err["msg"])
    if "input" in err and kind not in ("value_error", "assertion_error"):
        problem += f", got {_show(err['input'])}"
    return problem


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
        msg = msg.removeprefix(prefix)
    return msg[:1].lower() + msg[1:]


def _kind(value: Any) -> str:
    return "nothing" if value is None else type(value).__name__


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."

"""The guarded YAML reader on libyaml gives what PyYAML's Python reader gives: the same document,
or a refusal at the same line and column (the checks on depth, keys, integers and aliases are
bounds of this project, so the two readers are compared against each other and against plain
`yaml.safe_load`, not against the code under test alone)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.errors import CellFileError
from robomax_py.io import yaml_files
from robomax_py.io.yaml_files import load_yaml
from robomax_py.safe_files import LIMITS

REPO = Path(__file__).resolve().parents[2]
HERE = Path("cell.yaml")

pytestmark = pytest.mark.skipif(not yaml_files._WITH_LIBYAML, reason="PyYAML without libyaml: one reader only")


def _outcome(read: Any, text: str) -> tuple[str, Any]:
    try:
        return "document", read(text)
    except CellFileError as exc:
        return "refused", str(exc)


def _both(text: str, monkeypatch: pytest.MonkeyPatch) -> tuple[tuple[str, Any], tuple[str, Any]]:
    fast = _outcome(lambda t: load_yaml(t, HERE, CellFileError, "cell file"), text)
    with monkeypatch.context() as m:
        m.setattr(yaml_files, "_WITH_LIBYAML", False)
        slow = _outcome(lambda t: load_yaml(t, HERE, CellFileError, "cell file"), text)
    return fast, slow


def test_every_shipped_cell_reads_the_same_on_both_readers(monkeypatch: pytest.MonkeyPatch) -> None:
    files = sorted((REPO / "cells").glob("*.yaml")) + sorted((REPO / "robomax_py" / "robots").rglob("*.yaml"))
    assert len(files) >= 10
    for path in files:
        text = path.read_text()
        fast, slow = _both(text, monkeypatch)
        assert fast == slow == ("document", yaml.safe_load(text)), path


D = LIMITS.yaml_depth       # the root mapping is the first level, so "a: " leaves D - 1 for lists


@pytest.mark.parametrize("text, where", [
    ("a: " + "[" * (D - 1) + "]" * (D - 1), None),                  # D levels: read
    ("a: " + "[" * (D - 2) + "1" + "]" * (D - 2), None),            # a scalar at level D: read
    ("a: " + "[" * (D - 1) + "1" + "]" * (D - 1), "line 1, column 67"),    # the scalar, level D + 1
    ("a: " + "[" * D + "]" * D, "line 1, column 67"),                 # the list at level D + 1
    ("a: 1\nb:\n  c: 2\n  c: 3\n", "line 4, column 3"),
    ("? [1, 2]\n: x\n", "line 1, column 3"),
    ("a: &x [1, *x]\n", "recursive alias"),
    ("n: " + "9" * (LIMITS.int_digits + 1), "line 1, column 4"),
    ("base: &b {x: 1, y: 2}\nitems:\n- {<<: *b, y: 3}\n- {<<: [*b, {z: 4}]}\n", None),     # merge keys
    ("base: &b {x: 1}\nitem: {<<: *b, <<: *b}\n", "line 2, column 16"),
    ("item: {<<: 5}\n", "line 1, column 12"),
    ("a: b\x07\n", "offset 4: not valid YAML: character 0x07"),
    ("éé: b\x07\n", "offset 5: not valid YAML"),     # in characters (libyaml counts bytes: 7)
    ("a: [1, 2\nb: 3\n", ""),                    # not YAML: both refuse (libyaml words it its way)
])
def test_bounds_refuse_at_the_same_place_on_both_readers(text: str, where: str | None,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    fast, slow = _both(text, monkeypatch)
    if where is None:
        assert fast == slow == ("document", yaml.safe_load(text))
        return
    assert fast[0] == slow[0] == "refused", (fast, slow)
    assert where in fast[1] and where in slow[1], (fast, slow)
    if where:
        assert fast[1] == slow[1]


_scalars = st.one_of(st.integers(-10**6, 10**6), st.booleans(), st.none(),
                     st.text(st.characters(codec="ascii", exclude_categories=("Cc",)), max_size=8),
                     st.floats(allow_nan=False, width=32))
_documents = st.recursive(_scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text("abcxyz_", min_size=1, max_size=4), inner, max_size=4)),
    max_leaves=30)


@settings(max_examples=150, deadline=None)
@given(doc=_documents, flow=st.booleans(), cut=st.integers(0, 400))
def test_generated_documents_and_their_truncations_read_the_same(doc: Any, flow: bool, cut: int) -> None:
    """A generated document reads back as itself on both readers; cut short anywhere, both read
    the same document or both refuse it."""
    text = yaml.safe_dump({"root": doc}, default_flow_style=flow)
    with pytest.MonkeyPatch.context() as monkeypatch:
        fast, slow = _both(text, monkeypatch)
        assert fast == slow == ("document", {"root": doc})
        short = text[:cut]
        fast, slow = _both(short, monkeypatch)
        assert fast[0] == slow[0], (short, fast, slow)
        if fast[0] == "document":
            assert fast[1] == slow[1]

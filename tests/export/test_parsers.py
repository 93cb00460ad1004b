"""The dialects' parsers kept in the cache folder: the same trees from a kept parser as from one
built from the grammar, and a cache that cannot be written only means building again."""

from __future__ import annotations

from pathlib import Path

import pytest
from lark import Lark
from lark.exceptions import UnexpectedInput

from robomax_py.export.parsers import lalr_parser
from robomax_py.export.srcl.grammar import GRAMMAR

GOLDEN = Path(__file__).parent.parent / "golden" / "example.srcl"
OPTIONS = {"lexer": "basic", "propagate_positions": True, "maybe_placeholders": False}


def test_a_kept_parser_reads_as_a_built_one(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOMAX_CACHE", str(tmp_path))
    text = GOLDEN.read_text()
    built = Lark(GRAMMAR, parser="lalr", **OPTIONS).parse(text)
    first = lalr_parser("srcl", GRAMMAR, **OPTIONS)           # builds and keeps the file
    kept_file = tmp_path / "parsers" / "srcl.lark"
    assert kept_file.stat().st_size > 0
    kept = lalr_parser("srcl", GRAMMAR, **OPTIONS)            # reads it
    assert first.parse(text) == built
    assert kept.parse(text) == built
    # positions survive the file (the messages name lines and columns from them)
    assert kept.parse(text).meta.line == built.meta.line


def test_another_grammar_under_the_same_name_is_built_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOMAX_CACHE", str(tmp_path))
    lalr_parser("toy", 'start: "A"', lexer="basic")
    other = lalr_parser("toy", 'start: "B"', lexer="basic")
    assert other.parse("B").data == "start"
    with pytest.raises(UnexpectedInput):
        other.parse("A")


def test_an_unwritable_cache_still_gives_a_parser(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("")
    monkeypatch.setenv("ROBOMAX_CACHE", str(blocker))
    assert lalr_parser("srcl", GRAMMAR, **OPTIONS).parse(GOLDEN.read_text()) is not None
    assert not (tmp_path / "parsers").exists()

"""The program dialects' LALR parsers, kept in the cache folder between runs.

Building an LALR table from a grammar costs ~0.1 s of CPU per process (lark's grammar analysis),
paid by every `plan` for the proof that reads its program back. lark keeps a built parser in a
file of our choosing (`cache=`) and uses it only while the grammar, the options and lark's version
are the ones it was built from (a digest in the file); otherwise it builds again and replaces it.
A file that cannot be read or written (an unwritable cache, a half-written file of a concurrent
run) only costs building again: lark catches and logs that.
"""

from __future__ import annotations

from typing import Any

from lark import Lark

from robomax_py.cache_files import cache_folder


def lalr_parser(name: str, grammar: str, **options: Any) -> Lark:
    """lark's LALR parser of `grammar` (`options` as for `lark.Lark`), read from
    `<cache>/parsers/<name>.lark` when lark built it there from the same grammar and options."""
    folder = cache_folder("parsers")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return Lark(grammar, parser="lalr", **options)
    return Lark(grammar, parser="lalr", cache=str(folder / f"{name}.lark"), **options)

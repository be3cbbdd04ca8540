"""Replace a generated block (from its first marker to its last) in a document."""

from __future__ import annotations

import re
from pathlib import Path


def replace_block(path: Path, begin: str, end: str, text: str) -> None:
    """Put ``text`` (which starts with ``begin`` and ends with ``end``) in place of the
    block between those markers in ``path``; written to a temporary name, then moved."""
    doc = path.read_text()
    pattern = re.escape(begin) + r".*?" + re.escape(end)
    if not re.search(pattern, doc, flags=re.S):
        raise SystemExit(f"{path}: no block {begin!r} ... {end!r} to replace")
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(re.sub(pattern, lambda _: text, doc, flags=re.S))
    tmp.replace(path)

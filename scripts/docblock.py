"""Helpers of the scripts that write docs: a generated block replaced, a figure saved."""

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


def save_figure(fig, path: Path, dpi: int = 110) -> None:
    """Save a matplotlib figure to ``path`` under a temporary name, then move it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp" + path.suffix)
    fig.savefig(tmp, dpi=dpi)
    tmp.replace(path)

"""Regenerate the README's claims table from a full run of the main job.

Run: ``python scripts/readme_claims.py`` (runs ``tactsense.reproduce`` in a temporary
folder, about a minute, and rewrites the text between the markers
``<!-- claims:start -->`` and ``<!-- claims:end -->`` of README.md). The numbers in
the README therefore come from code, never typed by hand; the test suite checks that the
table's rows and bases match the claims the code defines.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from tactsense.reproduce import reproduce
from tactsense.reproduce.report import claims_table_markdown, summary

README = Path(__file__).resolve().parents[1] / "README.md"
START, END = "<!-- claims:start -->", "<!-- claims:end -->"


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        result = reproduce(Path(folder) / "report")
    claims = list(result["claims"].values())
    block = (
        f"{START}\n{summary(claims)} (full run, {result['meta']['seconds']:.0f} s, "
        f"tactsense {result['meta']['version']})\n\n{claims_table_markdown(claims)}\n{END}"
    )
    text = README.read_text(encoding="utf-8")
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    README.write_text(head + block + tail, encoding="utf-8")
    print(summary(claims))


if __name__ == "__main__":
    main()

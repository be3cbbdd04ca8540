"""The terminal table of ``tactsense reproduce`` (issue 21, item 9): every claim id whole."""

import io

import pytest
from rich.console import Console

from tactsense.cli.reproduce import claims_table
from tactsense.reproduce._common import Claim
from tactsense.reproduce.basis import BASIS


@pytest.mark.parametrize("width", [80, 100, 120])
def test_every_claim_id_is_printed_whole(width):
    """Three ids begin with "localization"; at 80 columns they were cut to
    "localization..." and could not be told apart. Each id must appear whole, on one
    line of the rendered table."""
    claims = [
        Claim(key, "a statement", 1.0, 1.234, "mm/deg", 0.1, "a note") for key in sorted(BASIS)
    ]
    assert sum(key.startswith("localization") for key in BASIS) >= 3
    buffer = io.StringIO()
    Console(file=buffer, width=width, color_system=None).print(claims_table(claims, "claims"))
    lines = buffer.getvalue().splitlines()
    for claim in claims:
        assert any(claim.id in line for line in lines), (claim.id, width)

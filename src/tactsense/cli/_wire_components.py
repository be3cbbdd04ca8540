"""``--components N`` of ``emulate``, ``record`` and ``live`` (r8-triwire): values per
taxel on a line of another wire format (text, marker, JustFloat; ``docs/devices.md``),
the option ``components=N`` of the source's format spelled as an option of the command."""

from __future__ import annotations

from typing import Annotated

import typer

from tactsense._validation import TactsenseInputError
from tactsense.cli._common import fail

ComponentsOption = Annotated[
    int | None,
    typer.Option(
        "--components",
        help="Values per taxel on a text, marker or justfloat line, 1 to 4 (3 for a "
        "three-axis taxel: x, y, z in turn, taxels row-major) [values/taxel]; default the "
        "sensor's. A line of another count is a clear error. The same as the format "
        "option components=N; the tactsense protocol's frames say their own.",
    ),
]


def source_with_components(source: str, components: int | None) -> str:
    """The source of ``record``/``live`` with ``components=N`` in its format's options."""
    from tactsense.stream.sources import with_components

    try:
        return with_components(source, components)
    except TactsenseInputError as error:
        fail(str(error))


def format_with_components(spec: str | None, components: int | None) -> str | None:
    """``emulate --format SPEC`` with ``components=N`` in its options."""
    from tactsense.stream.sources import format_with_components as add

    try:
        return add(spec, components)
    except TactsenseInputError as error:
        fail(str(error))


def refuse_with_skin(skin, components: int | None) -> None:
    """A robot skin's devices speak the tactsense protocol: no ``--components``."""
    if skin is not None and components is not None:
        fail("--components applies to one device of another wire format, not to --skin")

"""What every command shares: the console, the option types, and the one rule that turns
an error into a one-line message and an exit code."""

from __future__ import annotations

from typing import Annotated, NoReturn

import typer
from rich.console import Console

console = Console(stderr=True)
"""Messages, progress and tables meant for a person go to standard error."""

SensorOption = Annotated[
    str,
    typer.Option(
        "--sensor",
        help="Built-in finger ('initial': 3.8 mm x 45 deg, 'improved': 3.3 mm x 18 deg) "
        "or the path of a sensor TOML file.",
    ),
]


def new_group(help: str) -> typer.Typer:
    """A typer app for a group of commands, with tactsense's settings."""
    return typer.Typer(no_args_is_help=True, add_completion=False, rich_markup_mode=None, help=help)


def fail(message: str) -> NoReturn:
    """Print ``error: message`` and leave with exit status 2 (bad input)."""
    console.print(f"[bold red]error:[/] {message}")
    raise typer.Exit(code=2)

"""What every command shares: the console, the option types, and the one rule that turns
an error into a one-line message and an exit code."""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
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


def check_output(path: Path, force: bool, *, what: str = "output") -> Path:
    """Refuse an output path that cannot be written, before any work starts.

    The rule for every command: the parent folder must exist (it is never created, so a
    typo does not scatter folders), an existing directory is never an output file, and
    an existing file is replaced only with ``--force``.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        fail(f"{what} {path} is a directory; expected a file name")
    if not parent.is_dir():
        fail(f"folder {parent} of {what} {path} does not exist; create it first")
    if not os.access(parent, os.W_OK | os.X_OK):
        fail(f"cannot write {what} {path}: folder {parent} is not writable")
    if path.exists() and not force:
        fail(f"{path} exists; pass --force to replace it, or choose another name")
    return path


@contextmanager
def atomic_output(path: Path):
    """Yield a temporary name beside ``path``; move it into place only if the block ends
    without an exception (Ctrl-C included), else remove it."""
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.partial")
    try:
        yield temporary
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    os.replace(temporary, path)

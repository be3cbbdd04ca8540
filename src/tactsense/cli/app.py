"""The ``tactsense`` command line, one module per group of commands.

Each group (``model``, ``estimate``, ``live``, ``design``, ``reproduce``) is a typer app of its own;
this module mounts them. A new command is a function in its group's module.
"""

from __future__ import annotations

from typing import Annotated

import typer

from tactsense.cli import design, estimate, imports, interop, live, model, reproduce

app = typer.Typer(
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode=None,
    help="tactsense: digital twin and analysis of the capacitive tactile finger of Fearing (1990).",
)


def _version(value: bool) -> None:
    if value:
        from tactsense import __version__

        typer.echo(f"tactsense {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_version,
            is_eager=True,
            help="Print the version (tactsense X.Y.Z) and exit.",
        ),
    ] = False,
) -> None:
    """tactsense: digital twin and analysis of the capacitive tactile finger of Fearing (1990)."""


app.add_typer(reproduce.app)
app.add_typer(model.app)
app.add_typer(estimate.app)
app.add_typer(live.app)
app.add_typer(interop.app)
app.add_typer(imports.app)
app.add_typer(model.sensor_app, name="sensor")
app.add_typer(design.app, name="design")


def main() -> None:
    """Entry point of the ``tactsense`` script."""
    app()

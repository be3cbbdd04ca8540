"""The ``tactsense`` command line, one module per group of commands.

Each group (``model``, ``estimate``, ``live``, ``design``, ``reproduce``) is a typer app of its own;
this module mounts them. A new command is a function in its group's module.
"""

from __future__ import annotations

import sys
from typing import Annotated

import click
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
# ---- the MuJoCo adapter (r6-mujoco) ----
from tactsense.cli import _mujoco  # noqa: E402

app.add_typer(_mujoco.app)

# ---- tactsense dataset (r6-data) ----
from tactsense.cli import _dataset  # noqa: E402

app.add_typer(_dataset.app)
# ---- /r6-data ----

# ---- tactsense grasp (r7-grasp) ----
from tactsense.cli import _grasp  # noqa: E402

app.add_typer(_grasp.app)
# ---- /r7-grasp ----


def _show_usage_error(self, file=None) -> None:
    """A usage error (unknown option, value out of range, missing argument) as one line
    ``error: ...`` naming the command's help, instead of click's usage block."""
    command = self.ctx.command_path if self.ctx is not None else "tactsense"
    message = " ".join(self.format_message().split())
    cause = self.__cause__ or self.__context__
    errors = cause.errors() if hasattr(cause, "errors") else []
    given = [str(e.get("input", "")).strip().lower() for e in errors if isinstance(e, dict)]
    if any(value in ("nan", "+nan", "-nan") for value in given):
        # a range check fails on NaN with a misleading bound; say what it is
        name = "/".join(getattr(getattr(self, "param", None), "opts", []) or ["the value"])
        message = f"Invalid value for '{name}': NaN is not a number"
    print(f"error: {message} (see '{command} --help')", file=file or sys.stderr)


# typer >= 0.24 carries its own copy of click (typer._click): patch both
for _module in (click, getattr(typer, "_click", None)):
    _usage_error = getattr(getattr(_module, "exceptions", None), "UsageError", None)
    if _usage_error is not None:
        _usage_error.show = _show_usage_error


def main() -> None:
    """Entry point of the ``tactsense`` script."""
    app()

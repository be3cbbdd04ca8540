"""What every command shares: the console, the option types, and the one rule that turns
an error into a one-line message and an exit code."""

from __future__ import annotations

import functools
import math
import os
import re
import warnings
from collections.abc import Iterable
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, NoReturn

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape

from tactsense._validation import TactsenseInputError


class _MessageConsole(Console):
    """A console whose text messages are never hard-wrapped: a summary printed to a log
    or a pipe stays one line (rich would otherwise break it at 80 columns there, and at
    the terminal's width on a terminal, where the terminal wraps it anyway). Tables and
    other renderables are laid out at the console's width as before."""

    def print(self, *objects, soft_wrap=None, **kwargs) -> None:
        if soft_wrap is None and all(isinstance(o, str) for o in objects):
            soft_wrap = True
        super().print(*objects, soft_wrap=soft_wrap, **kwargs)


console = _MessageConsole(stderr=True)
"""Messages, progress and tables meant for a person go to standard error."""


def print_table(table) -> None:
    """Print a rich table on standard output: at the terminal's width on a terminal, and
    at the table's natural width when piped or redirected (rich would otherwise wrap
    every cell at 80 columns, breaking ids and numbers over lines)."""
    out = Console()
    if not out.is_terminal:
        natural = Console(width=10_000).measure(table).maximum
        out = Console(width=max(80, natural))
    out.print(table)


_PRESET_TEXTS = {
    "initial": "the paper's fingers 'initial' (3.8 mm x 45 deg)",
    "improved": "'improved' (3.3 mm x 18 deg)",
    "pad4": "the pads 'pad4' (4x4, 5 mm)",
    "pad16": "'pad16' (16x16, 2.5 mm)",
    "pad12x32": "'pad12x32' (12x32, 2 mm)",
    "fsr16": "the piezoresistive pads 'fsr16' (16x16 FSR, 4 mm)",
    "dsa9205": "'dsa9205' (6x14, 3.4 mm)",
    "dome12": "the point sets 'dome12' (docs/sensors.md)",
    "icub_fingertip": "'icub_fingertip' (the iCub's, 8 bits, falling; docs/contacts.md)",
}
"""How ``--sensor``'s help describes a built-in preset (the names come from the registry)."""


def sensor_help() -> str:
    """``--sensor``'s help: every preset the registry holds (``tactsense.sensor.PRESETS``,
    the registered kinds' included, each of those named with its kind's label), never a
    typed list; a plug-in that fails to load leaves the built-ins listed."""
    from tactsense.kinds import kinds
    from tactsense.sensor import PRESETS

    try:
        names = list(PRESETS)
        labels = {name: kind.label for kind in kinds().values()
                  for name in (getattr(kind, "presets", None) or {})}  # fmt: skip
    except Exception:  # a plug-in that fails to load must not stop the CLI (it says so later)
        names, labels = list(_PRESET_TEXTS), {}
    texts = [_PRESET_TEXTS.get(n) or f"'{n}' ({labels.get(n, 'a registered kind')})"
             for n in names]  # fmt: skip
    return f"A preset: {', '.join(texts)}; or the path of a sensor TOML file."


SensorOption = Annotated[str, typer.Option("--sensor", help=sensor_help())]


# ---- trial8 fixes (r8-fixa8): sensor check and simulate ----
def checked_sensor(path: Path):
    """The sensor ``sensor check PATH`` validates: a preset by name (as ``sensor show``;
    a file of that name comes first), a TOML file, or a finger's file."""
    from tactsense.sensor import PRESETS, SensorSpec, load_sensor

    if not path.exists() and str(path).removeprefix("fearing1990_") in PRESETS:
        return load_sensor(str(path))
    return load_sensor(path) if path.suffix.lower() == ".toml" else SensorSpec.from_toml(path)


def threshold_rule(spec) -> str:
    """The rule that gives locate's default contact threshold of ``spec``
    (:func:`tactsense.estimate.reading.threshold_counts`), in words with its numbers."""
    noise = float(spec.flaws.read_noise_counts)
    if spec.components > 1:  # the length of a taxel's change (vector_threshold_counts)
        return (
            f"the length of a taxel's change over its {spec.components} components, the "
            f"larger of 10 counts and 8 x the read noise of {noise:.3g} counts x "
            f"sqrt({spec.components})"
        )
    return (
        f"the larger of 10 counts, the same share of a range of fewer than 12 bits but at "
        f"least 3, and 5 x the read noise of {noise:.3g} counts; raised where creep is "
        "taken out"
    )


def rest_warnings(spec) -> list[str]:
    """What is wrong with ``spec`` untouched, one line each (its kind's ``rest_warnings``,
    e.g. a three-axis skin whose rest field saturates the converter); none by default."""
    from tactsense.kinds import kind_of

    return list(kind_of(spec).rest_warnings(spec))


def frame_text(spec) -> str:
    """A frame's shape for "wrote X: N frames of ... counts": ``4x4`` for scalar taxels,
    ``4x4x3 (x, y, z)`` for taxels of several components."""
    text = "x".join(str(n) for n in spec.frame_shape)
    if spec.components > 1:
        text += f" ({', '.join(spec.component_names)})"
    return text


# ---- /trial8 fixes (r8-fixa8) ----


CalibrationOption = Annotated[
    Path | None,
    typer.Option(
        help="Calibration JSON from 'tactsense calibrate': its baseline, gains and excluded "
        "taxels apply from the first frame, with a finger's nonlinearity and creep "
        "compensation, or a pad's or point set's force curve."
    ),
]
BaselineFramesOption = Annotated[
    int,
    typer.Option(
        min=1,
        max=1_000_000,
        help="Without --calibration: untouched frames at the start whose median is the "
        "undeflected reading V_o of eq. 4.",
    ),
]


def _threshold(value: float | None) -> float | None:
    """``--threshold``: a number in (0, 1]; NaN and infinities are refused by name."""
    if value is None:
        return None
    if not (math.isfinite(value) and 0.0 < value <= 1.0):
        raise typer.BadParameter(
            f"{value} is not a fraction: it must be a number in (0, 1], e.g. 0.005 for 0.5 %"
        )
    return value


ContactThresholdOption = Annotated[
    float | None,
    typer.Option(
        "--threshold",
        callback=_threshold,
        help="Smallest signal that counts as contact, as a fraction [default: 10 counts' "
        "worth on 12 bits or more (the same share of the range on fewer, at least 3 "
        "counts), or 5 standard deviations of the description's read_noise_counts when "
        "that is more (times the creep compensation's noise gain where creep is taken "
        "out); for capacitive taxels the fractional deflection of that change from the "
        "rest reading, at least 0.005 (0.5 %, 10 counts at 2000); for resistive and "
        "piezoresistive ones that change / counts_per_strain of strain; a weights "
        "calibration's own threshold when one is given].",
    ),
]

ThresholdOption = Annotated[
    float,
    typer.Option(
        callback=_threshold,
        help="Smallest tactel deflection that counts as a contact, as a fraction (0.005 = "
        "0.5 %, about 10 counts at 2000).",
    ),
]


class _Group(typer.Typer):
    """A typer app whose every command runs under :func:`guarded`."""

    def command(self, *args, **kwargs):
        register = super().command(*args, **kwargs)

        def decorator(function):
            register(guarded(function))
            return function

        return decorator


def new_group(help: str) -> typer.Typer:
    """A typer app for a group of commands, with tactsense's settings and error rule."""
    return _Group(no_args_is_help=True, add_completion=False, rich_markup_mode=None, help=help)


def guarded(function):
    """The one rule from errors to messages and exit codes, for every command.

    Bad input (a :class:`TactsenseInputError`, an existing output, an unreadable or
    unwritable path) is ``error: ...`` on one line and exit status 2; Ctrl-C is exit
    status 1 (outputs are written to temporary names, so nothing is left half-written);
    NumPy's floating-point warnings never reach the terminal: the estimates carry flags
    and NaN where a number is meaningless.
    """

    @functools.wraps(function)
    def run(*args, **kwargs):
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                return function(*args, **kwargs)
            except KeyboardInterrupt:
                from tactsense import _signals

                if _signals.terminated:  # SIGTERM takes Ctrl-C's path; 143 = 128 + SIGTERM
                    console.print(
                        "[bold red]error:[/] stopped by SIGTERM; no output was left half-written"
                    )
                    raise typer.Exit(code=143) from None
                console.print("[bold red]error:[/] interrupted; no output was left half-written")
                raise typer.Exit(code=1) from None
            except (TactsenseInputError, FileExistsError) as error:
                fail(str(error))
            except OSError as error:
                where = f" ({error.filename})" if error.filename else ""
                fail(f"{error.strerror or error}{where}")

    return run


def progress_bar(label: str, *, unit: str = "", quiet: bool = False, eta: bool = True):
    """The progress bar of every long command: ``label ━━━ done/total unit eta``.

    Shown on a terminal only: quiet when standard error is a file or a pipe (logs stay
    clean), and with ``--quiet``.
    """
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    columns = [TextColumn(label), BarColumn(), MofNCompleteColumn()]
    if unit:
        columns.append(TextColumn(unit))
    if eta:
        columns.append(TimeRemainingColumn())
    return Progress(*columns, console=console, disable=quiet or not console.is_terminal)


def fail(message: str) -> NoReturn:
    """Print ``error: message`` and leave with exit status 2 (bad input)."""
    # the message is text, not markup ("[array]" must survive) nor emoji codes ("10:100:8"
    # must not print as "10💯8"), and one line however long
    console.print(f"[bold red]error:[/] {escape(message)}", soft_wrap=True, emoji=False)
    raise typer.Exit(code=2)


def same_file(a: Path, b: Path) -> bool:
    """Whether two paths name the same file however they are spelled (relative or
    absolute, ``./``, ``..``, symlinks, hard links)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet): compare the resolved names
        try:
            return Path(a).resolve() == Path(b).resolve()
        except (OSError, RuntimeError):
            return False


def inside(path: Path, folder: Path) -> bool:
    """Whether ``path`` is ``folder`` or lies anywhere under it (symlinks resolved)."""
    try:
        path, folder = Path(path).resolve(), Path(folder).resolve()
    except (OSError, RuntimeError):
        return False
    return path == folder or folder in path.parents


def sensor_file(sensor: str | None) -> list[Path]:
    """The ``--sensor`` value as a list of input files: empty for a built-in finger."""
    if sensor is None or not Path(sensor).exists():
        return []
    return [Path(sensor)]


def check_output(
    path: Path,
    force: bool,
    *,
    what: str = "output",
    inputs: Iterable[Path | str | None] = (),
) -> Path:
    """Refuse an output path that cannot be written, before any work starts.

    The rule for every command: the parent folder must exist (it is never created, so a
    typo does not scatter folders), an existing directory is never an output file, an
    output is never one of the command's ``inputs`` (however the path is spelled, with
    or without ``--force``), and an existing file is replaced only with ``--force``.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    for source in inputs:
        if source is not None and same_file(path, Path(source)):
            fail(
                f"{what} {path} is the input {source}; an output never replaces an input "
                "(--force or not): choose another name"
            )
    if path.is_dir():
        fail(f"{what} {path} is a directory; expected a file name")
    if parent.exists() and not parent.is_dir():
        fail(f"{parent} in {what} {path} is a file, not a folder")
    if not parent.is_dir():
        fail(f"folder {parent} of {what} {path} does not exist; create it first")
    if not os.access(parent, os.W_OK | os.X_OK):
        fail(f"cannot write {what} {path}: folder {parent} is not writable")
    if path.exists() and not force:
        fail(f"{path} exists; pass --force to replace it, or choose another name")
    return path


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


_PARTIAL = re.compile(r"^\.(?P<stem>.+)\.(?P<pid>\d+)\.partial(?P<suffix>\.[^.]+)?$")


def remove_stale_partials(folder: Path) -> list[Path]:
    """Remove every ``.{name}.{pid}.partial{suffix}`` left in ``folder`` by a killed run.

    A run killed outright (SIGKILL, power loss) cannot clean up its temporary output;
    the next command that writes into the same folder removes it, whatever its name, if
    the process that wrote it is gone. Only tactsense's own naming pattern is touched,
    and only when the writer's process id is not alive.

    Returns
    -------
    list of Path
        The leftovers removed.
    """
    import shutil

    removed = []
    try:
        candidates = list(Path(folder).glob(".*.partial*"))
    except OSError:
        return removed
    for leftover in candidates:
        match = _PARTIAL.match(leftover.name)
        if match is None or _alive(int(match["pid"])) or int(match["pid"]) == os.getpid():
            continue
        try:
            if leftover.is_dir() and not leftover.is_symlink():
                shutil.rmtree(leftover)
            else:
                leftover.unlink()
        except OSError:
            continue
        removed.append(leftover)
    return removed


@contextmanager
def atomic_output(path: Path):
    """Yield a temporary name beside ``path``; move it into place only if the block ends
    without an exception (Ctrl-C included), else remove it.

    Leftovers of killed runs in the same folder are removed first
    (:func:`remove_stale_partials`); an error about the temporary file names ``path``.
    """
    path = Path(path)
    # hidden, unique, and with the final suffix (matplotlib picks the format from it)
    remove_stale_partials(path.parent if str(path.parent) else Path("."))
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.partial{path.suffix}")
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException as error:
        try:
            temporary.unlink(missing_ok=True)
        except OSError:
            pass
        # the user named the output, not our temporary file
        if isinstance(error, OSError) and error.filename in (str(temporary), temporary):
            error.filename = str(path)
            error.filename2 = None
        elif isinstance(error, OSError | TactsenseInputError) and str(temporary) in str(error):
            # libraries that put the name in the message (pyarrow: "Failed to open local file")
            if isinstance(error, OSError) and error.strerror:
                renamed = error.strerror.replace(str(temporary), str(path))
                raise OSError(error.errno, renamed) from error
            renamed = str(error).replace(str(temporary), str(path))
            raise (OSError if isinstance(error, OSError) else type(error))(renamed) from error
        raise

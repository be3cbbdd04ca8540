"""The iCub grasp dataset's trial files (Soh, Su and Demiris, IROS 2012) into recordings.

One trial file (``book_8.txt``, ``none_3.txt``: object, then trial number) holds the
readings of the iCub hand's five fingertips while the hand grasps. Its layout, as the
dataset's README gives it: a first line ``-10000`` (a marker, to be ignored), then one
*time slice* per 7 lines:

1. the 9 joint encoders of the hand (joints 7-15) [deg];
2. ``max(255 - reading)`` of each of the 5 fingertips [counts] (the logger's own
   summary; it was sampled apart from the taxel lines and can differ from them by a few
   counts, so it is kept but not used);
3. to 7. the 12 taxel readings of the thumb, index, middle, ring and little fingertips
   [counts], 8 bits, 255 untouched in principle (about 241-248 in fact), falling under
   pressure.

The files carry no time stamps: a slice's time is unknown. A recording made from one is
timed ``slice number x period_s``; the period defaults to 1 s, so that the frame times
are the slice numbers, and the recording's description says so.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactsense._validation import TactsenseInputError

FINGERS = ("thumb", "index", "middle", "ring", "little")
"""The fingertips in the order of a slice's taxel lines (lines 3 to 7)."""
HEADER = "-10000"
"""The first line of every trial file."""
SLICE_LINES = 7
"""Lines of one time slice."""
ENCODERS = 9
"""Joint encoders of a slice (the hand's joints 7-15) [-]."""
TAXELS = 12
"""Taxels of one fingertip [-]."""
FULL_SCALE = 255
"""Largest 8-bit reading [counts]."""
DEFAULT_PERIOD_S = 1.0
"""Time given to one slice when none is known [s]: the frame times are slice numbers."""

_WIDTHS = (ENCODERS, len(FINGERS)) + (TAXELS,) * len(FINGERS)
_WHAT = ("joint encoders", "fingertip maxima", *(f"{f} taxels" for f in FINGERS))
_NAME = re.compile(r"^(?P<object>.+)_(?P<trial>\d+)$")


class IcubGraspError(TactsenseInputError):
    """A file that is not an iCub grasp trial as the dataset's README describes it."""


@dataclass(frozen=True)
class GraspTrial:
    """One trial: every time slice of one grasp.

    Attributes
    ----------
    encoders_deg : ndarray, shape (T, 9)
        Joint encoders of the hand, joints 7-15 [deg].
    max_drop_counts : ndarray, shape (T, 5)
        The file's ``max(255 - reading)`` per fingertip [counts].
    taxels_counts : ndarray, shape (T, 5, 12)
        Taxel readings, fingertips in :data:`FINGERS` order [counts].
    source : str
        The file read.
    """

    encoders_deg: np.ndarray
    max_drop_counts: np.ndarray
    taxels_counts: np.ndarray
    source: str = ""

    def __len__(self) -> int:
        return len(self.taxels_counts)


def finger_index(finger: str) -> int:
    """Position of a fingertip's name in :data:`FINGERS`, or a clear error."""
    if finger not in FINGERS:
        raise IcubGraspError(
            f"finger {finger!r} is not an iCub fingertip; expected one of {', '.join(FINGERS)}"
        )
    return FINGERS.index(finger)


def parse_trial(text: str, *, source: str = "trial") -> GraspTrial:
    """A trial from the text of its file (see the module's description of the layout).

    Blank lines are skipped. Refused, with the line: a first line other than ``-10000``,
    a slice cut short, a line with the wrong count of numbers, a value that is not a
    finite number, and a taxel reading outside 0-255.
    """
    lines = [(k, line) for k, line in enumerate(text.splitlines(), start=1) if line.strip()]
    if not lines:
        raise IcubGraspError(
            f"{source} is empty; expected an iCub grasp trial (a first line {HEADER}, then "
            f"{SLICE_LINES} lines per time slice)"
        )
    first_line, first = lines[0]
    if first.strip() != HEADER:
        raise IcubGraspError(
            f"{source} line {first_line}: the first line is {first.strip()[:40]!r}; an iCub "
            f"grasp trial starts with the line {HEADER}"
        )
    body = lines[1:]
    if not body:
        raise IcubGraspError(f"{source}: the header line {HEADER} and no time slice after it")
    if len(body) % SLICE_LINES:
        whole = len(body) // SLICE_LINES
        start = body[whole * SLICE_LINES][0]
        raise IcubGraspError(
            f"{source}: the time slice that starts on line {start} has "
            f"{len(body) % SLICE_LINES} of its {SLICE_LINES} lines (a truncated file?); "
            f"{whole} whole slices before it"
        )
    rows: list[list[float]] = []
    for index, (number, line) in enumerate(body):
        slot = index % SLICE_LINES
        fields = line.split()
        if len(fields) != _WIDTHS[slot]:
            raise IcubGraspError(
                f"{source} line {number}: {len(fields)} numbers; line {slot + 1} of a time "
                f"slice holds the {_WHAT[slot]}, {_WIDTHS[slot]} numbers"
            )
        try:
            values = [float(x) for x in fields]
        except ValueError:
            bad = next(x for x in fields if not _is_number(x))
            raise IcubGraspError(
                f"{source} line {number}: {bad[:20]!r} is not a number ({_WHAT[slot]})"
            ) from None
        if not all(math.isfinite(v) for v in values):
            raise IcubGraspError(
                f"{source} line {number}: a value is not a finite number ({_WHAT[slot]})"
            )
        if slot >= 2 and not all(0 <= v <= FULL_SCALE for v in values):
            bad = next(v for v in values if not 0 <= v <= FULL_SCALE)
            raise IcubGraspError(
                f"{source} line {number}: the reading {bad:g} is outside 0-{FULL_SCALE} "
                f"({_WHAT[slot]}, 8-bit)"
            )
        rows.append(values)
    n = len(rows) // SLICE_LINES
    encoders = np.array([rows[SLICE_LINES * i] for i in range(n)])
    maxima = np.array([rows[SLICE_LINES * i + 1] for i in range(n)])
    taxels = np.array([rows[SLICE_LINES * i + 2 : SLICE_LINES * (i + 1)] for i in range(n)])
    return GraspTrial(encoders, maxima, taxels, source=source)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_trial(path: str | Path) -> GraspTrial:
    """A trial file (``book_8.txt``) as a :class:`GraspTrial`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="ascii")
    except UnicodeDecodeError:
        raise IcubGraspError(
            f"{path} is not a text file of numbers; expected an iCub grasp trial"
        ) from None
    except OSError as error:
        raise IcubGraspError(f"cannot read {path}: {error.strerror or error}") from None
    return parse_trial(text, source=str(path))


def trial_name(path: str | Path) -> tuple[str, int]:
    """The object and the trial number a trial file is named after (``book_8`` -> book, 8)."""
    match = _NAME.match(Path(path).stem)
    if match is None:
        raise IcubGraspError(
            f"{path}: a trial file is named OBJECT_NUMBER.txt (book_8.txt); got {Path(path).name}"
        )
    return match["object"], int(match["trial"])


def read_dataset(folder: str | Path) -> dict[str, dict[int, GraspTrial]]:
    """Every trial of a dataset folder: object -> trial number -> :class:`GraspTrial`."""
    folder = Path(folder)
    if not folder.is_dir():
        raise IcubGraspError(f"{folder} is not a folder of iCub grasp trials")
    found: dict[str, dict[int, GraspTrial]] = {}
    for path in sorted(folder.glob("*.txt")):
        obj, trial = trial_name(path)
        found.setdefault(obj, {})[trial] = read_trial(path)
    if not found:
        raise IcubGraspError(f"{folder} holds no trial files (OBJECT_NUMBER.txt)")
    return {obj: dict(sorted(trials.items())) for obj, trials in sorted(found.items())}


def trial_recording(trial: GraspTrial, finger: str, *, sensor=None, period_s=None):
    """One fingertip of a trial as a :class:`~tactsense.io.recording.Recording`.

    Parameters
    ----------
    trial : GraspTrial
    finger : {"thumb", "index", "middle", "ring", "little"}
    sensor : preset name, TOML path or spec, optional
        A point set of 12 taxels (default: the ``icub_fingertip`` preset).
    period_s : float, optional
        Time between slices [s]; the files carry none, so by default
        :data:`DEFAULT_PERIOD_S` (the frame times are the slice numbers).
    """
    from tactsense.interop._build import ImportError_, build_recording
    from tactsense.sensor import SensorSpecError, load_sensor

    k = finger_index(finger)
    try:
        spec = load_sensor("icub_fingertip" if sensor is None else sensor)
    except SensorSpecError as error:
        raise ImportError_(f"--sensor: {error}") from None
    if tuple(spec.shape) != (1, TAXELS):
        rows, cols = spec.shape
        raise IcubGraspError(
            f"sensor {spec.name!r} has {rows} x {cols} taxels; an iCub fingertip has "
            f"1 x {TAXELS} (a point set of {TAXELS})"
        )
    given = period_s is not None
    period = DEFAULT_PERIOD_S if period_s is None else float(period_s)
    if not (math.isfinite(period) and period > 0):
        raise IcubGraspError(f"the period between slices must be positive; got {period_s!r}")
    frames = trial.taxels_counts[:, k, :].reshape(-1, 1, TAXELS)
    timing = (
        f"slices {period:g} s apart (as given)"
        if given
        else "frame times are slice numbers (the file carries no times)"
    )
    return build_recording(
        spec,
        frames,
        np.arange(len(frames)) * period,
        source=trial.source,
        description=f"iCub grasp trial {trial.source}, {finger} fingertip; {timing}",
    )


def read_icub_grasp(path: str | Path, *, finger: str | None, sensor=None, period_s=None):
    """One fingertip of a trial file as a recording (``tactsense import --format icub-grasp``)."""
    if finger is None:
        raise IcubGraspError(
            f"{path}: an iCub grasp trial holds five fingertips; say which with --finger "
            f"({', '.join(FINGERS)})"
        )
    finger_index(finger)
    return trial_recording(read_trial(path), finger, sensor=sensor, period_s=period_s)

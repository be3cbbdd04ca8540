"""One shared input check for public boundaries.

Every public function that takes arrays or numbers from a user passes them
through these helpers, so that a wrong input is reported with what was wrong
and what was expected, instead of failing somewhere deep inside NumPy.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class TactsenseInputError(ValueError):
    """Raised when an input to a public tactsense function is malformed."""


class CalibrationError(TactsenseInputError):
    """Raised when a calibration cannot be built, loaded or applied."""


def as_float_array(value, name: str, *, allow_nan: bool = False) -> np.ndarray:
    """Convert ``value`` to a float64 array and check that it is finite.

    Parameters
    ----------
    value : array_like
        The user's input.
    name : str
        Name of the argument, used in the error message.
    allow_nan : bool
        Accept NaN and infinite entries.

    Returns
    -------
    ndarray
        ``value`` as a float64 array.
    """
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise TactsenseInputError(
            f"{name} must be numeric; got {type(value).__name__} ({error})"
        ) from None
    if not allow_nan and not np.all(np.isfinite(array)):
        bad = int(np.count_nonzero(~np.isfinite(array)))
        raise TactsenseInputError(
            f"{name} contains {bad} NaN or infinite value(s); expected finite numbers"
        )
    return array


def check_positive(value: float, name: str, *, allow_zero: bool = False) -> float:
    """Return ``value`` as float after checking it is finite and positive."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise TactsenseInputError(f"{name} must be a number; got {value!r}") from None
    if not np.isfinite(number) or number < 0 or (number == 0 and not allow_zero):
        expected = "non-negative" if allow_zero else "positive"
        raise TactsenseInputError(f"{name} must be a finite {expected} number; got {value!r}")
    return number


def check_choice(value: str, name: str, choices: Sequence[str]) -> str:
    """Return ``value`` after checking it is one of ``choices``."""
    if value not in choices:
        raise TactsenseInputError(
            f"{name} must be one of {', '.join(repr(c) for c in choices)}; got {value!r}"
        )
    return value


def check_poisson_ratio(value: float, name: str = "poisson_ratio") -> float:
    """Poisson's ratio of an isotropic solid lies in (-1, 0.5]."""
    number = float(value)
    if not (-1.0 < number <= 0.5):
        raise TactsenseInputError(f"{name} must lie in (-1, 0.5]; got {value!r}")
    return number


def check_frames(frames, shape: tuple[int, int], name: str = "frames") -> np.ndarray:
    """Check that ``frames`` has trailing dimensions ``(rows, cols)``.

    Parameters
    ----------
    frames : array_like, shape (..., rows, cols)
    shape : (int, int)
        Expected ``(rows, cols)`` of the wired array.
    """
    array = np.asarray(frames)
    if array.ndim < 2 or tuple(array.shape[-2:]) != tuple(shape):
        raise TactsenseInputError(
            f"{name} has shape {array.shape}; expected (..., {shape[0]}, {shape[1]}) "
            "= (..., rows, cols) of the wired array"
        )
    return array

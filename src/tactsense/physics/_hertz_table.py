"""A layer's taxel response to round contacts, tabulated once and kept separable.

What a taxel of a flat layer kind reads under one round contact of force F [N] and
pressure radius a [mm] centred (dx, dy) [mm] from the taxel's centre is
``F G(a; dx, dy)``: the compressive strain ``-eps_zz`` at the sensing depth averaged over
the taxel's electrode, per newton. The layer is linear and the same everywhere, so ``G``
is all a pad needs; it is even in dx and in dy (a rectangular electrode).

``G`` is computed here for a Hertz pressure ``p0 sqrt(1 - r^2/a^2)`` (a sphere) or a
uniform one (a disc) on a grid of a from 0 to the largest needed, by the bonded layer's
closed-form transfer function (:func:`tactsense.physics.pad_response.strain_transfer`)
times the pressure's exact Fourier transform (``3 (sin ka - ka cos ka) / (ka)^3`` for
Hertz, ``2 J1(ka) / ka`` for a disc, each times F) and the electrode's (a product of
sincs), on a periodic grid much larger than the response's reach (the field of a layer
bonded to a rigid base dies out exponentially, about e-fold per 1.2 layer thicknesses).
No pressure is sampled: the only grid is the offsets'.

The table is then factored (SVD of the (a, dx) x dy matrix) into
``G(a; dx, dy) = sum_r U_r(a, dx) V_r(dy)`` with as few terms as keep the largest error
under :data:`RANK_TOLERANCE` of the peak (six for the built-in pads): a frame is then an
outer product per contact, ``sum_r (F U_r(a, x_i - x_c)) V_r(y_j - y_c)``, interpolated
linearly in a and by cubics in dx, dy.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import math
import os
import sys
import tempfile
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import special

from tactsense.sensor import Layer

RANK_TOLERANCE = 2e-5
"""Largest error of the factored table against the full one, relative to its peak [-]."""

REACH_TOLERANCE = 1e-5
"""The table ends where ``|G|`` stays below this share of its peak beyond [-]."""

SHAPES = ("sphere", "disc")


@dataclass(frozen=True, eq=False)
class SeparableResponse:
    """``G(a; dx, dy) = sum_r x_factors[a_index, dx_index, r] * y_factors[dy_index, r]``.

    ``x_factors`` (n_a, n_x, R) at a = ``a_step_mm * a_index``, |dx| = ``step_mm *
    dx_index``; ``y_factors`` (n_y, R) at |dy| = ``step_mm * dy_index``; zero beyond
    the last index (the reach) [strain per newton: 1/N].
    """

    x_factors: np.ndarray
    y_factors: np.ndarray
    step_mm: float
    a_step_mm: float
    peak: float
    rank_error: float

    @property
    def a_top_mm(self) -> float:
        """Largest pressure radius tabulated [mm]."""
        return self.a_step_mm * (self.x_factors.shape[0] - 1)

    @functools.cached_property
    def padded_x(self) -> np.ndarray:
        """``x_factors`` padded for cubic interpolation along dx, (n_a, n_x + 3, R): the
        mirror of sample 1 first (the factors are even in dx), two zeros last."""
        f = self.x_factors
        zeros = np.zeros((f.shape[0], 2, f.shape[2]))
        return np.ascontiguousarray(np.concatenate([f[:, 1:2], f, zeros], axis=1))

    @functools.cached_property
    def padded_y(self) -> np.ndarray:
        """``y_factors`` padded alike, (n_y + 3, R)."""
        f = self.y_factors
        return np.ascontiguousarray(np.concatenate([f[1:2], f, np.zeros((2, f.shape[1]))]))

    def full(self, a_index: int) -> np.ndarray:
        """``G`` at one tabulated a over the quadrant dx, dy >= 0, (n_x, n_y) [1/N]."""
        return self.x_factors[a_index] @ self.y_factors.T


def pressure_transform(shape: str, ka: np.ndarray) -> np.ndarray:
    """Fourier transform of a round pressure of unit force at ``ka`` = wavenumber [rad/mm]
    times radius [mm] [-]: Hertz's ``3 (sin x - x cos x) / x^3`` or the disc's
    ``2 J1(x) / x``; 1 at x = 0."""
    x = np.asarray(ka, dtype=float)
    small = x < 1e-3
    safe = np.where(small, 1.0, x)
    if shape == "sphere":
        exact = 3.0 * (np.sin(safe) - safe * np.cos(safe)) / safe**3
        series = 1.0 - x**2 / 10.0
    else:
        exact = 2.0 * special.j1(safe) / safe
        series = 1.0 - x**2 / 8.0
    return np.where(small, series, exact)


def table_step_mm(layer: Layer, electrode_mm: tuple[float, float]) -> float:
    """Offset step of the table [mm]: a twentieth of the smallest of the electrode, the
    layer's thickness and the sensing depth (the narrowest feature of ``G``), at most
    0.1 mm (interpolated by cubics, a step of 0.1 mm is within 2e-5 of the peak on the
    built-in pads; tests/simulate/test_contact_frames.py checks the result against the
    exact solution)."""
    sizes = [*electrode_mm, layer.thickness_mm]
    if layer.sensing_depth_mm > 0:
        sizes.append(layer.sensing_depth_mm)
    return min(0.1, min(sizes) / 20.0)


A_STEP_MM = 0.05
"""Step of the table in the pressure radius a [mm]."""

A_TOP_LIMIT_MM = 5.0
"""Largest pressure radius a table covers [mm] (its memory grows with the square of its
reach): a batch with a larger contact runs the kind's reference path."""


def _spectrum(layer, electrode_mm, step, n):
    """The strain's transfer times the electrode's on an n x n periodic grid of ``step``
    [mm] (the half plane of ``rfft2``), and |k| [rad/mm] there."""
    from tactsense.physics.pad_response import strain_transfer

    fx = np.fft.fftfreq(n, d=step)[:, None]  # [cycles/mm]
    fy = np.fft.rfftfreq(n, d=step)[None, :]
    transfer = strain_transfer(fx, fy, layer.sensing_depth_mm, layer)  # [1/Pa]
    transfer = transfer * np.sinc(fx * electrode_mm[0]) * np.sinc(fy * electrode_mm[1])
    return transfer, 2.0 * np.pi * np.hypot(fx, fy)


def _quadrant(transfer, k, shape, a, step, n, size):
    """``G`` over the quadrant dx, dy in [0, size * step) for one a, (size, size) [1/N]."""
    spectrum = transfer * pressure_transform(shape, k * a)  # [m^2] for 1 N
    field = np.fft.irfft2(spectrum, s=(n, n)) / (step * 1e-3) ** 2
    return -field[:size, :size]  # compressive strain per newton


@functools.lru_cache(maxsize=16)
def layer_response_table(
    layer: Layer,
    electrode_mm: tuple[float, float],
    shape: str,
    a_top_mm: float,
    a_step_mm: float | None = None,
) -> SeparableResponse:
    """The separable table of ``G`` for a layer, an electrode (x, y) [mm] and a contact
    shape (``"sphere"``: Hertz; ``"disc"``: uniform), for pressure radii 0 to at least
    ``a_top_mm`` [mm] every ``a_step_mm`` [mm] (default :data:`A_STEP_MM`; cached per
    process)."""
    a_step = A_STEP_MM if a_step_mm is None else float(a_step_mm)
    from scipy.fft import next_fast_len

    step = table_step_mm(layer, electrode_mm)
    n_a = max(2, math.ceil(a_top_mm / a_step - 1e-9) + 1)
    a_values = a_step * np.arange(n_a)
    # a quadrant wide enough for the field to die out (about e-fold per 1.2 layer
    # thicknesses); the periodic images then lie beyond it as well
    trial = math.ceil((18.0 * layer.thickness_mm + max(electrode_mm) + a_values[-1]) / step)
    n = next_fast_len(2 * trial)
    transfer, k = _spectrum(layer, electrode_mm, step, n)
    # the reach from the smallest and the largest pressure (the field widens with a)
    ends = np.stack([_quadrant(transfer, k, shape, a, step, n, trial) for a in a_values[[0, -1]]])
    peak = float(np.abs(ends).max())
    beyond = np.maximum(np.abs(ends).max(axis=(0, 2)), np.abs(ends).max(axis=(0, 1)))
    tail = np.maximum.accumulate(beyond[::-1])[::-1]
    size = int(np.argmax(tail < REACH_TOLERANCE * peak)) or trial
    size = min(trial, size + 2)
    # the table itself on the smallest periodic grid whose images lie beyond the reach
    # (twice the reach and a margin: the images add under 1e-5 of the peak), a third to a
    # quarter of the first one's side: the build is that much faster
    small = next_fast_len(2 * size + 16)
    if small < n:
        n = small
        transfer, k = _spectrum(layer, electrode_mm, step, n)
    grid = np.stack([_quadrant(transfer, k, shape, a, step, n, size) for a in a_values])
    peak = float(np.abs(grid).max())
    grid[:, -1, :] = 0.0  # zero at the reach: the interpolation falls to it
    grid[:, :, -1] = 0.0
    matrix = grid.reshape(n_a * size, size)
    # the dy basis: eigenvectors of the Gram matrix, largest first (its singular values
    # squared; the terms kept are far above the round-off of the squares)
    _, vectors = np.linalg.eigh(matrix.T @ matrix)
    basis = vectors[:, ::-1]
    # the residual after each term, one rank-one update at a time (the same numbers as
    # refactoring at every rank, a fraction of the work)
    residual = matrix.copy()
    columns = []
    for rank in range(1, size + 1):
        column = matrix @ basis[:, rank - 1]
        columns.append(column)
        residual -= np.outer(column, basis[:, rank - 1])
        error = float(np.abs(residual).max())
        if error <= RANK_TOLERANCE * peak:
            break
    y_factors = np.ascontiguousarray(basis[:, :rank])
    x_factors = np.ascontiguousarray(np.stack(columns, axis=1).reshape(n_a, size, rank))
    return SeparableResponse(x_factors, y_factors, step, a_step, peak, error / peak)


# ---- the tables kept on disk (r9-fastpath) ----
class TableCacheWarning(UserWarning):
    """A table file in the cache could not be read (corrupt or truncated): rebuilt."""


TABLE_FIELDS = ("x_factors", "y_factors", "step_mm", "a_step_mm", "peak", "rank_error")


def table_cache_folder() -> Path:
    """Where the tables are kept between runs: ``$TACTSENSE_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/tactsense``, else ``~/.cache/tactsense`` (as the joint fit's)."""
    if os.environ.get("TACTSENSE_CACHE_DIR"):
        return Path(os.environ["TACTSENSE_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "tactsense"


@functools.lru_cache(maxsize=1)
def _code_digest() -> str | None:
    """Digest of the code a table comes from (this module, the strain transfer and the
    layer's transfer functions): a change of it makes new tables; None where the source
    cannot be read (no disk cache then)."""
    from tactsense.physics import layer, pad_response

    try:
        here = sys.modules[__name__]
        text = "".join(inspect.getsource(m) for m in (here, pad_response, layer))
    except (OSError, TypeError):
        return None
    return hashlib.sha256(text.encode()).hexdigest()


def table_cache_path(
    layer: Layer, electrode_mm, shape: str, a_top_mm: float, a_step_mm
) -> Path | None:
    """The file a table is kept in: named by a digest of everything it depends on (the
    layer, the electrode [mm], the shape, the radii [mm] and the code); None: no cache."""
    code = _code_digest()
    if code is None:
        return None
    a_step = A_STEP_MM if a_step_mm is None else float(a_step_mm)
    key = repr((layer, tuple(float(e) for e in electrode_mm), shape, float(a_top_mm), a_step))
    digest = hashlib.sha256((key + code).encode()).hexdigest()[:32]
    return table_cache_folder() / f"frames_table_{digest}.npz"


def _read_table(path: Path) -> SeparableResponse | None:
    """The table stored at ``path``; None if there is none; a corrupt file: None and a
    :class:`TableCacheWarning` (it is rebuilt and replaced)."""
    if not path.exists():
        return None
    try:
        with np.load(path) as stored:
            values = {f: stored[f] if stored[f].ndim else float(stored[f]) for f in TABLE_FIELDS}
        table = SeparableResponse(**values)
        if table.x_factors.ndim != 3 or table.y_factors.ndim != 2:
            raise ValueError("factors of the wrong rank")
        if table.x_factors.shape[2] != table.y_factors.shape[1]:
            raise ValueError("factors of different ranks")
        if not (np.all(np.isfinite(table.x_factors)) and np.all(np.isfinite(table.y_factors))):
            raise ValueError("factors not finite")
        return table
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as error:
        warnings.warn(
            f"table cache file {path} unreadable ({type(error).__name__}: {error}); rebuilding it",
            TableCacheWarning,
            stacklevel=3,
        )
        return None


@functools.lru_cache(maxsize=16)
def cached_response_table(
    layer: Layer,
    electrode_mm: tuple[float, float],
    shape: str,
    a_top_mm: float,
    a_step_mm: float | None = None,
) -> SeparableResponse:
    """:func:`layer_response_table`, kept on disk (:func:`table_cache_folder`) by a
    digest of its inputs and code (:func:`table_cache_path`) and in the process: the
    first run builds it (seconds), later runs read it (milliseconds). The file is written
    under a temporary name and moved into place (an interrupted write leaves no table); a
    folder that cannot be written is no error (the table is then built every run); a
    corrupt file is rebuilt with a :class:`TableCacheWarning`."""
    path = table_cache_path(layer, electrode_mm, shape, a_top_mm, a_step_mm)
    table = None if path is None else _read_table(path)
    if table is not None:
        return table
    table = layer_response_table(layer, electrode_mm, shape, a_top_mm, a_step_mm)
    if path is None:
        return table
    partial = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, suffix=".part", delete=False) as f:
            partial = f.name
            np.savez(f, **{name: getattr(table, name) for name in TABLE_FIELDS})
        os.replace(partial, path)
        partial = None
    except OSError:
        pass
    finally:  # an error or a Ctrl-C during the write leaves no partial file
        if partial is not None:
            Path(partial).unlink(missing_ok=True)
    return table


# ---- /r9-fastpath ----

"""The pad's fast forward for ``frames_from_contacts``: round contacts to taxel strain.

Each contact adds ``F G(a; x_i - x_c, y_j - y_c)`` to taxel (i, j), ``G`` the layer's
separable table (:mod:`tactsense.physics._hertz_table`): per contact and term r of the
table, a row vector ``F U_r(a, x_i - x_c)`` (linear in a and in |dx|) and a column vector
``V_r(y_j - y_c)`` (linear in |dy|), added as their outer product. The loop is compiled
(Numba); the same sum is an ``einsum`` of gathered factors in any array library
(:func:`superpose_array`, the check of the compiled loop and the route for an array-API
backend).
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit
from tactsense.physics._hertz_table import (
    A_TOP_LIMIT_MM,
    SeparableResponse,
    cached_response_table,
    pressure_transform,
    table_step_mm,
)

A_TOP_GRAIN_MM = 0.5
"""The tables are built for pressure radii up to a multiple of this [mm] (a batch with a
slightly larger contact reuses the table of the next multiple)."""


@jit(inline="always")
def _cubic_weights(w):
    """Lagrange weights of the four samples at -1, 0, 1, 2 for a point w in [0, 1)."""
    return (
        -w * (w - 1.0) * (w - 2.0) / 6.0,
        (w + 1.0) * (w - 1.0) * (w - 2.0) / 2.0,
        -(w + 1.0) * w * (w - 2.0) / 2.0,
        (w + 1.0) * w * (w - 1.0) / 6.0,
    )


@jit(fastmath=True)
def superpose(x_taxel, y_taxel, position, force, radius, x_factors, y_factors, step, a_step, out):
    """Add every contact's response to ``out`` (n, rows, cols) [force times 1/N].

    Parameters
    ----------
    x_taxel, y_taxel : float64 (rows,), (cols,)
        Taxel centres along x (rows) and y (columns) [mm].
    position : float64 (n, k, 2)
        Contact centres [mm].
    force : float64 (n, k)
        Normal forces [N] (times any scale); 0: no contact.
    radius : float64 (n, k)
        Pressure radius a of each contact [mm], at most the table's top.
    x_factors, y_factors : (n_a, n_x + 3, R), (n_y + 3, R), float32 or float64
        The table's factors padded for cubic interpolation
        (:meth:`~tactsense.physics._hertz_table.SeparableResponse.padded_x`): sample 0
        is the mirror of sample 2 (the factors are even), the last two are zero. The
        sums are carried in their precision (float32: 1e-7 of the peak).
    step, a_step : float
        The table's steps in offset and in pressure radius [mm].
    out : (n, rows, cols) array of the factors' type
    """
    n, k = force.shape
    n_a, n_x, terms = x_factors.shape
    n_y = y_factors.shape[0]
    rows, cols = x_taxel.size, y_taxel.size
    ux = np.empty((rows, terms), dtype=x_factors.dtype)
    vy = np.empty((terms, cols), dtype=x_factors.dtype)
    for p in range(n):
        frame = out[p]
        for c in range(k):
            f = force[p, c]
            if f <= 0.0:
                continue
            t = radius[p, c] / a_step
            ia = min(int(t), n_a - 2)
            wa = min(t - ia, 1.0)
            low, high = f * (1.0 - wa), f * wa  # linear in a, the force folded in
            below, above = x_factors[ia], x_factors[ia + 1]
            for i in range(rows):
                d = abs(x_taxel[i] - position[p, c, 0]) / step
                ix = int(d)
                if ix >= n_x - 3:
                    ux[i, :] = 0.0
                    continue
                w0, w1, w2, w3 = _cubic_weights(d - ix)
                for r in range(terms):
                    ux[i, r] = low * (
                        w0 * below[ix, r]
                        + w1 * below[ix + 1, r]
                        + w2 * below[ix + 2, r]
                        + w3 * below[ix + 3, r]
                    ) + high * (
                        w0 * above[ix, r]
                        + w1 * above[ix + 1, r]
                        + w2 * above[ix + 2, r]
                        + w3 * above[ix + 3, r]
                    )
            for j in range(cols):
                d = abs(y_taxel[j] - position[p, c, 1]) / step
                iy = int(d)
                if iy >= n_y - 3:
                    vy[:, j] = 0.0
                    continue
                w0, w1, w2, w3 = _cubic_weights(d - iy)
                for r in range(terms):
                    vy[r, j] = (
                        w0 * y_factors[iy, r]
                        + w1 * y_factors[iy + 1, r]
                        + w2 * y_factors[iy + 2, r]
                        + w3 * y_factors[iy + 3, r]
                    )
            for i in range(rows):
                row = frame[i]
                for r in range(terms):
                    u = ux[i, r]
                    if u == 0.0:
                        continue
                    for j in range(cols):
                        row[j] += u * vy[r, j]


def _lerp_index(distance, step, size):
    """Index, weight and inside-mask of a linear interpolation at ``|distance| / step``."""
    d = np.abs(distance) / step
    index = np.minimum(d.astype(np.int64), size - 2)
    inside = d < size - 1
    return index, d - index, inside


def superpose_array(x_taxel, y_taxel, position, force, radius, table: SeparableResponse):
    """:func:`superpose` as whole-array operations (gathers and one ``einsum``), (n, rows,
    cols) [-]: the same numbers to round-off; written so that an array-API library (CuPy,
    JAX) could run it with its own ``take`` and ``einsum``."""
    xf, yf = table.x_factors, table.y_factors
    n_a, n_x, _ = xf.shape
    t = radius / table.a_step_mm
    ia = np.minimum(t.astype(np.int64), n_a - 2)
    wa = np.minimum(t - ia, 1.0)[..., None, None]
    ix, wx, in_x = _lerp_index(x_taxel[None, None, :] - position[..., :1], table.step_mm, n_x)
    iy, wy, in_y = _lerp_index(y_taxel[None, None, :] - position[..., 1:], table.step_mm, len(yf))
    ia_ = ia[..., None]

    def at(a_index, x_index):  # (n, k, rows, terms)
        return xf[a_index, x_index]

    lo = at(ia_, ix) + wa * (at(ia_ + 1, ix) - at(ia_, ix))
    hi = at(ia_, ix + 1) + wa * (at(ia_ + 1, ix + 1) - at(ia_, ix + 1))
    u = (lo + wx[..., None] * (hi - lo)) * (in_x[..., None] * force[..., None, None])
    v = (yf[iy] + wy[..., None] * (yf[iy + 1] - yf[iy])) * in_y[..., None]
    return np.einsum("nkir,nkjr->nij", u, v)


WIDE_GRID_TERMS = 2048
"""Most wavenumbers per axis of :class:`WideContacts`' cosine sums [-] (memory and work
bounded: 2,049^2 terms, 34 MB): a contact whose sum would need more (a pressure radius
of metres) runs the kind's reference path, with a warning."""


class WideContacts:
    """Contacts wider than the tables (pressure radius above
    :data:`~tactsense.physics._hertz_table.A_TOP_LIMIT_MM`), one at a time: every taxel's
    compressive strain per newton as the cosine series of the layer's periodic field,
    ``G(dx, dy) = -1/(Lx Ly) sum_(m, n) T(k) E(k) P(|k| a) cos(kx dx) cos(ky dy)``
    (``T`` the bonded layer's strain transfer, ``E`` the electrode's sincs, ``P`` the
    pressure's exact transform, as the tables use; the field is even in dx and in dy).

    The period ``L`` along each axis is the pad's extent plus twice the contact's
    radius and ten layer thicknesses and the electrode, so the periodic images lie
    beyond every taxel's reach (the field of a layer bonded to a rigid base dies out
    about e-fold per 1.2 thicknesses); the wavenumbers stop at ``pi / h``, ``h`` = 5
    tables' steps (a quarter of the narrowest of the electrode, the layer and the
    sensing depth), where ``T E`` has died out. Measured against the exact Hankel
    solution (tests/simulate/test_contact_frames_wide.py): within 1e-6 of the peak on
    pad4, pad16, pad12x32 and hand4's palm pad, where 8 steps give 1e-4 and 12 steps
    2e-3. No pressure is sampled and no table is stored: a contact costs a pressure
    transform on the wavenumber grid and two small matrix products (milliseconds); the
    grid is the same for every wide contact of a batch (sized for its widest).
    """

    def __init__(self, spec, x_taxel, y_taxel, electrode):
        self.layer = spec.layer
        self.x_taxel, self.y_taxel = x_taxel, y_taxel
        self.electrode = electrode
        self.step_mm = 5.0 * table_step_mm(self.layer, electrode)
        self.extent = (float(np.ptp(x_taxel)), float(np.ptp(y_taxel)))
        self._spectra = {}

    def reach_mm(self, a_mm: float) -> float:
        """Distance from a contact's centre beyond which it presses no taxel (as the
        tables take it: 18 layer thicknesses and the electrode beyond its edge) [mm]."""
        return float(a_mm) + 18.0 * self.layer.thickness_mm + max(self.electrode)

    def terms(self, a_mm: float) -> tuple[int, int]:
        """Wavenumbers per axis the sum takes for contacts up to radius ``a_mm`` [-]."""
        margin = float(a_mm) + 10.0 * self.layer.thickness_mm + max(self.electrode)
        return tuple(
            math.ceil((extent + 2.0 * margin) / (2.0 * self.step_mm)) for extent in self.extent
        )

    def takes(self, a_mm: float) -> bool:
        """Whether contacts up to radius ``a_mm`` [mm] stay within
        :data:`WIDE_GRID_TERMS` wavenumbers per axis."""
        return max(self.terms(a_mm)) <= WIDE_GRID_TERMS

    def _spectrum(self, terms: tuple[int, int]):
        """Frequencies [cycles/mm] along x and y, and ``T E`` times the cosine series'
        weights (1 at 0, 2 beyond) over their product [1/Pa]; kept per period."""
        if terms not in self._spectra:
            from tactsense.physics.pad_response import strain_transfer

            periods = [2.0 * self.step_mm * m for m in terms]
            fx, fy = (np.arange(m + 1) / period for m, period in zip(terms, periods, strict=True))
            transfer = strain_transfer(
                fx[:, None], fy[None, :], self.layer.sensing_depth_mm, self.layer
            )
            transfer = transfer * np.sinc(fx * self.electrode[0])[:, None]
            transfer = transfer * np.sinc(fy * self.electrode[1])[None, :]
            wx = np.where(fx == 0, 1.0, 2.0)[:, None]
            wy = np.where(fy == 0, 1.0, 2.0)[None, :]
            scale = 1e6 / (periods[0] * periods[1])  # 1/(Lx Ly) in 1/m^2
            k = 2.0 * np.pi * np.hypot(fx[:, None], fy[None, :])  # [rad/mm]
            if len(self._spectra) > 2:  # a few periods at once: memory bounded
                self._spectra.clear()
            self._spectra[terms] = (fx, fy, -scale * wx * wy * transfer, k)
        return self._spectra[terms]

    def add(self, frame, position_mm, force, a_mm, shape, terms) -> None:
        """Add one contact's strain (force times the field per newton) to ``frame``
        (rows, cols), on the wavenumber grid ``terms`` (:meth:`terms` of a radius at
        least ``a_mm``); a contact beyond every taxel's reach adds nothing."""
        dx = self.x_taxel - position_mm[0]
        dy = self.y_taxel - position_mm[1]
        reach = self.reach_mm(a_mm)
        if np.abs(dx).min() > reach or np.abs(dy).min() > reach:
            return
        fx, fy, weighted, k = self._spectrum(terms)
        spectrum = weighted * pressure_transform(shape, k * a_mm)
        cx = np.cos(2.0 * np.pi * np.outer(dx, fx))
        cy = np.cos(2.0 * np.pi * np.outer(fy, dy))
        frame += force * (cx @ spectrum @ cy)


class PadContactForward:
    """A pad's fast forward (``Kind.contact_forward``): the tabulated layer response.

    The layer is taken as unbounded around the pad (as the twin's own forward takes it
    within its margin), so a contact beside the pad still presses its edge taxels.
    Contacts of pressure radius up to :data:`~tactsense.physics._hertz_table.A_TOP_LIMIT_MM`
    are superposed from the tables; wider ones are summed one by one in the layer's
    spectrum (:class:`WideContacts`), equally exact and slower.
    """

    def __init__(self, spec):
        g = spec.grid
        self.spec = spec
        self.x_taxel = g.row_pitch_mm * np.arange(g.rows, dtype=float)
        self.y_taxel = g.col_pitch_mm * np.arange(g.cols, dtype=float)
        self.electrode = (float(g.electrode_x_mm), float(g.electrode_y_mm))
        t = spec.transduction
        self.scale = t.strain_gain if t.kind == "capacitive" else 1.0
        layer = spec.layer
        self.modulus_star_pa = layer.youngs_modulus_pa / (1.0 - layer.poisson_ratio**2)
        self.wide = WideContacts(spec, self.x_taxel, self.y_taxel, self.electrode)

    def table(self, shape: str, a_top_mm: float) -> SeparableResponse:
        """The layer's table for ``shape`` covering pressure radii up to ``a_top_mm``
        (kept on disk: :func:`~tactsense.physics._hertz_table.cached_response_table`)."""
        top = A_TOP_GRAIN_MM * max(1, math.ceil(a_top_mm / A_TOP_GRAIN_MM - 1e-9))
        return cached_response_table(self.spec.layer, self.electrode, shape, top)

    def prepare(self, contacts):
        """A function ``(first, last) -> (last - first, rows * cols)``: the fractional
        deflection [-] of every taxel (before gains; float32, 1e-7 of the peak) for
        those frames of ``contacts`` (a ContactBatch), with the tables its contacts up to
        :data:`~tactsense.physics._hertz_table.A_TOP_LIMIT_MM` need (chosen once, so a
        frame reads the same whatever block it is computed in) and the wider ones summed
        in the spectrum; None when a contact is too wide even for that
        (:data:`WIDE_GRID_TERMS`: the caller runs the reference path)."""
        radius = contacts.pressure_radius_mm(self.modulus_star_pa)
        touching = contacts.normal_force_n > 0
        wide = touching & (radius > A_TOP_LIMIT_MM)
        widest = float(np.max(radius[wide], initial=0.0))
        if not self.wide.takes(widest):
            return None
        terms = self.wide.terms(widest)
        narrow = touching & ~wide
        tables = {}
        for shape, chosen in contacts.shape_masks():
            mine = narrow if chosen is True else narrow & chosen
            if not np.any(mine):
                continue
            table = self.table(shape, float(np.max(radius[mine])))
            tables[shape] = (
                table,
                table.padded_x.astype(np.float32),
                table.padded_y.astype(np.float32),
            )
        rows, cols = self.x_taxel.size, self.y_taxel.size

        def block(first: int, last: int) -> np.ndarray:
            out = np.zeros((last - first, rows, cols), dtype=np.float32)
            position = np.ascontiguousarray(contacts.position_mm[first:last])
            force = np.where(narrow[first:last], contacts.normal_force_n[first:last], 0.0)
            force = force * self.scale
            for shape, chosen in contacts.shape_masks(first, last):
                if shape not in tables:
                    continue
                table, x_factors, y_factors = tables[shape]
                superpose(
                    self.x_taxel,
                    self.y_taxel,
                    position,
                    force if chosen is True else np.where(chosen, force, 0.0),
                    np.ascontiguousarray(radius[first:last]),
                    x_factors,
                    y_factors,
                    table.step_mm,
                    table.a_step_mm,
                    out,
                )
            for p, c in zip(*np.nonzero(wide[first:last]), strict=True):
                frame = np.zeros((rows, cols))
                shape = (
                    contacts.shape
                    if isinstance(contacts.shape, str)
                    else contacts.shape[first + p, c]
                )
                self.wide.add(
                    frame,
                    contacts.position_mm[first + p, c],
                    contacts.normal_force_n[first + p, c] * self.scale,
                    float(radius[first + p, c]),
                    str(shape),
                    terms,
                )
                out[p] += frame.astype(np.float32)
            return out.reshape(last - first, rows * cols)

        return block

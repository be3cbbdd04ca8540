"""Three-dimensional elastic layer bonded to a rigid base, solved in the wavenumber domain.

A linear elastic, isotropic, homogeneous layer of thickness h (Young's modulus E,
Poisson's ratio nu, shear modulus mu = E / 2(1 + nu)) is bonded to a rigid base at
z = h (u = v = w = 0 there) and loaded on its free surface z = 0 by a normal pressure
p(x, y) (pushing into the layer) and, optionally, tangential tractions q_x, q_y (the
force per area applied to the surface along +x, +y). z points into the layer, so a
pressure gives w > 0 and a compressive strain eps_zz < 0; ``thickness=np.inf`` is the
half space.

Derivation (``docs/model.md``, section 8): a Fourier mode ``exp(i k.x)`` of the load
separates into plane strain in the plane of (k, z), driven by the pressure P and the
traction along k, Q_L, and anti-plane shear driven by the traction across k, Q_T. With
the Papkovich-Neuber potentials ``psi_z = A exp(-kz) + B exp(-k(h-z))`` and
``phi = C exp(-kz) + D exp(-k(h-z))`` (the paper's eqs. 11-15 in three dimensions),

    2 mu w = kappa psi - z psi' - phi',      2 mu u_L = -i k (z psi + phi),
    sigma_zz = 2 nu psi' + 2 mu w',          kappa = 3 - 4 nu,

and the four conditions ``sigma_zz(0) = -P``, ``sigma_Lz(0) = -Q_L``, ``u_L(h) = w(h) = 0``
give A..D in closed form over the determinant

    Delta = kappa + (kappa^2 + 1 + 4 k^2 h^2) exp(-2kh) + kappa exp(-4kh).

Every exponent is non-positive for 0 <= z <= h, so nothing overflows at large kh, and
no 1/(1 - 2 nu) appears (the volumetric stress is 2 nu psi'), so nu = 0.5 is regular.
The anti-plane part is ``2 mu u_T = 2 Q_T sinh(k(h-z)) / (k cosh kh)``. For normal load
the transfer function of w is the plane-strain strip kernel of ``physics.strip`` at
k = |k| (a mode sees only its own plane); the half space is ``exp(-kh) = 0``:
``2 mu w = P (kz + 2(1 - nu)) exp(-kz) / k`` (Boussinesq).

A load sampled on a regular grid is zero-padded, transformed with ``scipy.fft.rfft2``,
multiplied by these transfer functions (precomputed once per grid, depth and layer in
:class:`LayerResponse`) and transformed back. The FFT is periodic; the padding makes
the period longer than the load plus the reach of the layer's response (10 h for a
bonded layer, whose response dies out over a few h; the whole grid again
for the half space, whose strains decay as 1 / r^3).

References
----------
.. [1] R. S. Fearing, "Tactile Sensing Mechanisms", IJRR 9(3), 1990, sections 4-5.
.. [2] G. M. L. Gladwell, *Contact Problems in the Classical Theory of Elasticity*, 1980.
.. [3] D. M. Burmister, "The general theory of stresses and displacements in layered
   systems", J. Appl. Phys. 16, 1945.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.fft

from tactsense._validation import (
    TactsenseInputError,
    as_float_array,
    check_positive,
)
from tactsense.physics.layer_transfer import (  # the transfer functions, re-exported here
    _check_layer,
    _half_space_k0,
    shear_modulus,
    transfer_functions,
)

QUANTITIES = ("u_x", "u_y", "u_z", "eps_xx", "eps_yy", "eps_zz", "eps_xy", "eps_xz", "eps_yz")
"""Fields :class:`LayerResponse` can return: displacements [m] and strain tensor components [-].

``eps_xy``, ``eps_xz``, ``eps_yz`` are tensor (not engineering) shear strains.
"""

REACH_IN_THICKNESSES = 10.0
"""Padding beyond the load, in layer thicknesses, that removes wrap-around (see module doc)."""


class LayerResponse:
    """Fields at one depth of a bonded layer under loads sampled on a regular grid.

    The transfer functions are computed once, on the zero-padded ``rfft2`` grid; a call
    then costs two real FFTs and one product per quantity.

    Parameters
    ----------
    shape : (int, int)
        ``(ny, nx)`` of the load grid (rows along y, columns along x).
    spacing : float or (float, float)
        Sample spacing ``(dy, dx)`` [m] (one number: both).
    depth : float
        z, 0 <= z <= thickness [m].
    thickness : float
        h [m]; ``np.inf`` for the half space.
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu, in (-1, 0.5] [-]; 0.5 (incompressible) is regular.
    quantities : sequence of str
        Names from :data:`QUANTITIES`.
    tangential : bool
        Accept tangential tractions (three inputs instead of one).
    padding : (int, int) or None
        Zero samples appended along y and x; None: the reach of the response
        (``REACH_IN_THICKNESSES * h``, at most 8 grids; one grid for the half space),
        rounded up to a fast size.
    electrode : (float, float) or None
        ``(ly, lx)`` [m]: average each field over a rectangle of this size centred on the
        output point (a ``sinc`` factor per axis); None: point values.
    shift : (float, float)
        Evaluate the fields at the sample positions plus ``(sy, sx)`` [m].
    multiple_of : int
        Make the automatic padded size a multiple of this (for :meth:`decimated`).
    precision : {"double", "single"}
        Floating-point precision of the transforms; "single" is faster and keeps about
        six significant digits of each field (relative to its largest value).
    """

    def __init__(
        self,
        shape,
        spacing,
        depth,
        *,
        thickness,
        youngs_modulus,
        poisson_ratio,
        quantities=("eps_zz",),
        tangential=False,
        padding=None,
        electrode=None,
        shift=(0.0, 0.0),
        multiple_of=1,
        precision="double",
    ):
        h, E, nu = _check_layer(thickness, youngs_modulus, poisson_ratio)
        ny, nx = (int(n) for n in shape)
        if ny < 1 or nx < 1 or (ny, nx) != tuple(shape):
            raise TactsenseInputError(f"shape must be two positive integers; got {shape!r}")
        dy, dx = np.broadcast_to(as_float_array(spacing, "spacing"), (2,))
        if dy <= 0 or dx <= 0:
            raise TactsenseInputError(f"spacing must be positive [m]; got {spacing!r}")
        depth = float(depth)
        if not (0 <= depth <= h):
            raise TactsenseInputError(
                f"depth must lie within the layer, 0 <= depth <= thickness; got {depth!r}"
            )
        quantities = tuple(quantities)
        for q in quantities:
            if q not in QUANTITIES:
                raise TactsenseInputError(
                    f"unknown quantity {q!r}; expected one of {', '.join(QUANTITIES)}"
                )
        multiple = int(multiple_of)
        if padding is None:
            reach_y, reach_x = ny, nx  # half space: strains decay as 1 / r^3
            if np.isfinite(h):
                reach_y = min(8 * ny, math.ceil(REACH_IN_THICKNESSES * h / dy))
                reach_x = min(8 * nx, math.ceil(REACH_IN_THICKNESSES * h / dx))
            my = multiple * scipy.fft.next_fast_len(-(-(ny + reach_y) // multiple), real=True)
            mx = multiple * scipy.fft.next_fast_len(-(-(nx + reach_x) // multiple), real=True)
        else:
            py, px = (int(p) for p in padding)
            if py < 0 or px < 0:
                raise TactsenseInputError(f"padding must be non-negative; got {padding!r}")
            my, mx = ny + py, nx + px
        self.shape, self.padded_shape = (ny, nx), (my, mx)
        self.spacing, self.depth, self.quantities = (float(dy), float(dx)), depth, quantities
        self.thickness, self.youngs_modulus, self.poisson_ratio = h, E, nu
        self.tangential = bool(tangential)
        mu = shear_modulus(E, nu)

        ky = 2 * np.pi * scipy.fft.fftfreq(my, dy)[:, None]
        kx = 2 * np.pi * scipy.fft.rfftfreq(mx, dx)[None, :]
        ky, kx = np.broadcast_arrays(ky, kx)
        k = np.hypot(kx, ky)
        at_zero = k == 0
        k_safe = np.where(at_zero, 1.0, k)
        tf = transfer_functions(k if np.isfinite(h) else k_safe, depth, h, nu)
        ex, ey = np.where(at_zero, 0.0, kx / k_safe), np.where(at_zero, 0.0, ky / k_safe)
        if not np.isfinite(h):
            for name, value in _half_space_k0(
                depth, nu, 2 * np.pi / (mx * dx), 2 * np.pi / (my * dy)
            ).items():
                tf[name] = np.where(at_zero, value, tf[name])
            for name in ("W_Q", "dW_Q", "U_P", "dU_P"):
                tf[name] = np.where(at_zero, 0.0, tf[name])
        # in-plane displacement operators: u = G_ux_P P + G_ux_qx qx + G_ux_qy qy (times 1/2mu)
        # directions at k = 0: e e^T -> I/2 (the average over the cell), e -> 0
        exx = np.where(at_zero, 0.5, ex * ex)
        eyy = np.where(at_zero, 0.5, ey * ey)
        exy = np.where(at_zero, 0.0, ex * ey)
        ops = {}
        for suffix, d in (("", ""), ("d", "d")):
            w_p, w_q = tf[d + "W_P"], tf[d + "W_Q"]
            u_p, u_q, tt = tf[d + "U_P"], tf[d + "U_Q"], tf[d + "T"]
            ops[suffix + "w"] = (w_p, w_q * ex, w_q * ey)
            ops[suffix + "u"] = (u_p * ex, u_q * exx + tt * eyy, (u_q - tt) * exy)
            ops[suffix + "v"] = (u_p * ey, (u_q - tt) * exy, u_q * eyy + tt * exx)
        ikx, iky = 1j * kx, 1j * ky
        fields = {
            "u_x": ops["u"],
            "u_y": ops["v"],
            "u_z": ops["w"],
            "eps_xx": tuple(ikx * g for g in ops["u"]),
            "eps_yy": tuple(iky * g for g in ops["v"]),
            "eps_zz": ops["dw"],
            "eps_xy": tuple(
                0.5 * (iky * a + ikx * b) for a, b in zip(ops["u"], ops["v"], strict=True)
            ),
            "eps_xz": tuple(0.5 * (a + ikx * b) for a, b in zip(ops["du"], ops["w"], strict=True)),
            "eps_yz": tuple(0.5 * (a + iky * b) for a, b in zip(ops["dv"], ops["w"], strict=True)),
        }
        factor = 1.0 / (2 * mu)
        if electrode is not None:
            ly, lx = (check_positive(v, "electrode size", allow_zero=True) for v in electrode)
            factor = factor * np.sinc(kx * lx / (2 * np.pi)) * np.sinc(ky * ly / (2 * np.pi))
        sy, sx = (float(s) for s in shift)
        if sx or sy:
            factor = factor * np.exp(1j * (kx * sx + ky * sy))
        if precision not in ("double", "single"):
            raise TactsenseInputError(f"precision must be 'double' or 'single'; got {precision!r}")
        self._real = np.float32 if precision == "single" else np.float64
        self._kernels = []
        for q in quantities:
            parts = fields[q] if self.tangential else fields[q][:1]
            parts = [np.broadcast_to(p * factor, k.shape) for p in parts]
            parts = [p.real if not np.any(p.imag) else p for p in parts]
            complex_type = np.complex64 if precision == "single" else np.complex128
            parts = [p.astype(self._real if p.dtype.kind == "f" else complex_type) for p in parts]
            self._kernels.append(parts)

    def _spectra(self, pressure, traction_x, traction_y):
        loads = [_check_load(pressure, self.shape, "pressure")]
        if traction_x is not None or traction_y is not None:
            if not self.tangential:
                raise TactsenseInputError(
                    "tangential tractions need a LayerResponse built with tangential=True"
                )
            for t, name in ((traction_x, "traction_x"), (traction_y, "traction_y")):
                loads.append(None if t is None else _check_load(t, self.shape, name))
        loads = [None if a is None else a.astype(self._real, copy=False) for a in loads]
        spectra = [
            None if a is None else scipy.fft.rfft2(a, s=self.padded_shape, workers=1) for a in loads
        ]
        for parts in self._kernels:
            total = None
            for spectrum, kernel in zip(spectra, parts, strict=False):
                if spectrum is not None:
                    term = spectrum * kernel
                    total = term if total is None else total + term
            yield total

    def decimated(self, step, pressure, traction_x=None, traction_y=None):
        """Fields at every ``step``-th sample along both axes, from a folded spectrum.

        Sampling every ``step``-th point of the periodic field is the inverse FFT of the
        spectrum folded ``step`` times along y, so the inverse transform along y is
        ``step`` times shorter and the one along x runs on ``1/step`` of the rows.

        Parameters
        ----------
        step : int
            Must divide both padded sizes (``multiple_of`` at construction).
        pressure, traction_x, traction_y
            As in :meth:`__call__`.

        Returns
        -------
        dict of ndarray
            Shape (..., ceil(ny / step), ceil(nx / step)): samples 0, step, 2 step, ...
        """
        my, mx = self.padded_shape
        if my % step or mx % step:
            raise TactsenseInputError(
                f"step {step} must divide the padded shape {self.padded_shape}"
            )
        ny, nx = self.shape
        out = {}
        for q, total in zip(
            self.quantities, self._spectra(pressure, traction_x, traction_y), strict=True
        ):
            kx = total.shape[-1]
            folded = total.reshape(*total.shape[:-2], step, my // step, kx).sum(-3)
            rows = scipy.fft.ifft(folded, axis=-2, workers=1)[..., : -(-ny // step), :]
            # the full spectrum along x (Hermitian), folded in turn
            full = np.concatenate([rows, np.conj(rows[..., 1 : mx - kx + 1][..., ::-1])], -1)
            folded = full.reshape(*full.shape[:-1], step, mx // step).sum(-2)
            field = scipy.fft.ifft(folded, axis=-1, workers=1).real / (step * step)
            out[q] = field[..., : -(-nx // step)]
        return out

    def __call__(self, pressure, traction_x=None, traction_y=None):
        """Fields under the load.

        Parameters
        ----------
        pressure : array_like, shape (..., ny, nx)
            p [Pa], pushing into the layer; leading axes are frames.
        traction_x, traction_y : array_like, shape (..., ny, nx), optional
            q_x, q_y [Pa] on the surface (needs ``tangential=True``); None: zero.

        Returns
        -------
        dict of ndarray
            One array of shape (..., ny, nx) per quantity, at the sample positions.
        """
        ny, nx = self.shape
        out = {}
        for q, total in zip(
            self.quantities, self._spectra(pressure, traction_x, traction_y), strict=True
        ):
            field = scipy.fft.irfft2(total, s=self.padded_shape, workers=1)
            out[q] = field[..., :ny, :nx]
        return out


def _check_load(load, shape, name):
    array = as_float_array(load, name)
    if array.ndim < 2 or tuple(array.shape[-2:]) != tuple(shape):
        raise TactsenseInputError(
            f"{name} has shape {array.shape}; "
            f"expected (..., {shape[0]}, {shape[1]}) = (..., ny, nx)"
        )
    return array


@functools.lru_cache(maxsize=32)
def _cached_response(*args, **kwargs):
    return LayerResponse(*args, **kwargs)


def layer_response(
    pressure,
    spacing,
    depth,
    *,
    thickness,
    youngs_modulus,
    poisson_ratio,
    quantities=("eps_zz",),
    traction_x=None,
    traction_y=None,
):
    """Fields at ``depth`` under a sampled load (a cached :class:`LayerResponse`).

    Parameters
    ----------
    pressure : array_like, shape (..., ny, nx)
        p [Pa] on a regular grid of ``spacing`` [m] (one number or ``(dy, dx)``).
    depth, thickness : float
        z and h [m] (h = ``np.inf``: half space).
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu [-].
    quantities : sequence of str
        From :data:`QUANTITIES`.
    traction_x, traction_y : array_like, optional
        Tangential tractions [Pa].

    Returns
    -------
    dict of ndarray
        Each quantity, shape (..., ny, nx).
    """
    shape = np.shape(pressure)
    if len(shape) < 2:
        raise TactsenseInputError(
            f"pressure has shape {shape}; expected (..., ny, nx) samples on a regular grid"
        )
    shape = shape[-2:]
    spacing = tuple(np.broadcast_to(np.asarray(spacing, dtype=float), (2,)).tolist())
    response = _cached_response(
        tuple(shape),
        spacing,
        float(depth),
        thickness=float(thickness),
        youngs_modulus=float(youngs_modulus),
        poisson_ratio=float(poisson_ratio),
        quantities=tuple(quantities),
        tangential=traction_x is not None or traction_y is not None,
    )
    return response(pressure, traction_x, traction_y)


class TaxelPad:
    """Readings of a rectangular grid of taxels: a field averaged over each electrode.

    The load is sampled on a fine grid of ``subsamples`` points per pitch covering the
    pad: sample ``(i, j)`` sits at ``((i + 1/2) dy, (j + 1/2) dx)`` with ``d = pitch /
    subsamples``, and taxel ``(r, c)`` is centred at ``((r + 1/2) pitch_y, (c + 1/2)
    pitch_x)``. Its reading is the field at its depth averaged over its electrode (a
    rectangle ``ly x lx``), computed exactly for the sampled load in the wavenumber
    domain (sinc factors and a phase shift to the taxel centres), and only at the taxel
    centres (:meth:`LayerResponse.decimated`).

    Parameters
    ----------
    rows, cols : int
        Taxels along y and x.
    pitch : float or (float, float)
        ``(pitch_y, pitch_x)`` [m].
    electrode : float or (float, float)
        ``(ly, lx)`` [m]; 0: point readings.
    depth : float
        Depth of the sensing element [m].
    thickness, youngs_modulus, poisson_ratio
        The layer, as in :class:`LayerResponse`.
    subsamples : int
        Load samples per pitch along each axis.
    quantity : str
        From :data:`QUANTITIES` (default ``eps_zz``).
    padding, precision
        As in :class:`LayerResponse`.
    """

    def __init__(
        self,
        rows,
        cols,
        pitch,
        electrode,
        depth,
        *,
        thickness,
        youngs_modulus,
        poisson_ratio,
        subsamples=4,
        quantity="eps_zz",
        padding=None,
        precision="double",
    ):
        rows, cols, n = int(rows), int(cols), int(subsamples)
        if rows < 1 or cols < 1 or n < 1:
            raise TactsenseInputError("rows, cols and subsamples must be positive integers")
        py, px = np.broadcast_to(as_float_array(pitch, "pitch"), (2,))
        ly, lx = np.broadcast_to(as_float_array(electrode, "electrode"), (2,))
        if py <= 0 or px <= 0:
            raise TactsenseInputError(f"pitch must be positive [m]; got {pitch!r}")
        if ly < 0 or lx < 0 or ly > py or lx > px:
            raise TactsenseInputError(
                f"electrode must lie within one pitch, 0 <= size <= pitch [m]; got {electrode!r}"
            )
        self.rows, self.cols, self.subsamples = rows, cols, n
        self.pitch, self.electrode = (float(py), float(px)), (float(ly), float(lx))
        self.spacing = (py / n, px / n)
        self.grid_shape = (rows * n, cols * n)
        # taxel centres lie (n - 1) / 2 samples after samples 0, n, 2n, ...
        offset = (n - 1) / 2 * np.array(self.spacing)
        self.response = LayerResponse(
            self.grid_shape,
            self.spacing,
            depth,
            thickness=thickness,
            youngs_modulus=youngs_modulus,
            poisson_ratio=poisson_ratio,
            quantities=(quantity,),
            electrode=(ly, lx),
            shift=tuple(offset),
            padding=padding,
            multiple_of=n,
            precision=precision,
        )
        self.quantity = quantity

    def sample_positions(self):
        """``(y, x)`` [m] of the load samples: 1-D arrays of ``grid_shape``."""
        (dy, dx), (ny, nx) = self.spacing, self.grid_shape
        return (np.arange(ny) + 0.5) * dy, (np.arange(nx) + 0.5) * dx

    def taxel_centres(self):
        """``(y, x)`` [m] of the taxel centres: 1-D arrays of rows and cols."""
        return (np.arange(self.rows) + 0.5) * self.pitch[0], (
            np.arange(self.cols) + 0.5
        ) * self.pitch[1]

    def __call__(self, pressure):
        """Taxel readings [-] (strain) for pressure maps of shape (..., rows*n, cols*n) [Pa]."""
        return self.response.decimated(self.subsamples, pressure)[self.quantity]

"""What a pad can see: the Cramer-Rao bound for a probe at a point, and its blind spots.

Both start from the pad's noiseless reading of a sphere probe,
:func:`expected_counts`: the layer model of the simulator
(:func:`tactsense.physics.pad_response.pad_strain`) and its transducer (eqs. 1-2 for a
capacitive pad, the linear gain of a resistive one), every taxel at gain 1, without
noise, quantization, creep or jitter (the design, not one specimen of it).

* :func:`cramer_rao_bound`: the smallest standard deviations of ``(x, y, F)`` any
  unbiased estimator reaches from one frame, with each taxel's reading carrying
  independent noise of variance ``read_noise^2 + 1/12`` counts^2 (read noise and
  quantization as uniform rounding), as :mod:`tactsense.analysis.bound` does for the
  finger: ``J = G^T G / sigma^2`` with ``G`` the readings' derivatives by central
  differences.
* :func:`blind_spots`: where on the pad a probe moves no taxel's reading by more than
  a threshold (three times that noise by default): the places the pad does not see.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.kinds import kind_of
from tactsense.physics.indenters import SphereProbe, pressure_map
from tactsense.physics.pad_response import modulus_star_pa, pad_strain, strain_map
from tactsense.physics.transduction import amplifier_gain, divider_voltage, voltage_to_counts

PARAMETERS = ("x_mm", "y_mm", "force_n")
PROBE_RADIUS_MM = 1.6
"""The paper's probe: a 3.2-mm hemisphere (section 3) [mm]."""
RANK_TOLERANCE = 1e-6
"""Smallest singular value of the scaled whitened Jacobian over its largest below which
the Fisher matrix is called singular [-] (eigenvalue ratio 1e-12): far above the central
differences' rounding, far below any identifiable case measured (``docs/accuracy.md``)."""


def noise_variance(spec) -> float:
    """Variance of one reading: read noise plus uniform quantization [counts^2]."""
    return spec.flaws.read_noise_counts**2 + 1.0 / 12.0


def counts_from_strain(spec, strain) -> np.ndarray:
    """A pad's noiseless reading for a compressive strain at its taxels, gain 1 [counts].

    Capacitive: the plates close by ``strain_gain * strain`` (at most 0.95) and the
    reading follows eqs. 1-2 and the converter, unquantized; resistive:
    ``nominal_counts + counts_per_strain * max(strain, 0)``. The same arithmetic as the
    simulator's (``tactsense.simulate``), without flaws.
    """
    strain = np.asarray(strain, dtype=float)
    t = spec.transduction
    if t.kind == "capacitive":
        closing = np.minimum(t.strain_gain * strain, 0.95)
        voltage = amplifier_gain(spec) * divider_voltage(
            spec, spec.junction_capacitance_f / (1.0 - closing)
        )
        return voltage_to_counts(spec, voltage, quantize=False)
    if t.kind == "piezoresistive":
        from tactsense.physics.piezo import conductance_ratio, divider_counts, half_scale_strain

        el = spec.electronics
        g = conductance_ratio(strain, half_scale_strain(spec), t.exponent)
        return divider_counts(g, el.nominal_counts, 2**el.adc_bits - 1)
    return spec.electronics.nominal_counts + t.counts_per_strain * np.maximum(strain, 0.0)


def expected_counts(spec, x_mm: float, y_mm: float, force_n: float, radius_mm: float):
    """Noiseless readings of every taxel under a sphere at ``(x_mm, y_mm)``, (rows, cols)
    [counts]."""
    probe = SphereProbe(float(x_mm), float(y_mm), float(force_n), radius_mm=float(radius_mm))
    return counts_from_strain(spec, pad_strain(spec, [probe]))


def _on_layer_grid(spec) -> bool:
    """Whether ``spec`` is a grid of taxels under an elastic layer (``Kind.design_model``
    ``"layer"``), what this bound and the blind-spot map are computed for."""
    try:
        return kind_of(spec).design_model == "layer"
    except TactsenseInputError:  # not a sensor description
        return False


def _check_pad(spec, x_mm: float, y_mm: float) -> None:
    if not _on_layer_grid(spec):
        raise TactsenseInputError(
            f"this bound is for pads; {spec.name!r} is a {getattr(spec, 'kind_label', '?')}"
        )
    g = spec.grid
    for name, value, pitch, n in (
        ("x_mm", x_mm, g.row_pitch_mm, g.rows),
        ("y_mm", y_mm, g.col_pitch_mm, g.cols),
    ):
        low, high = -0.5 * pitch, (n - 0.5) * pitch
        if not (math.isfinite(value) and low <= value <= high):
            raise TactsenseInputError(
                f"{name} = {value:g} mm is off the {g.rows}x{g.cols} pad {spec.name!r}; "
                f"expected {low:g} to {high:g} mm"
            )


def rank_test(a: np.ndarray, scales, tolerance: float = RANK_TOLERANCE) -> dict:
    """Rank of ``J = A^T A`` from the singular values of ``A`` with each column times its
    parameter's physical scale (``scales``: a pitch for a position [mm], the load for a
    force [N]), so a singular value is the readings' change, in noise units, for a move
    of one pitch or a change of the whole load: ``rank``, ``smallest_ratio`` (smallest
    over largest singular value) and ``singular`` (``smallest_ratio < tolerance``).

    Not scaled by the columns' own lengths: a parameter no reading depends on has a
    column of rounding, which scaled to unit length would look independent."""
    scaled = np.asarray(a, dtype=float) * np.asarray(scales, dtype=float)
    if not np.all(np.isfinite(scaled)) or not np.any(scaled):
        return {"rank": 0, "smallest_ratio": 0.0, "singular": True}
    s = np.linalg.svd(scaled, compute_uv=False)
    ratio = float(s[-1] / s[0])
    return {"rank": int(np.sum(s > tolerance * s[0])), "smallest_ratio": ratio,
            "singular": ratio < tolerance}  # fmt: skip


def fisher_information(
    spec,
    x_mm: float,
    y_mm: float,
    force_n: float,
    *,
    radius_mm: float = PROBE_RADIUS_MM,
    step_mm: float | None = None,
) -> np.ndarray:
    """Fisher information of ``(x [mm], y [mm], force [N])`` from one frame, (3, 3).

    Central differences of :func:`expected_counts`: ``step_mm`` in position (default a
    hundredth of the pitch) and a ten-thousandth of the force.
    """
    check_positive(force_n, "force_n")
    check_positive(radius_mm, "radius_mm")
    _check_pad(spec, x_mm, y_mm)
    h = 0.01 * min(spec.grid.row_pitch_mm, spec.grid.col_pitch_mm) if step_mm is None else step_mm
    theta = np.array([x_mm, y_mm, force_n], dtype=float)
    steps = (h, h, 1e-4 * force_n)
    columns = []
    for k, step in enumerate(steps):
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        difference = expected_counts(spec, *up, radius_mm) - expected_counts(spec, *down, radius_mm)
        columns.append(difference.ravel() / (2 * step))
    jacobian = np.column_stack(columns)
    return jacobian.T @ jacobian / noise_variance(spec)


def cramer_rao_bound(
    spec, x_mm: float, y_mm: float, force_n: float, *, radius_mm: float = PROBE_RADIUS_MM
) -> dict:
    """Smallest standard deviations of position and force an unbiased estimator reaches
    from one frame of a pad.

    Parameters
    ----------
    spec : PadSpec
    x_mm, y_mm : float
        Where the sphere presses [mm] (the pad's axes, ``docs/nomenclature.md``).
    force_n : float
        Its load [N].
    radius_mm : float
        Its radius [mm] (default the paper's 3.2-mm probe).

    Returns
    -------
    dict
        ``x_mm``, ``y_mm``, ``position_mm`` (root mean square of x and y) [mm],
        ``force_n`` [N], ``force_relative`` [-], ``x_pitch`` and ``y_pitch`` (x and y
        in pitches) [-].

    Raises
    ------
    TactsenseInputError
        Where the contact is not identifiable (singular Fisher information by the rank
        test of :data:`RANK_TOLERANCE`): on a thin incompressible layer a probe centred
        on a resistive taxel stretches its neighbours, which read tension as rest; see
        :mod:`tactsense.analysis.pad_censored` for the censored and Bayesian bounds.
    """
    information = fisher_information(spec, x_mm, y_mm, force_n, radius_mm=radius_mm)
    # the rank test on J = A^T A (A's singular values: the square roots of J's
    # eigenvalues), in units of a pitch and the load
    g = spec.grid
    scale = np.array([g.row_pitch_mm, g.col_pitch_mm, force_n])
    singular = not np.all(np.isfinite(information))
    if not singular:
        eigen = np.linalg.eigvalsh(information * np.outer(scale, scale))
        singular = eigen[0] <= (RANK_TOLERANCE**2) * eigen[-1]
    if singular:
        raise TactsenseInputError(
            f"a {force_n:g}-N probe at ({x_mm:g}, {y_mm:g}) mm is not identifiable on "
            f"{spec.name!r} (singular Fisher information: rank test, tolerance "
            f"{RANK_TOLERANCE:g}): no compressed taxel's reading moves with it; try a "
            "point between taxels"
        )
    return bound_stds(information, spec, force_n)


def bound_stds(information: np.ndarray, spec, force_n: float) -> dict:
    """The bound's standard deviations from a Fisher matrix over (x, y, force): x, y and
    their RMS [mm], force [N] and relative to ``force_n`` [-], x and y in pitches [-]."""
    std = np.sqrt(np.diag(np.linalg.inv(information)))
    g = spec.grid
    return {
        "x_mm": float(std[0]),
        "y_mm": float(std[1]),
        "position_mm": float(np.sqrt(0.5 * (std[0] ** 2 + std[1] ** 2))),
        "force_n": float(std[2]),
        "force_relative": float(std[2] / force_n),
        "x_pitch": float(std[0] / g.row_pitch_mm),
        "y_pitch": float(std[1] / g.col_pitch_mm),
    }


def signal_map(
    spec,
    force_n: float,
    *,
    radius_mm: float = PROBE_RADIUS_MM,
    step_mm: float | None = None,
    fold: bool = True,
):
    """The largest change of any taxel's reading for a sphere at each point of the pad.

    The layer is linear and the same under every taxel, so a taxel's strain depends only
    on where the probe is relative to it: one strain map (the probe at the origin, the
    strain averaged over an electrode centred at each grid point) gives every taxel's
    strain for every probe position on the grid. The grid covers the pad (a half pitch
    beyond the outer taxels), ``step_mm`` apart (default: the pitch over an integer
    near 16, at most 0.25 mm), the taxel centres on it. With ``fold`` (the default) a
    large pad's map is made from a small one's (the same numbers, in a time that does
    not grow with the number of taxels).

    Returns
    -------
    x_mm : ndarray, shape (M,)
    y_mm : ndarray, shape (N,)
        Probe positions [mm].
    change : ndarray, shape (M, N)
        Largest absolute change of a taxel's reading from its untouched one [counts].
    rise : ndarray, shape (M, N)
        Largest rise (compression) [counts].
    """
    check_positive(force_n, "force_n")
    check_positive(radius_mm, "radius_mm")
    g = spec.grid
    if step_mm is None:
        step_mm = min(0.25, min(g.row_pitch_mm, g.col_pitch_mm) / 16)
    nx = max(2, math.ceil(g.row_pitch_mm / step_mm))
    ny = max(2, math.ceil(g.col_pitch_mm / step_mm))
    hx, hy = g.row_pitch_mm / nx, g.col_pitch_mm / ny
    # the kernel: offsets taxel - probe within reach (the strain beyond a few layer
    # thicknesses of a contact is nil)
    reach = 4.0 * spec.layer.thickness_mm + 2.0 * radius_mm + max(g.row_pitch_mm, g.col_pitch_mm)
    kx, ky = math.ceil(reach / hx), math.ceil(reach / hy)
    ox, oy = hx * np.arange(-kx, kx + 1), hy * np.arange(-ky, ky + 1)
    probe = SphereProbe(0.0, 0.0, float(force_n), radius_mm=float(radius_mm))
    pressure = pressure_map([probe], ox, oy, modulus_star_pa=modulus_star_pa(spec.layer))
    compressive = -strain_map(
        pressure, (hx, hy), spec.layer, electrode_mm=(g.electrode_x_mm, g.electrode_y_mm)
    )
    kernel = counts_from_strain(spec, compressive) - counts_from_strain(spec, 0.0)
    # probe positions: the pad and a half pitch beyond its outer taxels
    px = np.arange(-(nx // 2), (g.rows - 1) * nx + nx // 2 + 1)
    py = np.arange(-(ny // 2), (g.cols - 1) * ny + ny // 2 + 1)
    # a probe reaches the taxels within kx, ky grid steps: away from the edges the map
    # repeats from one cell to the next, and a large pad's map is a small one's with its
    # middle cell repeated (exactly: the kernel ends at the reach)
    mx, my = math.ceil(kx / nx), math.ceil(ky / ny)
    small_rows, small_cols = min(g.rows, 2 * mx + 3), min(g.cols, 2 * my + 3)
    if fold and (small_rows, small_cols) != (g.rows, g.cols):
        small = spec.replace(grid__rows=small_rows, grid__cols=small_cols, flaws__dead_tactels=())
        _, _, change, rise = _signal_map_direct(small, kernel, nx, ny, kx, ky, ox.size, oy.size)
        ix = _fold(px, nx, mx, g.rows, small_rows) + nx // 2
        iy = _fold(py, ny, my, g.cols, small_cols) + ny // 2
        return px * hx, py * hy, change[np.ix_(ix, iy)], rise[np.ix_(ix, iy)]
    _, _, change, rise = _signal_map_direct(spec, kernel, nx, ny, kx, ky, ox.size, oy.size)
    return px * hx, py * hy, change, rise


def _fold(u: np.ndarray, n: int, m: int, count: int, small: int) -> np.ndarray:
    """Grid index ``u`` (taxel k at ``k n``) on a row of ``count`` taxels -> the index
    with the same map on a row of ``small`` (``2 m + 3``) taxels: the first and last
    ``m + 1`` cells as they are, every cell between as the middle one."""
    if count == small:
        return u
    left, right = (m + 1) * n, (count - 1 - (m + 1)) * n
    return np.where(
        u <= left, u, np.where(u >= right, u - (count - small) * n, left + (u - left) % n)
    )


def _signal_map_direct(spec, kernel, nx, ny, kx, ky, size_x, size_y):
    """:func:`signal_map`'s maps, every taxel's kernel placed in turn."""
    g = spec.grid
    px = np.arange(-(nx // 2), (g.rows - 1) * nx + nx // 2 + 1)
    py = np.arange(-(ny // 2), (g.cols - 1) * ny + ny // 2 + 1)
    change = np.zeros((px.size, py.size))
    rise = np.zeros((px.size, py.size))
    for r in range(g.rows):
        for c in range(g.cols):
            # taxel at grid index (r nx, c ny); the probe at index p sees kernel[t - p]
            ix = r * nx - px + kx
            iy = c * ny - py + ky
            okx, oky = (ix >= 0) & (ix < size_x), (iy >= 0) & (iy < size_y)
            block = kernel[np.ix_(ix[okx], iy[oky])]
            sub = np.ix_(okx, oky)
            change[sub] = np.maximum(change[sub], np.abs(block))
            rise[sub] = np.maximum(rise[sub], block)
    return px, py, change, rise


def _regions(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """Connected regions of a boolean map (4-neighbour): labels and their count."""
    from scipy import ndimage

    labels, count = ndimage.label(mask)
    return labels, int(count)


def blind_spots(
    spec,
    force_n: float,
    *,
    radius_mm: float = PROBE_RADIUS_MM,
    threshold_counts: float | None = None,
    step_mm: float | None = None,
) -> dict:
    """Where on a pad a sphere of ``force_n`` moves no taxel's reading by more than
    ``threshold_counts`` (default: three times the reading noise, read noise and
    quantization): the pad does not see a press there.

    Returns
    -------
    dict
        ``threshold_counts``; ``blind_fraction`` (of the pad's area, a half pitch beyond
        the outer taxels) [-], ``blind_area_mm2`` [mm^2]; ``regions``, one per connected
        blind region: ``centre_mm`` (x, y), ``extent_mm`` (along x, along y),
        ``area_mm2``, ``largest_change_counts`` (the most any taxel moves in it); the
        grid ``step_mm``; and ``weakest_change_counts`` (the smallest, over the pad, of
        the largest change).
    """
    if not _on_layer_grid(spec):
        raise TactsenseInputError(
            f"blind spots are mapped on pads; {spec.name!r} is a {getattr(spec, 'kind_label', '?')}"
        )
    if threshold_counts is None:
        threshold_counts = 3.0 * math.sqrt(noise_variance(spec))
    check_positive(threshold_counts, "threshold_counts")
    x, y, change, _ = signal_map(spec, force_n, radius_mm=radius_mm, step_mm=step_mm)
    hx, hy = x[1] - x[0], y[1] - y[0]
    blind = change <= threshold_counts
    labels, count = _regions(blind)
    regions = []
    for k in range(1, count + 1):
        inside = labels == k
        ix, iy = np.nonzero(inside)
        regions.append(
            {
                "centre_mm": (float(x[ix].mean()), float(y[iy].mean())),
                "extent_mm": (float(np.ptp(x[ix]) + hx), float(np.ptp(y[iy]) + hy)),
                "area_mm2": float(inside.sum() * hx * hy),
                "largest_change_counts": float(change[inside].max()),
            }
        )
    regions.sort(key=lambda region: -region["area_mm2"])
    return {
        "threshold_counts": float(threshold_counts),
        "blind_fraction": float(blind.mean()),
        "blind_area_mm2": float(blind.sum() * hx * hy),
        "regions": regions,
        "step_mm": (float(hx), float(hy)),
        "weakest_change_counts": float(change.min()),
    }

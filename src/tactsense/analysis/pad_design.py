"""Design of a pad: what section 6 of the paper trades off, for a flat array.

For a pad otherwise like the given one, with its sensing element at ``depth_mm`` (the
layer's thickness scaled with it, keeping the preset's depth-to-thickness ratio) and
taxels ``pitch_mm`` apart along both axes (electrodes scaled with the pitch):

* ``counts_per_gram``: the A/D units a probe centred on a taxel moves its reading, per
  gram [1/g];
* ``xi``: aliasing, eq. 45 carried to two dimensions: the share of the energy of a
  taxel's response (the layer's strain transfer times its electrode's averaging) beyond
  the Nyquist square ``|kx|, |ky| < 1 / (2 pitch)`` [-];
* ``crb_position_mm`` and ``crb_force_pct``: the Cramer-Rao bound on the position
  (root mean square over x and y) and on the force of a probe a quarter pitch off a
  taxel along both axes, with the pad's read noise and quantization (what any estimator
  could reach) [mm], [%]; ``inf`` where the Fisher matrix is singular by the rank test
  of :func:`tactsense.analysis.pad_bound.rank_test`. The bound is for that one
  position: on a thin incompressible layer a probe centred on a resistive taxel
  stretches its neighbours, which read tension as rest (the classic bound there is
  infinite), while a quarter pitch off it two neighbours are compressed and the bound is
  small; :mod:`tactsense.analysis.pad_censored` gives the censored bound and the
  Bayesian one over the cell.
"""

from __future__ import annotations

import numpy as np

from tactsense.analysis.pad_bound import rank_test
from tactsense.kinds import kind_of
from tactsense.physics.contact import grams_force
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import pad_strain, strain_transfer
from tactsense.sensor import PadSpec, SensorSpecError

VARIABLES = {
    "counts_per_gram": ("1/g", "A/D units per gram of a probe centred on a taxel"),
    "xi": ("1", "aliasing: share of the taxel response's energy beyond the Nyquist square"),
    "crb_position_mm": ("mm", "Cramer-Rao bound on position (rms of x and y)"),
    "crb_force_pct": ("%", "Cramer-Rao bound on force"),
}

PROBE_RADIUS_MM = 1.6
"""The paper's probe: a 3.2-mm hemisphere (section 3)."""
_SIZE = 7  # taxels per side of the small pad each design is evaluated on


def design_variant(sensor: PadSpec, depth_mm: float, pitch_mm: float, poisson_ratio: float):
    """The pad of one design: 7 x 7 taxels, depth and pitch as asked, the rest as
    ``sensor`` (layer thickness and electrodes scaled with depth and pitch)."""
    g, layer = sensor.grid, sensor.layer
    scale = pitch_mm / max(g.row_pitch_mm, g.col_pitch_mm)
    return sensor.replace(
        grid__rows=_SIZE,
        grid__cols=_SIZE,
        grid__row_pitch_mm=pitch_mm,
        grid__col_pitch_mm=pitch_mm,
        grid__electrode_x_mm=g.electrode_x_mm * scale,
        grid__electrode_y_mm=g.electrode_y_mm * scale,
        layer__sensing_depth_mm=depth_mm,
        layer__thickness_mm=depth_mm * layer.thickness_mm / layer.sensing_depth_mm,
        layer__poisson_ratio=poisson_ratio,
        flaws__dead_tactels=(),
    )


def _counts(spec: PadSpec, strain: np.ndarray) -> np.ndarray:
    """Reading above the untouched one for a compressive strain [counts] (eq. 4 inverted
    for a capacitive pad, ``V_S = V_o / (1 - d)``; the linear gain for a resistive one)."""
    t, nominal = spec.transduction, spec.electronics.nominal_counts
    if t.kind == "capacitive":
        deflection = np.minimum(t.strain_gain * strain, 0.95)
        return nominal * deflection / (1.0 - deflection)
    if t.kind == "piezoresistive":
        from tactsense.physics.piezo import conductance_ratio, divider_counts, half_scale_strain

        g = conductance_ratio(strain, half_scale_strain(spec), t.exponent)
        return divider_counts(g, 0.0, 2**spec.electronics.adc_bits - 1 - nominal)
    return t.counts_per_strain * np.maximum(strain, 0.0)


def aliasing(spec: PadSpec, samples: int = 257) -> float:
    """Share of the energy of a taxel's response beyond the Nyquist square [-].

    Both integrals (over the Nyquist square, and over the quadrant up to 8 cycles per
    sensing depth, where the response has died out) by the trapezoid rule on a grid of
    ``samples`` squared points each: the integrand is smooth on each, so the error falls
    as the square of the step.
    """
    pitch = max(spec.grid.row_pitch_mm, spec.grid.col_pitch_mm)
    g, layer = spec.grid, spec.layer

    def energy(limit: float) -> float:
        k = np.linspace(0.0, limit, samples)  # [cycles/mm]; even in kx and ky: one quadrant
        kx, ky = np.meshgrid(k, k, indexing="ij")
        power = (
            strain_transfer(kx, ky, layer.sensing_depth_mm, layer)
            * np.sinc(kx * g.electrode_x_mm)
            * np.sinc(ky * g.electrode_y_mm)
        ) ** 2
        weights = np.full(samples, k[1] - k[0])
        weights[0] = weights[-1] = 0.5 * (k[1] - k[0])
        return float(np.einsum("i,j,ij->", weights, weights, power))

    total = energy(max(8.0 / layer.sensing_depth_mm, 0.5 / pitch))
    return 1.0 - energy(0.5 / pitch) / total if total > 0 else float("nan")


def design_point(
    sensor: PadSpec, depth_mm: float, pitch_mm: float, poisson_ratio: float, grams: float
) -> dict[str, float]:
    """The map's variables for one pad design (NaN where it does not make a valid pad)."""
    try:
        spec = design_variant(sensor, depth_mm, pitch_mm, poisson_ratio)
    except SensorSpecError:
        return dict.fromkeys(VARIABLES, float("nan"))
    force = grams_force(grams)
    centre = (_SIZE // 2) * pitch_mm

    def readings(x: float, y: float, f: float) -> np.ndarray:
        probe = SphereProbe(x, y, f, radius_mm=PROBE_RADIUS_MM)
        return _counts(spec, pad_strain(spec, [probe])).ravel()

    on_taxel = readings(centre, centre, force)
    counts_per_gram = float(on_taxel.max()) / grams
    # Fisher information of (x, y, F) for a probe off the taxel grid, by central differences
    x0 = y0 = centre + 0.25 * pitch_mm
    step, df = 0.01 * pitch_mm, 0.01 * force
    d_x = (readings(x0 + step, y0, force) - readings(x0 - step, y0, force)) / (2 * step)
    d_y = (readings(x0, y0 + step, force) - readings(x0, y0 - step, force)) / (2 * step)
    d_f = (readings(x0, y0, force + df) - readings(x0, y0, force - df)) / (2 * df)
    noise = spec.flaws.read_noise_counts**2 + 1.0 / 12.0  # read noise and quantization
    jacobian = np.column_stack([d_x, d_y, d_f])
    fisher = jacobian.T @ jacobian / noise
    # a position no compressed taxel's reading depends on is not observable: the bound
    # is unbounded, inf (the rank test of pad_bound, not an absolute condition cut-off)
    position = force_pct = float("inf")
    if not rank_test(jacobian / np.sqrt(noise), (pitch_mm, pitch_mm, force))["singular"]:
        bound = np.linalg.inv(fisher)
        if bound[0, 0] > 0 and bound[1, 1] > 0 and bound[2, 2] > 0:
            position = float(np.sqrt(0.5 * (bound[0, 0] + bound[1, 1])))
            force_pct = float(100.0 * np.sqrt(bound[2, 2]) / force)
    return {
        "counts_per_gram": counts_per_gram,
        "xi": aliasing(spec),
        "crb_position_mm": position,
        "crb_force_pct": force_pct,
    }


IRRELEVANT = ("name", "description", "grid.rows", "grid.cols", "electronics.scan_rate_hz")
"""Fields of a pad that no variable of the map depends on: every design is evaluated on
a 7 x 7 patch of taxels (:func:`design_variant`) from one frame."""


def _fields(spec: PadSpec) -> dict:
    """The description as dotted keys -> values."""

    def flatten(data: dict, prefix: str) -> dict:
        out = {}
        for key, value in data.items():
            name = f"{prefix}{key}"
            if isinstance(value, dict):
                out.update(flatten(value, f"{name}."))
            else:
                out[name] = value
        return out

    return flatten(spec.to_dict(), "")


def map_point(pad: PadSpec) -> tuple[float, float]:
    """Where ``pad`` sits on a design map: (sensing depth, pitch) [mm], the larger pitch
    if its two differ (as :func:`design_variant` takes it)."""
    return pad.layer.sensing_depth_mm, max(pad.grid.row_pitch_mm, pad.grid.col_pitch_mm)


def map_differences(sensor: PadSpec, other: PadSpec, poisson_ratio: float) -> dict:
    """How ``other``, at its own sensing depth and pitch, differs from the design the map
    of ``sensor`` evaluates there: dotted field -> (other's value, the map's value);
    empty when the map's values at that point are ``other``'s own.

    The map scales the layer's thickness with the depth and the electrodes with the
    pitch, keeping ``sensor``'s ratios, and keeps everything else of ``sensor``
    (transduction, the layer's modulus, electronics, noise): a pad of another
    transduction, layer or thickness ratio is not on it.
    """
    depth, pitch = map_point(other)
    try:
        mine = _fields(design_variant(sensor, depth, pitch, poisson_ratio))
        theirs = _fields(design_variant(other, depth, pitch, poisson_ratio))
    except SensorSpecError:
        return {"design": ("not a valid variant", "")}
    differences = {}
    for key in sorted(set(mine) | set(theirs)):
        if key in IRRELEVANT:
            continue
        a, b = theirs.get(key), mine.get(key)
        same = a == b or (
            isinstance(a, float) and isinstance(b, float) and np.isclose(a, b, rtol=1e-9, atol=0)
        )
        if not same:
            differences[key] = (a, b)
    return differences


def designs_on_map(
    sensor: PadSpec, pads, poisson_ratio: float
) -> tuple[dict[str, tuple[float, float]], dict[str, dict]]:
    """The pads to mark on the design map of ``sensor``: name -> (sensing depth, pitch)
    [mm] of those whose own design the map evaluates at their point (``sensor`` itself,
    always), and name -> :func:`map_differences` of those left out (e.g. ``pad4`` on
    ``pad16``'s map: another transduction and layer, whose bound is finite where the map's
    is not)."""

    marked = {sensor.name: map_point(sensor)}
    left_out = {}
    for pad in pads:
        same_model = kind_of(pad).design_model == kind_of(sensor).design_model
        if not same_model or pad.name == sensor.name:
            continue
        differences = map_differences(sensor, pad, poisson_ratio)
        if differences:
            left_out[pad.name] = differences
        else:
            marked[pad.name] = map_point(pad)
    return marked, left_out


def _what(key: str) -> str:
    """A field of a pad description in a few words, for the map's note."""
    if key == "layer.thickness_mm":
        return "layer thickness / depth"
    if key.startswith("grid.electrode"):
        return "electrode size / pitch"
    section = key.split(".")[0]
    return {"layer": "layer material", "flaws": "noise and flaws"}.get(section, section)


def left_out_note(left_out: dict[str, dict], sensor_name: str) -> str | None:
    """One line under the map naming the pads it does not describe, and why."""
    if not left_out:
        return None
    parts = []
    for name, differences in sorted(left_out.items()):
        words = dict.fromkeys(_what(key) for key in differences)  # in order, once each
        parts.append(f"{name} (other {', '.join(words)})")
    return (
        f"Not marked: {'; '.join(parts)}. The map keeps {sensor_name}'s transduction, layer "
        "and ratios; map another pad with --sensor NAME."
    )

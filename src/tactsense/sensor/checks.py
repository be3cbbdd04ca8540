"""The checks of the sections every kind of sensor shares: each appends readable sentences
to a list of problems (none: valid), as :meth:`SpecBase.problems` gathers them."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from tactsense.sensor.common import Electronics, Flaws, Layer, Transduction


def positive(problems: list[str], section: str, key: str, value: Any) -> None:
    """Append a sentence to ``problems`` unless ``value`` is a finite positive number."""
    if not (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and value > 0
    ):
        problems.append(f"[{section}] {key} must be positive; got {value!r}")


def check_electronics(
    el: Electronics, problems: list[str], transduction: Transduction | None = None
) -> None:
    """Every problem with the electronics section.

    ``transduction`` is the sensor's (None: a finger, whose chain is the capacitive one).
    The rest reading ``nominal_counts`` may be 0 (a resistive cell at rest) except where
    the reading comes from the capacitive chain, whose amplifier is set so that the
    untouched junction reads ``nominal_counts`` and whose signal (eq. 4) divides by the
    reading: there it must be positive. A falling reading must rest above 0 to fall.
    """
    for fld in dataclasses.fields(el):
        if fld.name != "nominal_counts":
            positive(problems, "electronics", fld.name, getattr(el, fld.name))
    nominal = el.nominal_counts
    kind = "capacitive" if transduction is None else transduction.kind
    falling = transduction is not None and transduction.polarity == "falling"
    if not (
        isinstance(nominal, int | float)
        and not isinstance(nominal, bool)
        and math.isfinite(nominal)
        and nominal >= 0
    ):
        problems.append(
            f"[electronics] nominal_counts (the reading at rest) must be 0 or more; got {nominal!r}"
        )
    elif nominal == 0 and kind == "capacitive":
        problems.append(
            "[electronics] nominal_counts = 0: the capacitive chain's reading is "
            "proportional to the plates' capacitance (eqs. 1-4), so it must rest above 0; "
            'describe a cell that reads 0 at rest as kind = "resistive"'
        )
    elif nominal == 0 and falling:
        problems.append(
            '[electronics] nominal_counts = 0 with polarity = "falling": a reading that '
            'rests at 0 cannot fall; give the rest reading, or polarity = "rising"'
        )
    if problems:
        return
    if not 1 <= el.adc_bits <= 24:
        problems.append(f"[electronics] adc_bits = {el.adc_bits} must lie in 1..24")
    elif nominal >= 2**el.adc_bits:
        problems.append(
            f"[electronics] nominal_counts = {nominal:g} does not fit in a "
            f"{el.adc_bits}-bit converter (0 to {2**el.adc_bits - 1})"
        )


def check_flaws(f: Flaws, shape: tuple[int, int], problems: list[str]) -> None:
    """Every problem with the flaws section of a sensor whose frames have ``shape``."""
    for key in (
        "gain_spread_sd",
        "force_jitter_n",
        "position_jitter_mm",
        "read_noise_counts",
        "creep_fraction",
    ):
        value = getattr(f, key)
        if not (math.isfinite(value) and value >= 0):
            problems.append(f"[flaws] {key} must be non-negative; got {value!r}")
    for key in (
        "nonlinear_saturation",
        "delayed_time_constant_s",
        "creep_time_constant_s",
        "gain_min",
        "gain_max",
    ):
        positive(problems, "flaws", key, getattr(f, key))
    if f.gain_min > 1.0 or f.gain_max < 1.0:
        problems.append(
            f"[flaws] gain_min <= 1 <= gain_max is required; got {f.gain_min}, {f.gain_max}"
        )
    if not 0.0 <= f.delayed_fraction <= 1.0:
        problems.append(f"[flaws] delayed_fraction must lie in [0, 1]; got {f.delayed_fraction!r}")
    for key in ("hysteresis", "drift_per_decade"):
        value = getattr(f, key)
        if not (math.isfinite(value) and 0.0 <= value <= 1.0):
            problems.append(f"[flaws] {key} must lie in [0, 1]; got {value!r}")
    if not (math.isfinite(f.crosstalk) and 0.0 <= f.crosstalk <= 1.0):
        problems.append(
            f"[flaws] crosstalk must lie in [0, 1] (0: isolated scan, 1: every unscanned "
            f"line floating); got {f.crosstalk!r}"
        )
    for key in ("temperature_coefficient_per_k", "temperature_rate_k_per_s"):
        value = getattr(f, key)
        if not math.isfinite(value):
            problems.append(f"[flaws] {key} must be a finite number; got {value!r}")
    coefficient = f.temperature_coefficient_per_k
    if math.isfinite(coefficient) and abs(coefficient) > 0.1:
        problems.append(
            f"[flaws] temperature_coefficient_per_k = {coefficient!r} is "
            "more than 10 % per kelvin; an FSR's is about 0.003/K"
        )
    rows, cols = shape
    for row, col in f.dead_tactels:
        if not (0 <= row < rows and 0 <= col < cols):
            problems.append(
                f"[flaws] dead tactel ({row}, {col}) is outside the wired array {rows}x{cols}"
            )


def check_layer(layer: Layer, problems: list[str]) -> None:
    """Every problem with an elastic layer section."""
    for key in ("thickness_mm", "youngs_modulus_pa", "sensing_depth_mm"):
        positive(problems, "layer", key, getattr(layer, key))
    nu = layer.poisson_ratio
    if not (isinstance(nu, float) and -1.0 < nu <= 0.5):
        problems.append(
            f"[layer] poisson_ratio = {nu!r} is out of range; Poisson's ratio lies in (-1, 0.5]"
        )
    if layer.substrate != "rigid":
        problems.append(f"[layer] substrate = {layer.substrate!r}; only 'rigid' is modelled")
    if not problems and layer.sensing_depth_mm > layer.thickness_mm:
        problems.append(
            f"[layer] sensing_depth_mm = {layer.sensing_depth_mm:g} lies below the layer "
            f"(thickness_mm = {layer.thickness_mm:g})"
        )


POLARITIES = ("rising", "falling")
"""Which way a reading moves under load (:attr:`Transduction.polarity`)."""


def check_transduction(t: Transduction, problems: list[str]) -> None:
    """Every problem with a transduction section."""
    if t.kind not in TRANSDUCTION_KINDS:
        problems.append(
            f"[transduction] kind = {t.kind!r}; expected 'capacitive', 'resistive' or "
            "'piezoresistive'"
        )
    if t.polarity not in POLARITIES:
        problems.append(
            f"[transduction] polarity = {t.polarity!r}; expected 'rising' (the reading rises "
            "under load) or 'falling' (it falls from its rest reading, as iCub's fingertips)"
        )
    for key in ("strain_gain", "dielectric_thickness_mm", "dielectric_constant"):
        positive(problems, "transduction", key, getattr(t, key))
    positive(problems, "transduction", "counts_per_strain", t.counts_per_strain)
    positive(problems, "transduction", "exponent", t.exponent)
    if not problems and t.kind == "piezoresistive" and not 0.2 <= t.exponent <= 5.0:
        problems.append(
            f"[transduction] exponent = {t.exponent:g} is outside 0.2..5: a piezoresistive "
            "cell's conductance rises as a moderate power of the load (an FSR: about 1)"
        )


def habit_rows(spec) -> list[tuple[str, str]]:
    """Rows for ``sensor check`` on a pad or point set's piezoresistive response and its
    habits (issue 32), the ones that are on."""
    t, f, el = spec.transduction, spec.flaws, spec.electronics
    rows = []
    if t.kind == "piezoresistive":
        half = (2**el.adc_bits - 1 - el.nominal_counts) / t.counts_per_strain
        rows.append(
            (
                "piezoresistive response",
                f"conductance ~ strain^{t.exponent:g} through a divider: half the span at "
                f"strain {half:.3g}, saturating at {2**el.adc_bits - 1} counts",
            )
        )
    habits = [
        f"{label} {value:g}"
        for label, value in (
            ("hysteresis", f.hysteresis),
            ("drift per decade", f.drift_per_decade),
            ("temperature coefficient [1/K]", f.temperature_coefficient_per_k),
            ("crosstalk", f.crosstalk),
        )
        if value
    ]
    if habits:
        rows.append(("habits (flaws)", ", ".join(habits)))
    return rows


TRANSDUCTION_KINDS = ("capacitive", "resistive", "piezoresistive")
"""The kinds of ``[transduction]`` (a finger is always capacitive)."""

"""A three-axis pad: a grid of magnets in an elastic layer over three-axis Hall sensors.

The class of magnetic skins labs bring (uSkin/Xela, the magnets of ReSkin and AnySkin
taxelised): each taxel is a small permanent magnet embedded in the elastic layer above a
three-axis Hall-effect sensor on the rigid substrate. A contact's normal and tangential
tractions displace the magnet (the layer model of :mod:`tactsense.physics.layer`, with
its tangential response); the sensor reads the magnetic field of every magnet at its
place (a point dipole each: its own and, weaker, its neighbours'), converted to counts.

Coordinates are the pad's (:mod:`tactsense.sensor.pad`): taxel ``(row, col)`` centred at
``x = row * row_pitch_mm``, ``y = col * col_pitch_mm`` on the free surface ``z = 0``,
``z`` the outward normal. A frame is ``(rows, cols, 3)``: the components ``x, y, z`` of
the field each sensor reads, in counts (``frame_shape``; the component axis is last).
``layer.sensing_depth_mm`` is the depth of the magnets' centres at rest,
``transduction.hall_depth_mm`` that of the Hall elements (at or below the layer's
bonded face).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tactsense.sensor.checks import check_electronics, check_flaws, check_layer, positive
from tactsense.sensor.common import Electronics, Flaws, Layer, SpecBase
from tactsense.sensor.pad import Grid, GridGeometry


@dataclass(frozen=True)
class MagneticTransduction:
    """A magnet per taxel, read by a three-axis Hall sensor below it.

    The field of a magnet is a point dipole's, ``B = mu0 / (4 pi r^3) (3 (m . r^) r^ - m)``,
    with its moment ``m`` along the outward normal; a sensor reads the sum over the magnets
    of the pad. Its reading of a component is ``nominal_counts + B / lsb`` (the converter's
    zero field at ``electronics.nominal_counts``, offset binary), clipped to the converter.
    """

    kind: str = "magnetic"
    """Only ``magnetic`` (the magnet's dipole field through a three-axis Hall sensor)."""
    moment_a_m2: float = 1.5e-3
    """Magnetic dipole moment of each magnet, along the outward normal [A m^2]."""
    hall_depth_mm: float = 4.0
    """Depth of the Hall elements below the free surface, at or below the layer's
    bonded face [mm]."""
    lsb_xy_ut: float = 0.751
    """Field per count of the x and y axes [uT/count]."""
    lsb_z_ut: float = 1.210
    """Field per count of the z axis [uT/count]."""
    neighbours: bool = True
    """Whether a sensor reads every magnet of the pad (True: the physical crosstalk of a
    magnetic skin) or its own alone."""
    earth_field_x_ut: float = 0.0
    """A uniform background field every sensor reads, along x [uT]: the Earth's (25-65 uT
    in magnitude) in the pad's frame as mounted. Always on (it is the world's field, not
    a flaw); an estimator takes it out with the baseline."""
    earth_field_y_ut: float = 0.0
    """The background field along y [uT]."""
    earth_field_z_ut: float = 0.0
    """The background field along z, the outward normal [uT]."""
    offset_sd_ut: float = 0.0
    """Standard deviation of each sensor's offset per axis [uT]: the Hall element's own
    offset and the magnet's placement error at assembly. Drawn once per sensor from
    ``flaws.gain_seed`` (it belongs to the skin, not to a run), switched on with the
    flaw ``gain_spread`` (the skin's manufacturing spread)."""


@dataclass(frozen=True)
class TriaxialSpec(GridGeometry, SpecBase):
    """Complete description of a three-axis (magnetic) taxel pad.

    Construct from a preset (``tactsense.sensor.preset("mag4x4")``), from TOML with
    ``kind = "triaxial"``, or directly; immutable and validated on construction.
    ``grid.electrode_x_mm`` and ``electrode_y_mm`` are the magnet's footprint (the
    layer's displacement is averaged over it).
    """

    name: str = "triaxial"
    description: str = ""
    grid: Grid = field(
        default_factory=lambda: Grid(
            rows=4,
            cols=4,
            row_pitch_mm=4.7,
            col_pitch_mm=4.7,
            electrode_x_mm=1.0,
            electrode_y_mm=1.0,
        )
    )
    layer: Layer = field(default_factory=lambda: Layer(thickness_mm=3.0, sensing_depth_mm=1.5))
    transduction: MagneticTransduction = field(default_factory=MagneticTransduction)
    electronics: Electronics = field(
        default_factory=lambda: Electronics(adc_bits=16, nominal_counts=32768.0, scan_rate_hz=100.0)
    )
    flaws: Flaws = field(default_factory=Flaws)

    kind: ClassVar[str] = "triaxial"
    components: ClassVar[int] = 3
    component_names: ClassVar[tuple[str, ...]] = ("x", "y", "z")
    SECTIONS: ClassVar[dict[str, type]] = {
        "grid": Grid,
        "layer": Layer,
        "transduction": MagneticTransduction,
        "electronics": Electronics,
        "flaws": Flaws,
    }

    def problems(self) -> list[str]:
        """Every problem with this description, as readable sentences (none: valid)."""
        return _validate(self)

    @property
    def lsb_t(self) -> np.ndarray:
        """Field per count of the components x, y, z [T/count], shape (3,)."""
        t = self.transduction
        return 1e-6 * np.array([t.lsb_xy_ut, t.lsb_xy_ut, t.lsb_z_ut])

    def summary(self) -> list[tuple[str, str]]:
        """Derived quantities worth printing, as (label, value with unit) rows."""
        g, layer, t = self.grid, self.layer, self.transduction
        return [
            ("kind", "triaxial (three components per taxel: x, y, z)"),
            ("frame shape (rows, cols, components)", f"{self.frame_shape}"),
            ("pitch (rows x cols)", f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm"),
            ("pad size (x, y)", f"{self.extent_mm[0]:g} x {self.extent_mm[1]:g} mm"),
            (
                "layer",
                f"{layer.thickness_mm:g} mm, E = {layer.youngs_modulus_pa:g} Pa, "
                f"nu = {layer.poisson_ratio:g}",
            ),
            ("magnets", f"{t.moment_a_m2:g} A m^2 at {layer.sensing_depth_mm:g} mm depth"),
            (
                "Hall sensors",
                f"at {t.hall_depth_mm:g} mm depth, "
                f"{t.lsb_xy_ut:g} / {t.lsb_z_ut:g} uT per count (x, y / z)",
            ),
            (
                "background field (x, y, z)",
                f"{t.earth_field_x_ut:g}, {t.earth_field_y_ut:g}, "
                f"{t.earth_field_z_ut:g} uT; offsets {t.offset_sd_ut:g} uT sd per axis",
            ),
            (
                "zero field reads",
                f"{self.electronics.nominal_counts:g} counts of {2**self.electronics.adc_bits - 1}",
            ),
        ]


def _validate(spec: TriaxialSpec) -> list[str]:
    problems: list[str] = []
    g, t, layer = spec.grid, spec.transduction, spec.layer
    for fld in dataclasses.fields(g):
        positive(problems, "grid", fld.name, getattr(g, fld.name))
    if not problems:
        if g.electrode_x_mm > g.row_pitch_mm or g.electrode_y_mm > g.col_pitch_mm:
            problems.append(
                f"[grid] magnets of {g.electrode_x_mm:g} x {g.electrode_y_mm:g} mm "
                f"overlap at a pitch of {g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm"
            )
        if g.rows * g.cols > 16_384:
            problems.append(f"[grid] {g.rows} x {g.cols} taxels: at most 16,384 are supported")
    check_layer(layer, problems)
    if t.kind != "magnetic":
        problems.append(f'[transduction] kind = {t.kind!r}: only "magnetic" is modelled')
    for name in ("moment_a_m2", "hall_depth_mm", "lsb_xy_ut", "lsb_z_ut"):
        positive(problems, "transduction", name, getattr(t, name))
    for name in ("earth_field_x_ut", "earth_field_y_ut", "earth_field_z_ut", "offset_sd_ut"):
        value = getattr(t, name)
        if not (
            isinstance(value, int | float)
            and not isinstance(value, bool)
            and math.isfinite(value)
            and abs(value) <= 1e5
        ):
            problems.append(
                f"[transduction] {name} must be a finite number of at most "
                f"100000 uT in size; got {value!r}"
            )
    if isinstance(t.offset_sd_ut, int | float) and t.offset_sd_ut < 0:
        problems.append(f"[transduction] offset_sd_ut must be >= 0; got {t.offset_sd_ut!r}")
    if not problems and t.hall_depth_mm < layer.thickness_mm:
        problems.append(
            f"[transduction] hall_depth_mm = {t.hall_depth_mm:g} lies inside the layer "
            f"({layer.thickness_mm:g} mm thick): the Hall sensors sit on the substrate, "
            "at or below the layer's bonded face"
        )
    if not isinstance(t.neighbours, bool):
        problems.append(f"[transduction] neighbours must be true or false; got {t.neighbours!r}")
    check_electronics(spec.electronics, problems, None)
    if not problems:
        check_flaws(spec.flaws, spec.shape, problems)
    return problems

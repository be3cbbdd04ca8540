"""Three-axis taxels: a grid of magnets in an elastic layer over three-axis Hall sensors.

Registered as a plug-in through the ``tactsense.kinds`` entry point (``pyproject.toml``),
as another package's kind would be: nothing outside this module and
:mod:`tactsense.sensor.triaxial` names it. A frame is ``(rows, cols, 3)``
(``spec.frame_shape``), the field components x, y, z of every taxel in counts.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

import numpy as np

from tactsense.kinds.base import Kind
from tactsense.sensor.pad import Grid
from tactsense.sensor.common import Electronics, Flaws, Layer
from tactsense.sensor.triaxial import MagneticTransduction, TriaxialSpec


def mag4x4() -> TriaxialSpec:
    """A 4 x 4 magnetic three-axis pad at 4.7 mm pitch (the class of uSkin/Xela patches).

    Provisional numbers (r8-skel): replaced with sourced ones by the physics work.
    """
    return TriaxialSpec(
        name="mag4x4",
        description="4 x 4 magnetic three-axis pad (provisional parameters)",
        grid=Grid(rows=4, cols=4, row_pitch_mm=4.7, col_pitch_mm=4.7,
                  electrode_x_mm=1.0, electrode_y_mm=1.0),
        layer=Layer(thickness_mm=3.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5,
                    sensing_depth_mm=1.5),
        transduction=MagneticTransduction(moment_a_m2=1.5e-3, hall_depth_mm=4.0),
        electronics=Electronics(adc_bits=16, nominal_counts=32768.0, scan_rate_hz=100.0),
        flaws=Flaws(gain_spread_sd=0.05, gain_min=0.8, gain_max=1.25, read_noise_counts=3.0,
                    force_jitter_n=0.0, position_jitter_mm=0.0),
    )


def magtip() -> TriaxialSpec:
    """A 6 x 4 magnetic three-axis fingertip pad (the class of uSkin's fingertips),
    laid flat. Provisional numbers (r8-skel)."""
    spec = mag4x4()
    return TriaxialSpec(
        name="magtip",
        description="6 x 4 magnetic three-axis fingertip, flat (provisional parameters)",
        grid=Grid(rows=6, cols=4, row_pitch_mm=4.7, col_pitch_mm=4.7,
                  electrode_x_mm=1.0, electrode_y_mm=1.0),
        layer=spec.layer,
        transduction=spec.transduction,
        electronics=spec.electronics,
        flaws=spec.flaws,
    )


class TriaxialKind(Kind):
    name = "triaxial"
    spec_class = TriaxialSpec
    label = "three-axis pad"
    presets = MappingProxyType({"mag4x4": mag4x4, "magtip": magtip})
    image_grid = True
    multi_contact = True
    view_drawing = "grid"
    design_model = None
    senses_shear = True
    scenarios = ("press", "hold", "two-probes", "slide", "loads")
    forwards = ("twin",)
    frame_axes = "time, row, col, component (x, y, z)"

    def surface_grid(self, spec):
        g = spec.grid
        return (g.row_pitch_mm, g.rows), (g.col_pitch_mm, g.cols)

    def size_text(self, spec):
        g = spec.grid
        return (f"{g.rows} x {g.cols} taxels x 3 axes",
                f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm")

    def layer_strain(self, spec, indenters):
        raise self.unsupported(spec, "a scalar strain per taxel (it reads three components)")

    def elastic_batch(self, spec, states, *, forward="twin", alone=True) -> np.ndarray:
        """Displacement of every magnet (x, y, z outward) [mm] for each state, shape
        (S, rows, cols, 3)."""
        from tactsense.physics.triaxial import magnet_displacement

        out = np.zeros((len(states), *spec.shape, 3))
        for k, state in enumerate(states):
            if state:
                out[k] = magnet_displacement(spec, state)
        return out

    def reads_capacitive(self, spec):
        return False

    def frame_blocks(self, spec: Any, run: Any, chunk_frames: int):
        """The three-axis chain (``simulate``): the elastic displacement of each step,
        sampled at each taxel's instant of the scan, the dipole field, gains (each
        sensor's sensitivity, all three axes), noise, quantization and the converter's
        range. Yields ``(first, last, counts)`` with counts of shape (k, rows, cols, 3)."""
        from tactsense.physics.triaxial import dipole_field_t, field_counts

        rows, cols = spec.shape
        period = spec.scan_period_s
        per_frame = rows * cols
        n_steps = len(run.applied)
        active = run.active
        full_scale = 2**spec.electronics.adc_bits - 1
        dead = np.zeros(spec.shape, dtype=bool)
        if "dead" in active:
            for r, c in spec.flaws.dead_tactels:
                dead[r, c] = True
        cache: dict[int, np.ndarray] = {}
        taxel = np.arange(per_frame)
        for first in range(0, run.n_frames, chunk_frames):
            last = min(run.n_frames, first + chunk_frames)
            times = np.arange(first, last)[:, None] * period + run.offsets.ravel()[None, :]
            step = np.clip(np.searchsorted(run.boundaries, times, side="right") - 1, 0,
                           n_steps - 1)
            needed = [int(s) for s in np.unique(step) if int(s) not in cache]
            if needed:
                if len(cache) > 4096:
                    cache.clear()
                    needed = [int(s) for s in np.unique(step)]
                values = self.elastic_batch(spec, [run.applied[s] for s in needed])
                cache.update(zip(needed, values, strict=True))
            disp = np.stack([np.stack([cache[int(s)].reshape(per_frame, 3)[taxel_i]
                                       for taxel_i, s in zip(taxel, row, strict=True)])
                             for row in step])
            field = dipole_field_t(spec, disp.reshape(last - first, rows, cols, 3))
            gains = np.asarray(run.gains, dtype=float)
            gains = gains[..., None] if gains.shape == spec.shape else gains
            counts = field_counts(spec, field * gains)
            if "noise" in active:
                counts = counts + run.rng.normal(0.0, spec.flaws.read_noise_counts, counts.shape)
            counts = np.clip(np.rint(counts) if "quantization" in active else counts, 0,
                             full_scale)
            counts[:, dead] = 0.0
            yield first, last, counts

    # ---- three-axis estimation (r8-triest) -----------------------------------------
    contact_estimation = True
    """Contacts are estimated (:mod:`tactsense.estimate.triaxial`: position, normal and
    tangential force, slip)."""
    if "calibration" not in scenarios:  # the normal sweep of 'calibrate'
        scenarios = (*scenarios, "calibration")
    array_calibration = False
    """Its calibration is the three-axis one (a 3x3 matrix per taxel,
    :mod:`tactsense.estimate.triaxial.calibration`), not a pad's gains and force curve."""

    def shear_response(
        self,
        spec,
        positions_mm,
        *,
        force_n: float = 0.49,
        shear_ratio: float = 0.25,
        size_mm: float = 1.6,
    ) -> np.ndarray:
        """The change of every taxel's reading [counts/N] per newton of normal force and
        per newton of tangential force along x and along y, for a sphere of ``size_mm``
        at each of ``positions_mm`` (P, 2) [mm]: shape (P, 3, rows, cols, 3), load 0 the
        normal force, 1 the tangential along x, 2 along y; the last axis the field
        components x, y, z.

        Differences of the kind's forward model (magnet displacement, then the dipole
        fields, no gains, no noise) about a press of ``force_n`` [N]: the normal response
        from rest to the press, the tangential ones from the press to the press with a
        tangential force of ``shear_ratio`` times it (friction high enough that nothing
        slips), so that the field's curvature about the loaded state is taken in."""
        from tactsense.physics.indenters import SphereProbe
        from tactsense.physics.triaxial import dipole_field_t, magnet_displacement

        positions = np.asarray(positions_mm, dtype=float).reshape(-1, 2)
        shear = shear_ratio * force_n
        rest = dipole_field_t(spec, np.zeros((*spec.shape, 3)))
        out = np.empty((len(positions), 3, *spec.shape, 3))
        for k, (x, y) in enumerate(positions):
            loads = ({}, {"shear_x_n": shear}, {"shear_y_n": shear})
            probes = [
                SphereProbe(x, y, force_n, radius_mm=size_mm, friction=100.0, **load)
                for load in loads
            ]
            disp = np.stack([magnet_displacement(spec, [probe]) for probe in probes])
            field = dipole_field_t(spec, disp) / spec.lsb_t
            out[k, 0] = (field[0] - rest / spec.lsb_t) / force_n
            out[k, 1] = (field[1] - field[0]) / shear
            out[k, 2] = (field[2] - field[0]) / shear
        return out

    # ---- /r8-triest ----


KIND: Any = TriaxialKind()

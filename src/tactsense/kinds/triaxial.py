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
from tactsense.sensor.common import Electronics, Flaws, Layer
from tactsense.sensor.pad import Grid
from tactsense.sensor.triaxial import MagneticTransduction, TriaxialSpec

MAGNET = {"remanence_t": 1.32, "diameter_mm": 1.0, "height_mm": 1.0}
"""Each taxel's magnet (an assumption): an N42 NdFeB cylinder (remanence 1.29-1.32 T in
makers' grade tables) of 1 mm x 1 mm; its moment is ``Br V / mu0``."""

SOURCES = (
    "pitch 4.7 mm: uSkin's flat version (Tomo et al., IEEE RA-L 3(3), 2018, 2584-2591); "
    "Hall sensors: Melexis MLX90393, 16 bits, 0.751 / 1.210 uT per count on x, y / z "
    "(GAIN_SEL 0, RES 0, HALLCONF 0xC: its data sheet's sensitivity table, as the "
    "Adafruit_MLX90393 library tabulates it), the zero field at 32768 counts; "
    "assumptions: 1 x 1 mm N42 magnets 1.5 mm deep in a 3-mm silicone layer "
    "(E 250 kPa, nu 0.5), the Hall elements 1 mm under it, read noise 3 counts, "
    "a 5 % gain and 20 uT offset spread, the Earth's field 48 uT"
)
"""Where the presets' numbers come from, and which are assumptions (docs/triaxial.md)."""

BRIEF = (
    "4.7 mm pitch (uSkin, Tomo et al., IEEE RA-L 2018), MLX90393 Hall sensors at "
    "0.751 / 1.210 uT per count (its data sheet); magnets, layer and noise assumed "
    "(docs/triaxial.md)"
)
""":data:`SOURCES` in a line, for a preset's description."""


def _magnetic_skin(name: str, rows: int, cols: int, description: str) -> TriaxialSpec:
    from tactsense.physics.triaxial import magnet_moment_a_m2

    return TriaxialSpec(
        name=name,
        description=description,
        grid=Grid(rows=rows, cols=cols, row_pitch_mm=4.7, col_pitch_mm=4.7,
                  electrode_x_mm=MAGNET["diameter_mm"], electrode_y_mm=MAGNET["diameter_mm"]),
        layer=Layer(thickness_mm=3.0, youngs_modulus_pa=2.5e5, poisson_ratio=0.5,
                    sensing_depth_mm=1.5),
        transduction=MagneticTransduction(
            moment_a_m2=round(magnet_moment_a_m2(**MAGNET), 7),
            hall_depth_mm=4.0,
            lsb_xy_ut=0.751,
            lsb_z_ut=1.210,
            earth_field_x_ut=20.0,
            earth_field_y_ut=0.0,
            earth_field_z_ut=-44.0,
            offset_sd_ut=20.0,
        ),
        electronics=Electronics(adc_bits=16, nominal_counts=32768.0, scan_rate_hz=100.0),
        flaws=Flaws(gain_spread_sd=0.05, gain_min=0.8, gain_max=1.25, read_noise_counts=3.0,
                    force_jitter_n=0.0, position_jitter_mm=0.0, nonlinear_saturation=0.712,
                    delayed_fraction=0.1, delayed_time_constant_s=0.05,
                    creep_fraction=0.05, creep_time_constant_s=10.0),
    )  # fmt: skip


def mag4x4() -> TriaxialSpec:
    """A 4 x 4 magnetic three-axis pad at 4.7 mm pitch (the class of uSkin/Xela's flat
    patches): :data:`SOURCES` says where each number comes from."""
    return _magnetic_skin(
        "mag4x4", 4, 4,
        "4 x 4 magnetic three-axis pad, the class of uSkin's flat patches: " + BRIEF,
    )  # fmt: skip


def magtip() -> TriaxialSpec:
    """A 6 x 4 magnetic three-axis fingertip laid flat (the class of uSkin's fingertips,
    Tomo et al., IEEE RA-L 3(1), 2018, 124-131: 6 N normal range, 10 % hysteresis); its
    24 taxels' layout is an assumption, the rest as :func:`mag4x4`."""
    return _magnetic_skin(
        "magtip", 6, 4,
        "6 x 4 magnetic three-axis fingertip laid flat, the class of uSkin's fingertips "
        "(Tomo et al., IEEE RA-L 3(1), 2018; layout assumed): " + BRIEF,
    )  # fmt: skip


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
    scenarios = ("press", "shear", "slide-to-slip", "hold", "two-probes", "slide", "loads")
    forwards = ("twin",)
    frame_axes = "time, row, col, component (x, y, z)"

    def surface_grid(self, spec):
        g = spec.grid
        return (g.row_pitch_mm, g.rows), (g.col_pitch_mm, g.cols)

    def size_text(self, spec):
        g = spec.grid
        return (
            f"{g.rows} x {g.cols} taxels x 3 axes",
            f"{g.row_pitch_mm:g} x {g.col_pitch_mm:g} mm",
        )

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

    def contact_state(self, spec, contacts):
        """One frame's contacts as indenters that carry their tangential force
        (``tangential_force_n`` (x, y) [N]), for ``frames_from_contacts``: a sphere (Hertz
        pressure, Cattaneo-Mindlin traction) or a disc at (x, y) [mm]. The forces given
        are the forces applied; the friction is the contact's own ``friction`` (mu) where
        given, else ``max(1, Q / P)`` (a tangential force carried without slip at the
        rim); a tangential force at or above ``mu P`` is gross slip (``mu = Q / P``)."""
        from tactsense.physics.indenters import DiscProbe, SphereProbe

        made = []
        for c in contacts:
            cls = SphereProbe if c["shape"] == "sphere" else DiscProbe
            x, y = c["position_mm"]
            qx, qy = c.get("tangential_force_n", (0.0, 0.0))
            force = c["normal_force_n"]
            ratio = float(np.hypot(qx, qy)) / force if force > 0 else 0.0
            friction = max(float(c.get("friction") or 1.0), ratio)
            made.append(cls(x, y, force, radius_mm=c["radius_mm"], shear_x_n=qx,
                            shear_y_n=qy, friction=friction))  # fmt: skip
        return tuple(made)

    def frame_blocks(self, spec: Any, run: Any, chunk_frames: int):
        """The three-axis chain (``simulate``): :func:`tactsense.physics.triaxial_chain.
        triaxial_frame_blocks` (displacement sampled at each taxel's tick, the layer's
        memory, dipole and background field, gains, offsets, noise, quantization, the
        converter's range, dead sensors). Yields ``(first, last, counts)`` with counts of
        shape (k, rows, cols, 3)."""
        from tactsense.physics.triaxial_chain import triaxial_frame_blocks

        return triaxial_frame_blocks(self, spec, run, chunk_frames)

    def rest_warnings(self, spec) -> list[str]:
        """Problems of the untouched skin, one line each (``sensor check`` and
        ``simulate`` print them): an axis whose rest field already reads the
        converter's rail (:func:`tactsense.physics.triaxial.rest_saturation`)."""
        from tactsense.physics.triaxial import rest_saturation

        lines = []
        for s in rest_saturation(spec):
            side = "full scale" if s["rail"] else "zero"
            lines.append(
                f"{spec.name!r}: the rest field saturates the converter on the {s['axis']} "
                f"axis of {s['taxels']} of {s['of']} taxels (it would read "
                f"{s['counts']:.0f} counts untouched; the range is 0 .. "
                f"{2 ** int(spec.electronics.adc_bits) - 1}): they read {s['rail']} "
                f"({side}) whatever the load. Lower [transduction] moment_a_m2 or the "
                "background field, or put the Hall sensors further (hall_depth_mm)"
            )
        return lines

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
        friction: float | None = None,
    ) -> np.ndarray:
        """The change of every taxel's reading [counts/N] per newton of normal force and
        per newton of tangential force along x and along y, for a sphere of ``size_mm``
        at each of ``positions_mm`` (P, 2) [mm]: shape (P, 3, rows, cols, 3), load 0 the
        normal force, 1 the tangential along x, 2 along y; the last axis the field
        components x, y, z.

        Differences of the kind's forward model (magnet displacement, then the dipole
        fields, no gains, no noise) about a press of ``force_n`` [N]: the normal response
        from rest to the press, the tangential ones from the press to the press with a
        tangential force of ``shear_ratio`` times it, so that the field's curvature about
        the loaded state is taken in. ``friction`` None: ``shear_ratio`` (the traction of
        gross slip, the pressure's shape times Q/P; of the shapes Cattaneo-Mindlin
        passes through, from the stick's edge-heavy one to this, the one whose fit of
        the scenarios' ramps erred least, noise-free: ``docs/triaxial.md``)."""
        from tactsense.physics.indenters import SphereProbe
        from tactsense.physics.triaxial import dipole_field_t, magnet_displacement

        positions = np.asarray(positions_mm, dtype=float).reshape(-1, 2)
        shear = shear_ratio * force_n
        friction = shear_ratio if friction is None else friction
        rest = dipole_field_t(spec, np.zeros((*spec.shape, 3)))
        out = np.empty((len(positions), 3, *spec.shape, 3))
        for k, (x, y) in enumerate(positions):
            loads = ({}, {"shear_x_n": shear}, {"shear_y_n": shear})
            probes = [
                SphereProbe(x, y, force_n, radius_mm=size_mm, friction=friction, **load)
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

"""The paper's finger (Fearing 1990): a cylinder of rings and strips with a tip row."""

from __future__ import annotations

import math
from types import MappingProxyType
from typing import Any

from tactsense.kinds.base import Kind
from tactsense.sensor.finger import SensorSpec, fearing1990_improved, fearing1990_initial


class FingerKind(Kind):
    name = "finger"
    spec_class = SensorSpec
    presets = MappingProxyType({"initial": fearing1990_initial, "improved": fearing1990_improved})
    position_names = ("axial_mm", "angle_deg")
    position_units = ("mm", "deg")
    image_grid = True
    multi_contact = False

    def periodic(self, spec: SensorSpec) -> bool:
        return bool(spec.closes_circumference)

    def jitter(self, spec: SensorSpec, first_mm: float, second_mm: float) -> tuple[float, float]:
        """Along the finger [mm] and around it [deg]."""
        return first_mm, math.degrees(second_mm / spec.radius_mm)

    # ---- the view and the commands (r5-cliview) ----
    view_drawing = "unwrapped"
    array_calibration = False
    # ---- simulation, scenarios and design (r5-sim) ----
    forwards = ("twin", "finger3d", "finger3d-foam")
    frame_axes = "time, row (along the finger, 0 = tip), col (around)"
    scenarios = ("sweep-axial", "sweep-around", "repeated", "calibration", "knife-edge")
    scenario_options = MappingProxyType({})
    surface_scenarios = False
    design_model = "paper"

    def elastic_batch(self, spec, states, *, forward="twin", alone=True):
        """The 2-D twin (:func:`~tactsense.physics.array_response.deflection_batch`) or
        the 3-D skin's tabulated response (:mod:`tactsense.physics.finger3d_table`)."""
        if forward != "twin":
            from tactsense.physics.finger3d_table import deflection_batch_3d

            return deflection_batch_3d(spec, states, forward)
        from tactsense.physics.array_response import deflection_batch

        if alone:
            return deflection_batch(spec, states)
        # an empty state keeps a window of probes alone on the path of the whole
        return deflection_batch(spec, [*states, ()])[:-1]

    def elastic_window_alone(self, applied):
        """The compiled path (single probes of one diameter) when the whole is on it."""
        from tactsense.physics.contact import Probe

        probes = [s[0] for s in applied if len(s) == 1 and type(s[0]) is Probe]
        return len(probes) == len(applied) and len({p.contact_diameter_mm for p in probes}) == 1

    def reads_capacitive(self, spec):
        return True

    def size_text(self, spec):
        a = spec.array
        size = f"{spec.shape[0]} x {spec.shape[1]} tactels"
        return size, f"{a.spacing_axial_mm:g} mm x {a.spacing_angle_deg:g} deg"

    # ---- forms for other tools: LSL, URDF (r5-interop) -------------------------
    def lsl_taxel_fields(self, spec: SensorSpec) -> dict:
        """Each channel's position along the finger [mm] and around it [deg]."""
        import numpy as np

        rows, cols = spec.shape
        return {
            "axial_mm": np.repeat(spec.row_axial_mm, cols),
            "angle_deg": np.tile(spec.col_angle_deg, rows),
        }

    def urdf_taxels(self, spec: SensorSpec) -> list[tuple[float, float]]:
        """The ring width along the axis by the strip width around it [mm]."""
        return [(spec.rings.ring_width_mm, spec.rings.strip_width_mm)] * spec.n_taxels

    def urdf_note(self, spec: SensorSpec) -> str | None:
        """Where the tip row is, and which way the taxel frames point."""
        if not spec.array.tip_row:
            return None
        return (
            f" tactsense: {spec.name}, row 0 under the hemispherical tip at "
            f"{spec.array.tip_row_axial_mm:g} mm along the skin; each taxel on the "
            "skin at its real position, z its outward normal, x along the finger "
        )

    def from_urdf_array(self, array, base: SensorSpec, *, path, preset: str) -> SensorSpec:
        """The unwrapped cylinder: rows along the finger, columns around it."""
        from tactsense.kinds._finger_urdf import finger_from_array

        return finger_from_array(array, base, path, preset)

    def from_urdf_taxels(self, taxels, base: SensorSpec, *, path) -> SensorSpec:
        """Rows and columns read back from the taxels' positions on the skin."""
        from tactsense.kinds._finger_urdf import finger_from_taxels

        return finger_from_taxels(taxels, base, path)

    # ---- estimation (r5-estimate) ----------------------------------------------

    # ---- frames from contacts (r6-fast) ----------------------------------------
    senses_shear = True

    def contact_state(self, spec, contacts):
        """Each contact as the paper's probe (:class:`~tactsense.physics.contact.Probe`,
        a parabolic pressure across its contact diameter) or, for a disc, a uniform
        :class:`~tactsense.physics.contact.FlatContact` of the disc's diameter: the
        position (axial [mm], arc around the skin [mm]), the total force and its angle
        from the normal from the normal and the axial tangential force [N] (the
        tangential force around the finger is not modelled); a sphere's contact diameter
        is twice its Hertz radius on the skin's rubber (at most its diameter)."""
        from tactsense.physics.contact import FlatContact, Probe

        e = spec.elastic
        modulus_star = e.youngs_modulus_pa / (1.0 - e.poisson_ratio**2)
        made = []
        for c in contacts:
            axial, around = c["position_mm"]
            angle = math.degrees(around / spec.radius_mm)
            normal, shear = c["normal_force_n"], c["tangential_force_n"][0]
            force = math.hypot(normal, shear)
            alpha = math.degrees(math.atan2(shear, normal))
            radius = c["radius_mm"]
            if c["shape"] == "sphere":
                hertz = 1e3 * (3.0 * normal * radius * 1e-3 / (4.0 * modulus_star)) ** (1 / 3)
                made.append(Probe(axial, angle, force, 2.0 * min(hertz, radius), alpha))
            else:
                made.append(
                    FlatContact(axial, angle, force, 2.0 * radius, 2.0 * radius, "uniform", alpha)
                )
        return tuple(made)

    # ---- the finger's fast forward (r9-fastpath) ----
    def contact_forward(self, spec):
        """The 2-D twin compiled over every contact of a batch, as :meth:`contact_state`
        makes them (:class:`tactsense.physics._finger_forward.FingerContactForward`)."""
        from tactsense.physics._finger_forward import FingerContactForward

        return FingerContactForward(spec)

    # ---- /r9-fastpath ----


KIND: Any = FingerKind()

"""The one protocol a sensor kind answers.

Everything that differs between kinds of array is asked of the kind's :class:`Kind`
object: commands, writers, estimators and views hold a sensor, ask ``kind_of(sensor)``
and call it; none of them compares a kind's name. A kind lives in one module: its
description (a :class:`~tactsense.sensor.common.SpecBase` dataclass, which may live in
:mod:`tactsense.sensor`) and a :class:`Kind` subclass, registered through the
``tactsense.kinds`` entry-point group (see ``docs/kinds.md``).

Methods come in groups: what the kind *is* (names, presets), its *geometry* (positions,
neighbours, coordinates), its *forward model* (loads to taxel signals), its *estimation*
(the response a fit uses, defaults) and its *forms* for other tools (URDF, LSL, the
view). A method a kind cannot answer raises :class:`KindNotSupported`, a one-line error
naming the sensor and what it lacks, never a traceback.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from tactsense._validation import TactsenseInputError


class KindNotSupported(TactsenseInputError):
    """What was asked has no meaning, or no model yet, for this kind of sensor."""


class Kind:
    """What one kind of sensor answers. Subclass it, set the class attributes, override
    what differs from the defaults, and register one instance (``docs/kinds.md``)."""

    # ---- what the kind is ------------------------------------------------------
    name: ClassVar[str]
    """The kind's name in TOML (``kind = "pad"``); equal to ``spec_class.kind``."""
    spec_class: ClassVar[type]
    """The frozen dataclass that describes one sensor of this kind."""
    label: ClassVar[str] = ""
    """The kind in words for a message (``"point set"``); default: its name."""
    plural: ClassVar[str] = ""
    """The plural in words (``"point sets"``); default: the label and an ``s``."""
    presets: ClassVar[Mapping[str, Callable[[], Any]]] = MappingProxyType({})
    """Built-in sensors of this kind by short name."""

    # ---- geometry --------------------------------------------------------------
    position_names: ClassVar[tuple[str, str]] = ("x_mm", "y_mm")
    """The two surface coordinates a contact's position is given in (column names)."""
    position_units: ClassVar[tuple[str, str]] = ("mm", "mm")
    """Their units."""
    image_grid: ClassVar[bool] = True
    """Whether a frame's (rows, cols) form a picture of the surface (a grid of taxels)."""
    multi_contact: ClassVar[bool] = True
    """Whether contacts are found and tracked per frame (many); False for a kind whose
    estimator reports the one contact of each frame (the paper's finger)."""

    def __init__(self) -> None:
        if not getattr(self, "label", ""):
            type(self).label = self.name
        if not getattr(self, "plural", ""):
            type(self).plural = self.label + "s"

    def describes(self, spec: Any) -> bool:
        """Whether ``spec`` is a sensor of this kind."""
        # a subclass of this kind's description may be another kind (``kind`` names it)
        return isinstance(spec, self.spec_class) and getattr(spec, "kind", None) == self.name

    def periodic(self, spec: Any) -> bool:
        """Whether the columns wrap around (the last column neighbours the first)."""
        return False

    def jitter(self, spec: Any, first_mm: float, second_mm: float) -> tuple[float, float]:
        """A positioning error given in mm on the surface, in this kind's coordinates."""
        return first_mm, second_mm

    def unsupported(self, spec: Any, what: str) -> KindNotSupported:
        """The error to raise when ``what`` does not apply to ``spec``."""
        return KindNotSupported(f"{what} does not apply to {spec.name!r}, a {self.label}")

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r}>"

    # ---- the view and the commands (r5-cliview) ----
    view_drawing: ClassVar[str] = "dots"
    """How the browser view draws a sensor of this kind: ``"unwrapped"`` (the paper's
    finger cut open along its seam: rows along it, columns around it, the tip row apart),
    ``"grid"`` (a flat grid in mm with the interpolated surface) or ``"dots"`` (dots at
    the taxels' positions [mm] projected onto the plane normal to their mean normal; asks
    only ``taxel_positions_mm`` and ``taxel_normals``, so any kind can use it)."""
    contact_estimation: ClassVar[bool] = True
    """Whether contacts are estimated frame by frame (by the live estimator
    :attr:`multi_contact` picks); False: the view shows the deflection only and says
    ``contact estimation: not yet for <plural>``."""
    array_calibration: ClassVar[bool] = True
    """Whether the kind takes an array's calibration (``tactsense calibrate``: a probe
    on every taxel, a uniform press or known weights; per-taxel gains and a force curve);
    False: the paper's finger calibration (a probe swept along every column, section 3.1,
    with creep steps and a knife edge)."""
    # ---- simulation, scenarios and design (r5-sim) ----
    forwards: ClassVar[tuple[str, ...]] = ("twin",)
    """The elastic models ``simulate --forward`` takes for this kind; ``"twin"`` is the
    kind's own (for a layer kind, its three-dimensional layer model)."""
    frame_axes: ClassVar[str] = "time, row, col"
    """What the axes of a recording's frames are (the ``axes`` attribute of ``frames``)."""
    scenarios: ClassVar[tuple[str, ...]] = (
        "press", "hold", "two-probes", "slide", "sweep", "knife-edge", "punch",
        "calibration", "loads",
    )  # fmt: skip
    """The ``--scenario`` names the kind takes, the first its default."""
    scenario_options: ClassVar[Mapping[str, tuple[str, ...]]] = MappingProxyType(
        {
            "knife-edge": ("force_g", "size_mm", "angle_deg", "dwell_s"),
            "calibration": ("force_g", "size_mm", "dwell_s"),
        }
    )
    """The options a scenario reads on this kind where they differ from the command's
    table (``tactsense.cli._scenario.USES``): scenario name -> option names."""
    surface_scenarios: ClassVar[bool] = True
    """Whether its scenarios are the indenters of :mod:`tactsense.flat_scenarios`, placed
    on the surface in mm; False: the paper's probe sweeps over (row, col) tactels
    (:mod:`tactsense.simulate`)."""
    design_model: ClassVar[str | None] = None
    """The elastic model the design analyses use for this kind: ``"paper"`` (the finger's
    strip and half-plane, Fearing 1990: ``design bound``, ``design sweep``,
    ``reproduce``), ``"layer"`` (a grid of taxels under an elastic layer: ``design
    bound``, ``design sweep``, ``sensor check``'s blind spots), or None (none of them)."""

    def check_forward(self, spec: Any, forward: str) -> str:
        """``forward`` checked: a known model, and one this kind has (a one-line error
        otherwise)."""
        from tactsense.physics.finger3d_table import check_forward

        check_forward(forward)
        if forward not in self.forwards:
            raise KindNotSupported(
                f"--forward {forward} is the paper's finger in 3-D; {spec.name!r} is "
                f"a {self.label} (its layer model is already three-dimensional)"
            )
        return forward

    def layer_strain(self, spec: Any, indenters: Any) -> np.ndarray:
        """Compressive strain [-] of every taxel, (rows, cols), under ``indenters`` pressed
        together (the layer model of :mod:`tactsense.physics.pad_response`)."""
        from tactsense.physics.pad_response import points_strain

        return points_strain(spec, indenters)

    def elastic_batch(
        self, spec: Any, states: Any, *, forward: str = "twin", alone: bool = True
    ) -> np.ndarray:
        """Fractional deflection [-] of every taxel for each state (a tuple of contacts
        held together), shape (S, rows, cols), before gains and the transducer.

        ``alone``: whether ``states`` are the whole scenario's states or a window of them
        whose path (where a kind has several) the whole scenario chose (see
        :meth:`elastic_window_alone`).
        """
        from tactsense.physics.pad_response import deflection_batch_flat

        return deflection_batch_flat(spec, states, self.layer_strain)

    def frame_blocks(self, spec: Any, run: Any, chunk_frames: int) -> Any:
        """The kind's own chain from contacts to counts for ``simulate``, or None (the
        default: the elastic deflection times gains through the transducer the spec's
        ``transduction`` names). A generator of ``(first, last, counts)``, counts of shape
        ``(last - first, *spec.frame_shape)``, frames ``chunk_frames`` at a time; ``run``
        holds what the simulation drew (``applied`` states, step ``boundaries`` [s],
        ``n_frames``, ``offsets`` (each taxel's instant in the scan [s]), ``active`` flaws,
        ``rng``, ``gains``)."""
        return None

    def elastic_window_alone(self, applied: Any) -> bool:
        """Whether a window of ``applied``'s states takes the path the whole would
        (``elastic_batch``'s ``alone``); a kind with one path: True."""
        return True

    def reads_capacitive(self, spec: Any) -> bool:
        """Whether the sensor reads through the paper's capacitive chain (eqs. 1-4)."""
        return spec.transduction.kind == "capacitive"

    def surface_grid(self, spec: Any) -> tuple[tuple[float, int], tuple[float, int]] | None:
        """The grid of taxels a surface scenario places indenters on: along x and along y
        the pitch [mm] and the number of taxels; None: no grid, an indenter is placed in
        the tangent plane of a taxel (``at_taxel``, by default the first)."""
        return None

    def size_text(self, spec: Any) -> tuple[str, str]:
        """(size, pitch) of a sensor in words, for ``sensor list``: the taxel count and
        the median distance from each taxel to its nearest [mm]."""
        positions = spec.taxel_positions_mm()
        gaps = np.linalg.norm(positions[:, None] - positions[None], axis=-1)
        np.fill_diagonal(gaps, np.inf)
        size = f"{spec.n_taxels} taxels"
        return size, f"{np.median(gaps.min(axis=1)):.3g} mm (nearest, median)"

    # ---- forms for other tools: LSL, URDF (r5-interop) -------------------------
    def lsl_taxel_fields(self, spec: Any) -> dict[str, np.ndarray]:
        """Extra metadata of each channel of the LSL frames outlet, beside its label,
        unit, type, location [mm], row and column: field name (units in the name, e.g.
        ``axial_mm``) -> one number per taxel in frame order (row-major), shape (N,).
        Default: none."""
        return {}

    def urdf_array(self, spec: Any) -> dict | None:
        """The sensor as the ROS tactile toolbox's flat ``<array>``: ``rows``, ``cols``,
        ``size_mm`` (x, y) [mm] of a taxel and ``spacing_mm`` (x, y) [mm] between taxels
        (row (row, col) at (row * spacing x, col * spacing y)); None (the default) to be
        written as a ``<taxel>`` list at the taxels' real positions and normals."""
        return None

    def urdf_taxels(self, spec: Any) -> list[tuple[float, float]]:
        """The ``<box>`` (x, y) [mm] of each taxel of a ``<taxel>`` list, frame order (x
        along the tangent the URDF writer picks: +x, the finger's axis, where it can).
        Default: a square of each taxel's area (``spec.areas_mm2``)."""
        areas = getattr(spec, "areas_mm2", None)
        if areas is None:
            raise self.unsupported(spec, "a URDF <taxel> list (no taxel areas)")
        return [(float(np.sqrt(a)), float(np.sqrt(a))) for a in areas]

    def urdf_note(self, spec: Any) -> str | None:
        """A comment written before the ``<taxel>`` list (what the list cannot say);
        default none."""
        return None

    def from_urdf_array(self, array: Any, base: Any, *, path: Any, preset: str) -> Any:
        """A sensor of this kind from a URDF ``<array>`` (a
        :class:`~tactsense.kinds.urdf.TactileArray`), the rest from ``base`` (the preset
        named ``preset``); a :class:`~tactsense.kinds.urdf.UrdfError` naming ``path`` if it
        does not fit. None (the default): this kind is not read from an ``<array>``."""
        return None

    def from_urdf_taxels(self, taxels: Any, base: Any, *, path: Any) -> Any:
        """A sensor of this kind from a URDF ``<taxel>`` list (a
        :class:`~tactsense.kinds.urdf.TactileTaxels`), the rest from ``base``; a
        :class:`~tactsense.kinds.urdf.UrdfError` naming ``path`` if it does not fit. None
        (the default): this kind is not read from a ``<taxel>`` list."""
        return None

    # ---- estimation (r5-estimate) ----------------------------------------------
    response_fit: ClassVar[bool] = False
    """Whether the kind tabulates its layer's response on a grid
    (:meth:`contact_response` with a window ``half``), so that ``find_contacts`` can fit
    it: the ``fit`` method, the sub-taxel refinement of ``interpolate``, a contact's
    force as the response's amplitude, and the reach of two point loads (pads)."""

    def contact_response(
        self, spec: Any, *, half: int = 0, n_sub: int = 8, signed: bool = False
    ) -> np.ndarray:
        """The response an estimator fits: the signal of the taxels per newton of the
        scenarios' probe (a 1.6-mm sphere) [-/N], from the kind's own forward model.

        Parameters
        ----------
        spec : the sensor's description
        half : int
            Half width of the window of taxels [taxel] (grid kinds).
        n_sub : int
            Sub-taxel positions of the probe per taxel along each axis (grid kinds).
        signed : bool
            A resistive taxel's strain before it is clipped at zero (grid kinds), so
            that the responses to several loads add up.

        Returns
        -------
        ndarray
            On a grid kind (:attr:`response_fit`), shape ``(n_sub + 1, n_sub + 1,
            2 half + 1, 2 half + 1)``: ``[a, b, i, j]`` the taxel at offset ``(i - half,
            j - half)`` from the taxel nearest below the probe, for the probe ``(a, b) /
            n_sub`` taxels from that taxel. On a kind without a grid, shape ``(N, N)``:
            row ``i`` for the probe centred on taxel ``i`` (``half``, ``n_sub`` unused).
        """
        raise self.unsupported(spec, "a contact response")

    # ---- frames from contacts (r6-fast) ----------------------------------------
    senses_shear: ClassVar[bool] = False
    """Whether the kind's forward model takes a contact's tangential force (the finger:
    its axial part); False: a :class:`~tactsense.simulate.ContactBatch`'s tangential
    forces are ignored, and :func:`~tactsense.simulate.frames_from_contacts` says so."""

    def contact_state(self, spec: Any, contacts: list[dict]) -> tuple:
        """One frame's contacts as the kind's own contact objects (what ``layer_strain``
        and ``elastic_batch`` take), from the dicts of ``ContactBatch.frame`` (position
        [mm] in the kind's surface coordinates, forces [N], radius [mm], shape). Default
        (a layer kind): a :class:`~tactsense.physics.indenters.SphereProbe` (Hertz
        pressure) or a :class:`~tactsense.physics.indenters.DiscProbe` at (x, y)."""
        from tactsense.physics.indenters import DiscProbe, SphereProbe

        made = []
        for c in contacts:
            cls = SphereProbe if c["shape"] == "sphere" else DiscProbe
            x, y = c["position_mm"]
            made.append(cls(x, y, c["normal_force_n"], radius_mm=c["radius_mm"]))
        return tuple(made)

    def contact_forward(self, spec: Any) -> Any:
        """The kind's fast forward for ``frames_from_contacts``, or None (the default:
        ``elastic_batch`` frame by frame, slow but any kind works). An object whose
        ``prepare(contacts)`` (a :class:`~tactsense.simulate.ContactBatch`) returns None
        (a batch it does not take: the reference runs) or a function ``(first, last) ->
        (last - first, rows * cols)`` (float32 or float64): every taxel's fractional
        deflection [-] (what ``elastic_batch`` gives, before gains) in those frames."""
        return None

    # ---- contacts of any size (r6-padfit) ----------------------------------------
    def contact_model(self, spec: Any) -> Any:
        """The model the ``joint`` method of ``find_contacts`` fits jointly to a frame's
        contacts, or None (the default: the kind has none). An object with
        ``signal(position_mm (k, 2), force_n (k,), radius_mm (k,))`` -> the frame's
        signal [-] under k round contacts of contact radius a [mm], ``a_top_mm`` (the
        largest a it covers), ``pitch_mm`` and ``modulus_star_pa`` [Pa]."""
        return None

    # ---- three-axis taxels and the untouched sensor (r8) -------------------------
    def shear_response(self, spec: Any, positions_mm: np.ndarray, **load: Any) -> np.ndarray:
        """The change of every taxel's reading per newton of normal force and of
        tangential force along x and y for a contact at each of ``positions_mm`` (P, 2)
        [mm], shape (P, 3, *spec.frame_shape) [counts/N]: what the three-axis estimator
        fits (``tactsense.estimate.triaxial``). Default: the kind has none."""
        raise self.unsupported(spec, "three-axis contact estimation (no shear response)")

    def rest_warnings(self, spec: Any) -> list[str]:
        """What is wrong with ``spec`` untouched, one line each (``sensor check``,
        ``simulate`` and ``mujoco`` print them), e.g. a rest reading already on the
        converter's rail. Default: nothing."""
        return []


RESPONSE_PROBE_N = 0.49
"""The load of the probe whose response :meth:`Kind.contact_response` tabulates: the
scenarios' 50-g sphere [N]."""


def signal_per_strain(spec: Any, strain: np.ndarray, *, signed: bool = False) -> np.ndarray:
    """A taxel's signal [-] from its compressive strain [-]: times the dielectric's strain
    gain on a capacitive taxel; on a resistive one the strain itself, clipped at zero (the
    cell does not read tension) unless ``signed``."""
    if spec.transduction.kind == "capacitive":
        return spec.transduction.strain_gain * strain
    return strain if signed else np.maximum(strain, 0.0)

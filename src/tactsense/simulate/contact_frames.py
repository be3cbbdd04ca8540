"""Frames from arrays of contacts: the batch call for physics engines and data sets.

:func:`frames_from_contacts` takes N frames of up to k contacts each (a
:class:`ContactBatch`: positions [mm], normal and tangential forces [N], indenter radius
[mm] and shape) and returns the N frames a sensor reads, with the kind's transduction and
its per-frame flaws, every frame on its own (nothing carries from one frame to the next).

The flaws are those of :func:`tactsense.simulate.simulate` that act on one frame alone,
applied exactly as its scan loop (``simulate/run.py``) applies them: ``gain_spread``,
``nonlinearity``, the transducer and its clipping (saturation), ``crosstalk``,
``noise``, ``quantization`` and ``dead`` taxels. The flaws with memory need a sequence
in time and are left out, whatever ``flaws`` asks: ``viscoelastic`` (delayed response
and creep), ``hysteresis`` and ``drift`` (piezoresistive cells). ``jitter`` is left out
too: the contacts given are the contacts applied (they are a data set's labels; jitter
them before the call to model a positioning error).

A kind answers the call through :meth:`tactsense.kinds.Kind.contact_forward` (its fast
forward, e.g. the pad's tabulated layer response) where it has one, else through its
``elastic_batch`` frame by frame (any kind works, slowly).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.kinds import kind_of
from tactsense.physics.transduction import sample_offsets
from tactsense.sensor import SpecBase

SHAPES = ("sphere", "disc")
"""Indenter shapes a :class:`ContactBatch` takes: ``"sphere"`` (Hertz's pressure over the
contact radius a rigid sphere of ``radius_mm`` makes on the half space at its force,
at most the radius) and ``"disc"`` (uniform pressure on a disc of ``radius_mm``)."""

MEMORY_FLAWS = ("viscoelastic", "hysteresis", "drift")
"""Flaws that need a sequence in time: never applied by :func:`frames_from_contacts`."""

LEFT_OUT_FLAWS = (*MEMORY_FLAWS, "jitter")
"""Every flaw :func:`frames_from_contacts` leaves out (``jitter``: the contacts given are
the contacts applied)."""


def named_left_out_flaws(flaws) -> list[str]:
    """The flaws of :data:`LEFT_OUT_FLAWS` that ``flaws`` names one by one (a comma
    string or names; none for "all" or "none", which mean the per-frame flaws that
    apply): a caller that must not accept a flaw it never applies raises on them."""
    from tactsense.simulate.run import _resolve_flaws

    if flaws is None or (isinstance(flaws, str) and flaws.strip() in ("all", "none")):
        return []
    return [name for name in _resolve_flaws(flaws) if name in LEFT_OUT_FLAWS]


class ShearIgnoredWarning(UserWarning):
    """Tangential forces were given to a kind whose forward model does not take them."""


def _per_contact(name, value, n, k) -> np.ndarray:
    """``value`` (a number or an (n, k) array) as an (n, k) array of floats, or a
    :class:`ContactBatchError` naming ``name`` and the shape expected."""
    array = _array(name, value)
    try:
        return np.broadcast_to(array, (n, k))
    except ValueError:
        raise ContactBatchError(
            f"{name} has shape {array.shape}; expected a number or ({n}, {k})"
        ) from None


class ContactBatchError(TactsenseInputError):
    """A :class:`ContactBatch` whose arrays do not fit together or hold bad values."""


def _array(name: str, value, shape: tuple[int, ...] | None = None) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ContactBatchError(f"{name} must be numbers; got {type(value).__name__}") from None
    if shape is not None and array.shape != shape:
        raise ContactBatchError(f"{name} has shape {array.shape}; expected {shape}")
    if not np.all(np.isfinite(array)):
        raise ContactBatchError(f"{name} must be finite (no NaN or infinity)")
    return array


@dataclass(frozen=True)
class ContactBatch:
    """N frames of up to k contacts each; a missing contact has normal force 0.

    Parameters
    ----------
    position_mm : (N, k, 2) ndarray
        Centre of each contact [mm] in the kind's surface coordinates: on a pad x along
        the rows and y along the columns (taxel (0, 0) at the origin); on a point set
        (x, y) seen from +z (the tangent plane of the taxel nearest to it); on the
        finger the axial position and the arc length around the skin, ``angle [rad] *
        radius_mm`` (the unwrapped plane of :mod:`tactsense.geometry`).
    normal_force_n : (N, k) ndarray
        Normal force of each contact [N], >= 0.
    tangential_force_n : (N, k, 2) ndarray or None
        Tangential force along the two surface coordinates [N]. Kinds whose layer model
        takes normal pressure only (pads, point sets) ignore it (:func:`frames_from_contacts`
        warns once, :class:`ShearIgnoredWarning`); the finger takes its axial part; a
        three-axis pad takes both (Cattaneo-Mindlin traction on a sphere).
    radius_mm : (N, k) ndarray or float
        Radius of each indenter [mm] > 0: a sphere's radius (its contact radius follows
        from its force, Hertz) or a disc's.
    shape : (N, k) ndarray of str, or str
        ``"sphere"`` or ``"disc"`` (:data:`SHAPES`) for every contact (kept as the
        string) or each.
    friction : (N, k) ndarray, float or None
        Friction coefficient mu of each contact [-] >= 0, for a kind that takes
        tangential forces (a three-axis pad: the Cattaneo-Mindlin stick radius
        ``c/a = (1 - Q/(mu P))^(1/3)``, gross slip at ``Q = mu P``). 0 or None: not known,
        and the tangential force is then taken as carried without slip at the rim
        (``mu = max(1, Q/P)``). A tangential force above ``mu P`` is gross slip.
    """

    position_mm: np.ndarray
    normal_force_n: np.ndarray
    tangential_force_n: np.ndarray | None = None
    radius_mm: np.ndarray | float = 1.6
    shape: np.ndarray | str = "sphere"
    friction: np.ndarray | float | None = None

    def __post_init__(self) -> None:
        force = _array("normal_force_n", self.normal_force_n)
        if force.ndim != 2:
            raise ContactBatchError(
                f"normal_force_n has shape {force.shape}; expected (N frames, k contacts)"
            )
        n, k = force.shape
        if np.any(force < 0):
            raise ContactBatchError("normal_force_n must be >= 0 [N] (a push; 0: no contact)")
        position = _array("position_mm", self.position_mm, (n, k, 2))
        tangential = (
            None
            if self.tangential_force_n is None
            else _array("tangential_force_n", self.tangential_force_n, (n, k, 2))
        )
        radius = _per_contact("radius_mm", self.radius_mm, n, k)
        if np.any(radius <= 0):
            raise ContactBatchError("radius_mm must be > 0 [mm]")
        if isinstance(self.shape, str):
            shape = self.shape
            unknown = [] if shape in SHAPES else [shape]
        else:
            shape = np.asarray(self.shape).astype(str)
            try:
                shape = np.broadcast_to(shape, (n, k))
            except ValueError:
                raise ContactBatchError(
                    f"shape has shape {shape.shape}; expected a string or ({n}, {k})"
                ) from None
            unknown = sorted(set(np.unique(shape).tolist()) - set(SHAPES))
        if unknown:
            raise ContactBatchError(
                f"unknown contact shape(s) {', '.join(unknown)}; expected {' or '.join(SHAPES)}"
            )
        object.__setattr__(self, "position_mm", position)
        object.__setattr__(self, "normal_force_n", force)
        object.__setattr__(self, "tangential_force_n", tangential)
        object.__setattr__(self, "radius_mm", radius)
        if self.friction is not None:
            friction = _per_contact("friction", self.friction, n, k)
            if np.any(friction < 0):
                raise ContactBatchError("friction must be >= 0 [-] (0: not known)")
            object.__setattr__(self, "friction", friction)
        object.__setattr__(self, "shape", shape)

    @property
    def n_frames(self) -> int:
        """N [-]."""
        return int(self.normal_force_n.shape[0])

    @property
    def max_contacts(self) -> int:
        """k, the contacts per frame at most [-]."""
        return int(self.normal_force_n.shape[1])

    def frame(self, index: int) -> list[dict]:
        """The contacts of one frame that touch (force > 0), each a dict of plain numbers:
        ``position_mm`` (2,), ``normal_force_n``, ``tangential_force_n`` (2,),
        ``radius_mm``, ``shape``, and ``friction`` [-] where the batch gives it (> 0)."""
        out = []
        for j in range(self.max_contacts):
            force = float(self.normal_force_n[index, j])
            if force <= 0:
                continue
            tangential = (
                (0.0, 0.0)
                if self.tangential_force_n is None
                else tuple(float(v) for v in self.tangential_force_n[index, j])
            )
            contact = {
                "position_mm": tuple(float(v) for v in self.position_mm[index, j]),
                "normal_force_n": force,
                "tangential_force_n": tangential,
                "radius_mm": float(self.radius_mm[index, j]),
                "shape": str(self.shape if isinstance(self.shape, str) else self.shape[index, j]),
            }
            if self.friction is not None and self.friction[index, j] > 0:
                contact["friction"] = float(self.friction[index, j])
            out.append(contact)
        return out

    def shape_masks(self, first: int = 0, last: int | None = None):
        """``(shape, chosen)`` for each shape present in frames ``first`` to ``last``:
        ``chosen`` a boolean (frames, k) array, or True when every contact has it."""
        if isinstance(self.shape, str):
            return [(self.shape, True)]
        part = self.shape[first:last]
        return [(name, part == name) for name in SHAPES if np.any(part == name)]

    def pressure_radius_mm(self, modulus_star_pa: float) -> np.ndarray:
        """Radius of each contact's pressure [mm], (N, k): a sphere's Hertz contact radius
        ``(3 F R / (4 E*))^(1/3)`` at most ``R`` (Johnson 1985, eq. 4.22, as
        :class:`~tactsense.physics.indenters.SphereProbe`), a disc's own radius.

        Parameters
        ----------
        modulus_star_pa : float
            Plane-strain modulus ``E / (1 - nu^2)`` of the layer [Pa].
        """
        radius = self.radius_mm
        hertz = 1e3 * np.cbrt(3.0 * self.normal_force_n * radius * 1e-3 / (4.0 * modulus_star_pa))
        sphere = np.minimum(hertz, radius)
        if isinstance(self.shape, str):
            return sphere if self.shape == "sphere" else np.array(radius, dtype=float)
        return np.where(self.shape == "sphere", sphere, radius)


def resolve_flaws(flaws) -> tuple[str, ...]:
    """The flaws :func:`frames_from_contacts` applies for ``flaws`` ("all", "none", a
    comma-separated string or names): the per-frame ones, in :data:`FLAW_NAMES` order."""
    from tactsense.simulate.run import _resolve_flaws

    return tuple(name for name in _resolve_flaws(flaws) if name not in LEFT_OUT_FLAWS)


def check_gains(spec, gains, active) -> np.ndarray:
    """Per-taxel gains [-], (rows, cols): ``gains`` checked, else the sensor's own
    (``gain_spread``, drawn from ``flaws.gain_seed`` as :func:`simulate` draws them), else
    ones."""
    from tactsense.physics.flaws import draw_gains

    if gains is not None:
        gains = _array("gains", gains)
        if gains.shape != tuple(spec.shape):
            raise TactsenseInputError(f"gains has shape {gains.shape}; expected {spec.shape}")
        return gains
    if "gain_spread" in active:
        return draw_gains(spec)
    return np.ones(spec.shape)


def frames_from_contacts(
    spec,
    contacts: ContactBatch,
    *,
    flaws="all",
    rng=None,
    gains: np.ndarray | None = None,
    fast: bool = True,
) -> np.ndarray:
    """The frames a sensor reads under N frames of contacts, each frame on its own.

    Parameters
    ----------
    spec : SensorSpec, PadSpec or PointsSpec
        The sensor (any registered kind).
    contacts : ContactBatch
        N frames of up to k contacts (positions [mm], forces [N], radii [mm], shapes).
    flaws : "all", "none" or iterable of str
        As :func:`tactsense.simulate.simulate`'s; the flaws with memory
        (:data:`MEMORY_FLAWS`) and ``jitter`` are left out whatever is asked.
    rng : int, numpy.random.Generator or None
        Source of the read noise.
    gains : (rows, cols) ndarray, optional
        Per-taxel gains [-] instead of the sensor's own (``gain_spread``).
    fast : bool
        Use the kind's fast forward (:meth:`Kind.contact_forward`) where it has one and
        it takes the batch (a pad's: tables up to a pressure radius of 5 mm, wider
        contacts summed in the layer's spectrum, up to radii of metres); False: the
        kind's ``elastic_batch`` frame by frame (the reference, whose pad pressure is
        sampled on a 0.5-mm grid: docs/batch-frames.md).

    Returns
    -------
    (N, rows * cols) ndarray of float64
        A/D counts of every taxel, frame order (row-major), as :func:`simulate`'s frames
        (whole numbers when ``quantization`` is on). A sensor of several components per
        taxel (``spec.components``, a three-axis pad): (N, rows * cols, components), the
        components last; its tangential forces go into the forward model (the reference
        path; ``fast`` has no effect on it).

    Notes
    -----
    Each frame's taxels are read at their own instants of the scan in :func:`simulate`;
    here the contacts are held over the frame, so every taxel reads the same contacts.
    """
    if not isinstance(spec, SpecBase):
        raise TactsenseInputError(
            "spec must be a sensor description (SensorSpec, PadSpec, PointsSpec); "
            f"got {type(spec).__name__}"
        )
    if not isinstance(contacts, ContactBatch):
        raise TactsenseInputError(f"contacts must be a ContactBatch; got {type(contacts).__name__}")
    active = resolve_flaws(flaws)
    gains = check_gains(spec, gains, active)
    rng = np.random.default_rng(rng)
    kind = kind_of(spec)
    shear = contacts.tangential_force_n
    if shear is not None and not kind.senses_shear and np.any(shear != 0):
        warnings.warn(
            f"tangential forces ignored: {spec.name!r}, a {kind.label}, takes normal pressure only",
            ShearIgnoredWarning,
            stacklevel=2,
        )
    forward = kind.contact_forward(spec) if fast else None
    block = forward.prepare(contacts) if forward is not None else None
    if block is not None:
        from tactsense.simulate._contact_chain import fast_frames

        return fast_frames(spec, contacts, block, active, gains, rng)
    return reference_frames(spec, contacts, active, gains, rng)


def reference_frames(spec, contacts: ContactBatch, active, gains, rng) -> np.ndarray:
    """The frames by :func:`simulate`'s own scan loop: each frame one step of the kind's
    contacts (``Kind.contact_state``), held for one scan period [counts], (N, taxels)."""
    from tactsense.simulate.run import _frame_blocks, _Run

    kind = kind_of(spec)
    n = contacts.n_frames
    applied = [kind.contact_state(spec, contacts.frame(i)) for i in range(n)]
    period = spec.scan_period_s
    run = _Run(
        active=tuple(active),
        rng=rng,
        gains=gains,
        applied=applied,
        n_frames=n,
        # the same arithmetic as the scan's tick times: frame i starts at i * period
        boundaries=np.arange(n + 1) * period,
        offsets=sample_offsets(spec),
    )
    # several components per taxel (r8-triphys): (N, taxels, components)
    out = np.empty((n, math.prod(spec.shape), *spec.frame_shape[2:]))
    if n == 0:
        return out
    for first, last, counts in _frame_blocks(spec, run):
        out[first:last] = counts.reshape(last - first, *out.shape[1:])
    return out


__all__ = [
    "LEFT_OUT_FLAWS",
    "MEMORY_FLAWS",
    "SHAPES",
    "ContactBatch",
    "ContactBatchError",
    "ShearIgnoredWarning",
    "frames_from_contacts",
]

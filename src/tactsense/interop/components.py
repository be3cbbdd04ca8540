"""How a frame's numbers are named and laid out in other tools' files, whatever the number
of components a taxel reports (``spec.components``: 1 for a scalar taxel, 3 for a
three-axis one, :mod:`tactsense.sensor.triaxial`).

One rule for every flat form (CSV columns, LSL channels, a flat LeRobot feature, the
interleaved ``TactileState`` channel): taxels in row-major order, a taxel's components
together in the order of ``spec.component_names`` (x, y, z: the pad's axes, x along the
rows, y along the columns, z the outward normal), the component fastest. That is the
order of ``frames.reshape(n, -1)`` for frames of shape ``(n, *spec.frame_shape)``. A
value is named ``r<row>c<col>`` for a scalar taxel and ``r<row>c<col><component>``
(``r0c1x``, ``r0c1y``, ``r0c1z``) for a taxel of several components.
"""

from __future__ import annotations

import numpy as np


def value_count(spec) -> int:
    """Numbers in one frame: taxels times components [-]."""
    return int(spec.n_taxels * spec.components)


def value_names(spec) -> list[str]:
    """The name of each number of a frame, in the flat order (component fastest)."""
    rows, cols = spec.shape
    parts = spec.component_names if spec.components > 1 else ("",)
    return [f"r{r}c{c}{p}" for r in range(rows) for c in range(cols) for p in parts]


def describe_values(spec) -> str:
    """``rows x cols = n taxels`` (with ``x 3 components = m values`` when several), for
    messages that say what a file should hold."""
    rows, cols = spec.shape
    text = f"{rows} x {cols} = {spec.n_taxels} taxels"
    if spec.components > 1:
        text += f" x {spec.components} components ({', '.join(spec.component_names)}) = "
        text += f"{value_count(spec)} values"
    return text


def component_channel_names(spec) -> list[str]:
    """The ``TactileState`` channel names of a sensor of several components: one channel
    per component, ``<sensor>/<component>`` (``mag4x4/x``, ``mag4x4/y``, ``mag4x4/z``);
    for a scalar sensor its own name alone."""
    if spec.components == 1:
        return [spec.name]
    return [f"{spec.name}/{p}" for p in spec.component_names]


def split_components(frames, spec) -> np.ndarray:
    """Frames ``(n, *frame_shape)`` as ``(n, components, rows*cols)``: each component's
    values in row-major taxel order (one ``TactileState`` channel per component)."""
    values = np.asarray(frames).reshape(-1, spec.n_taxels, spec.components)
    return np.ascontiguousarray(np.swapaxes(values, 1, 2))


def join_components(per_component, spec) -> np.ndarray:
    """The inverse of :func:`split_components`: ``(n, components, rows*cols)`` to
    ``(n, *frame_shape)``."""
    values = np.asarray(per_component).reshape(-1, spec.components, spec.n_taxels)
    return np.swapaxes(values, 1, 2).reshape(-1, *spec.frame_shape)


def pick_component_values(channels: list, spec, where: str, get) -> list:
    """One frame's values (flat order, component fastest) from a ``TactileState``'s
    channels (``get(channel, "name" | "values")``).

    Either a channel per component, ``<sensor>/<component>`` (as tactsense writes), each
    of rows x cols values; or one channel (the only one, or the one named as the sensor)
    of rows x cols x components values, interleaved (component fastest), as a driver that
    sends a taxel's vector together may publish.
    """
    from tactsense.interop._build import ImportError_

    by_name = {get(ch, "name"): ch for ch in channels}
    wanted = component_channel_names(spec)
    if all(name in by_name for name in wanted):
        per = [list(get(by_name[name], "values")) for name in wanted]
        for name, values in zip(wanted, per, strict=True):
            if len(values) != spec.n_taxels:
                rows, cols = spec.shape
                raise ImportError_(
                    f"{where}: channel {name!r} has {len(values)} values; {spec.name!r} has "
                    f"{rows} x {cols} = {spec.n_taxels} taxels"
                )
        return join_components(np.asarray(per, dtype=np.float64), spec).ravel().tolist()
    single = [ch for ch in channels if get(ch, "name") == spec.name]
    if not single and len(channels) == 1:
        single = list(channels)
    if len(single) == 1:
        values = list(get(single[0], "values"))
        if len(values) != value_count(spec):
            raise ImportError_(
                f"{where}: channel {get(single[0], 'name')!r} has {len(values)} values; "
                f"{spec.name!r} has {describe_values(spec)} (interleaved, component fastest)"
            )
        return values
    names = ", ".join(repr(get(ch, "name")) for ch in channels)
    raise ImportError_(
        f"{where}: a TactileState holds the channels {names}; expected "
        f"{', '.join(map(repr, wanted))} (one per component) or one channel "
        f"{spec.name!r} of {value_count(spec)} values (pass --sensor with the sensor's name)"
    )


def nested_lists(pa, flat, components: int, taxels: int):
    """``flat`` float32 values (component fastest) as ``taxels`` lists of ``components``
    (``list<float32>``): the innermost level of datasets' Array3D storage."""
    offsets = pa.array(np.arange(0, taxels * components + 1, components, dtype=np.int32))
    return pa.ListArray.from_arrays(offsets, flat)


def contact_shear(contacts: list[dict]) -> np.ndarray | None:
    """The tangential force the object applies [N], ``(k, 3)`` in the sensor's frame
    (``shear_x_n``, ``shear_y_n``, 0), of a live estimate's contacts when they carry it (a
    kind that senses shear); else None. A missing or non-finite value counts 0."""
    if not contacts or not any("shear_x_n" in c for c in contacts):
        return None
    out = np.zeros((len(contacts), 3))
    for k, contact in enumerate(contacts):
        for axis, name in enumerate(("shear_x_n", "shear_y_n")):
            value = contact.get(name)
            out[k, axis] = float(value) if value is not None and np.isfinite(value) else 0.0
    return out


SHEAR_FIELDS = ("shear_x_n", "shear_y_n")
"""The tangential force of a contact [N] along the sensor's x and y, as a shear-sensing
kind's contact table has it."""


def shear_state_names(slots: int) -> tuple[str, ...]:
    """LeRobot ``observation.state`` names of each slot's tangential force:
    ``contact{k}.shear_x_n``, ``contact{k}.shear_y_n`` [N]."""
    return tuple(f"contact{k}.{field}" for k in range(slots) for field in SHEAR_FIELDS)


def shear_state(table, start: int, n: int, slots: int) -> np.ndarray:
    """The shear part of ``observation.state`` for ``n`` frames, ``(n, 2 * slots)`` [N],
    from a contact table whose ``frame`` counts from ``start`` (slot = the contact's rank;
    0 in an empty slot, as the other slot fields)."""
    from tactsense._validation import TactsenseInputError

    out = np.zeros((n, 2 * slots), dtype=np.float32)
    if slots == 0:  # a kind that senses no shear: no columns
        return out
    frame = np.asarray(table.frame, dtype=np.int64) - start
    rank = np.asarray(table.contact, dtype=np.int64)
    for j, field in enumerate(SHEAR_FIELDS):
        values = table_column(table, field)
        if values is None:
            raise TactsenseInputError(
                f"the contact estimate has no {field} column; a shear-sensing sensor's "
                "LeRobot state needs the tangential force"
            )
        out[frame, rank * 2 + j] = np.nan_to_num(np.asarray(values, dtype=float))
    return out


def table_column(table, name: str):
    """A contact table's column ``name``: an attribute, or one of its ``extra`` columns
    (where the three-axis estimator keeps ``shear_x_n``, ``shear_y_n``); None if absent."""
    value = getattr(table, name, None)
    if value is None:
        value = (getattr(table, "extra", None) or {}).get(name)
    return value


def component_contacts(reader, *, baseline_frames: int, calibration, threshold,
                       max_contacts: int = 8):  # fmt: skip
    """The contacts of a recording whose taxels report several components, a piece at a
    time, ``(start, n, time_s, table, events)`` as ``tactsense.batch.iter_contacts`` gives
    a pad's: the three-axis estimator's (:mod:`tactsense.estimate.triaxial`, position,
    normal and tangential force), its table's ``extra`` holding ``shear_x_n`` and
    ``shear_y_n`` [N]. None when that estimator is not installed (the frames alone are
    then exported). ``threshold``: the export's ``--threshold``, a fraction of the
    converter's full scale, as ``locate`` takes it.
    """
    try:
        from tactsense.estimate.triaxial.locate import iter_shear_contacts
    except ImportError:
        return None
    counts = None if threshold is None else threshold * (2**reader.sensor.electronics.adc_bits - 1)
    return iter_shear_contacts(
        reader, baseline_frames=baseline_frames, calibration=calibration,
        threshold_counts=counts, max_contacts=max_contacts,
    )  # fmt: skip


def shear_vectors(table, keep) -> np.ndarray | None:
    """The contacts' tangential force ``(shear_x_n, shear_y_n, 0)`` [N] in the sensor's
    frame, the rows ``keep`` of a contact table, when the estimate has it (a kind that
    senses shear); else None. A non-finite value counts 0."""
    sx, sy = table_column(table, "shear_x_n"), table_column(table, "shear_y_n")
    if sx is None or sy is None:
        return None
    sx, sy = np.asarray(sx, dtype=float)[keep], np.asarray(sy, dtype=float)[keep]
    return np.nan_to_num(np.column_stack([sx, sy, np.zeros_like(sx)]))


def refuse_contact_options(sensor, calibration, threshold) -> None:
    """An export of the frames alone (no contact estimator for ``sensor``) refuses the
    options that apply to contacts, rather than ignoring them."""
    if calibration is not None or threshold is not None:
        from tactsense._validation import TactsenseInputError

        raise TactsenseInputError(
            f"--calibration and --threshold apply to contacts; no contact estimator is "
            f"installed for {sensor.name!r}, so its frames alone are exported"
        )

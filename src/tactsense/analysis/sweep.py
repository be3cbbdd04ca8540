"""Design maps: what section 6 of the paper trades off, over a grid of designs.

For every depth x spacing (x Poisson's ratio x load) of a finger otherwise like the
given one, :func:`design_sweep` computes

* ``counts_per_gram``: sensitivity, the A/D units a 50-g probe centred on a tactel moves
  the reading, per gram (eqs. 1-4 and the elastic model) [1/g];
* ``xi``: the aliasing of eq. 45, energy beyond the Nyquist rate [-];
* ``ripple_tactel``: the worst position error of the paper's interpolation for a line
  load (Fig. 20) [tactel];
* ``crb_axial_mm`` and ``crb_force_pct``: the Cramer-Rao bound on position along the
  finger and on force for a probe at the middle of the cylinder, with the finger's read
  noise (what any estimator can reach) [mm], [%];

as an :class:`xarray.Dataset` with units in the attributes. A design that does not fit
the finger (rings beyond the cylinder) is NaN. Each depth is one task, so a grid runs
on a Dask client (``client=``) as well as here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tactsense._validation import TactsenseInputError
from tactsense.analysis.aliasing import interpolation_errors, reconstruction_error
from tactsense.analysis.bound import cramer_rao_bound
from tactsense.kinds import kind_of, kinds
from tactsense.physics.array_response import tactel_deflection
from tactsense.physics.contact import Probe, grams_force
from tactsense.physics.transduction import deflection_to_counts
from tactsense.sensor import SensorSpec, SensorSpecError

VARIABLES = {
    "counts_per_gram": ("1/g", "A/D units per gram of a probe centred on a tactel"),
    "xi": ("1", "aliasing: share of eq. 45's energy beyond the Nyquist rate"),
    "ripple_tactel": ("tactel", "worst position error of the interpolation, line load"),
    "crb_axial_mm": ("mm", "Cramer-Rao bound on position along the finger"),
    "crb_force_pct": ("%", "Cramer-Rao bound on force"),
}


def design_point(
    sensor: SensorSpec, depth_mm: float, spacing_mm: float, poisson_ratio: float, grams: float
) -> dict[str, float]:
    """The map's variables for one design (NaN where the design does not fit)."""
    try:
        spec = sensor.replace(
            elastic__effective_depth_mm=depth_mm,
            elastic__effective_poisson_ratio=poisson_ratio,
            array__spacing_axial_mm=spacing_mm,
        )
    except SensorSpecError:
        return dict.fromkeys(VARIABLES, float("nan"))
    middle = spec.shape[0] // 2
    axial, angle = float(spec.row_axial_mm[middle]), float(spec.col_angle_deg[0])
    force = grams_force(grams)
    peak = float(tactel_deflection(spec, [Probe(axial, angle, force)])[middle, 0])
    counts = float(deflection_to_counts(spec, peak, quantize=False)) - float(
        deflection_to_counts(spec, 0.0, quantize=False)
    )
    positions = np.linspace(-0.5, 0.5, 41)
    ripple, _ = interpolation_errors(positions, depth_mm, spacing_mm, poisson_ratio)
    try:
        bound = cramer_rao_bound(spec, axial, angle, force)
        crb_axial, crb_force = bound["axial_mm"], 100 * bound["force_relative"]
    except TactsenseInputError:
        crb_axial = crb_force = float("nan")
    return {
        "counts_per_gram": counts / grams,
        "xi": float(reconstruction_error(depth_mm, spacing_mm, poisson_ratio)),
        "ripple_tactel": float(np.abs(ripple).max()),
        "crb_axial_mm": crb_axial,
        "crb_force_pct": crb_force,
    }


@dataclass(frozen=True)
class DesignMap:
    """How one design model (``Kind.design_model``) maps designs: its variables (name ->
    (unit, long name)), ``point(sensor, depth [mm], pitch [mm], poisson [-], grams [g])``
    giving them for one design, the command's default grid (``--depth``, ``--spacing``,
    ``--poisson`` as START:STOP:COUNT) and ``marks(sensor, poisson)``: the designs to mark
    on the plot (name -> (depth, pitch) [mm]) and a note naming those left out."""

    variables: dict
    point: Callable
    grid: dict
    marks: Callable


def _paper_marks(sensor, poisson_ratio: float):
    """The paper's two fingers (Table 1)."""
    from tactsense.sensor import load_sensor

    improved = load_sensor("improved")
    designs = {
        "initial": (3.8, 3.8),
        "improved": (improved.elastic.effective_depth_mm, improved.array.spacing_axial_mm),
    }
    return designs, None


def _layer_marks(sensor, poisson_ratio: float):
    """The pads the map describes (same layer and transduction), and a note on the rest."""
    from tactsense.analysis.pad_design import designs_on_map, left_out_note
    from tactsense.sensor import PRESETS

    pads = [make() for make in PRESETS.values()]
    designs, left_out = designs_on_map(sensor, pads, poisson_ratio)
    return designs, left_out_note(left_out, sensor.name)


def design_map(sensor) -> DesignMap:
    """The design map of a sensor's kind (``Kind.design_model``): the paper's finger
    (here), or a grid of taxels under an elastic layer
    (:mod:`tactsense.analysis.pad_design`); another kind has none (a one-line error)."""
    kind = kind_of(sensor)
    if kind.design_model == "paper":
        grid = {"depth": "2:6:9", "spacing": "2:3.8:7", "poisson": "0.4"}
        return DesignMap(VARIABLES, design_point, grid, _paper_marks)
    if kind.design_model == "layer":
        from tactsense.analysis import pad_design

        grid = {"depth": "0.5:4:8", "spacing": "1.5:5:8", "poisson": "0.5"}
        return DesignMap(pad_design.VARIABLES, pad_design.design_point, grid, _layer_marks)
    mapped = " and ".join(k.plural for k in kinds().values() if k.design_model)
    raise TactsenseInputError(
        f"design maps are made for {mapped}; {sensor.name!r} is a {kind.label}"
    )


def variables_of(sensor) -> dict[str, tuple[str, str]]:
    """The map's variables for a sensor's kind: a finger's, or a pad's
    (:mod:`tactsense.analysis.pad_design`)."""
    return design_map(sensor).variables


def _depth_slice(sensor_toml: str, depth, spacings, poissons, grams) -> np.ndarray:
    """All designs of one depth: array (spacing, poisson, grams, variable)."""
    sensor = SensorSpec.from_toml_string(sensor_toml)
    mapped = design_map(sensor)
    variables, point_of = mapped.variables, mapped.point
    out = np.full((len(spacings), len(poissons), len(grams), len(variables)), np.nan)
    for i, spacing in enumerate(spacings):
        for j, nu in enumerate(poissons):
            for k, g in enumerate(grams):
                point = point_of(sensor, depth, spacing, nu, g)
                out[i, j, k] = [point[name] for name in variables]
    return out


def design_sweep(
    sensor: SensorSpec,
    depths_mm: Sequence[float],
    spacings_mm: Sequence[float],
    *,
    poisson_ratios: Sequence[float] = (0.4,),
    grams: Sequence[float] = (50.0,),
    client=None,
    progress: Callable[[int, int], None] | None = None,
):
    """The design map over a grid; an :class:`xarray.Dataset` (see the module).

    Parameters
    ----------
    sensor : SensorSpec
        Everything but depth, axial spacing and Poisson's ratio comes from it.
    depths_mm, spacings_mm : sequence of float
        Effective depth and axial tactel spacing [mm].
    poisson_ratios : sequence of float
        Effective Poisson's ratio [-].
    grams : sequence of float
        Probe load [g].
    client : dask.distributed.Client, optional
        Run one task per depth on it; default here, one depth after the other.
    """
    import xarray as xr

    depths = [float(d) for d in depths_mm]
    spacings = [float(s) for s in spacings_mm]
    poissons = [float(p) for p in poisson_ratios]
    loads = [float(g) for g in grams]
    for name, values in (("depth", depths), ("spacing", spacings), ("load", loads)):
        if not values or min(values) <= 0 or not np.all(np.isfinite(values)):
            raise TactsenseInputError(f"every {name} must be a positive number; got {values}")
    if not poissons or not all(0.0 <= p < 0.5 + 1e-12 for p in poissons):
        raise TactsenseInputError(f"Poisson's ratios must lie in [0, 0.5]; got {poissons}")
    toml = sensor.to_toml_string()
    if client is None:
        slices = []
        for n, depth in enumerate(depths):
            slices.append(_depth_slice(toml, depth, spacings, poissons, loads))
            if progress is not None:
                progress(n + 1, len(depths))
    else:
        futures = client.map(
            _depth_slice,
            [toml] * len(depths),
            depths,
            [spacings] * len(depths),
            [poissons] * len(depths),
            [loads] * len(depths),
            pure=False,
        )
        slices = client.gather(futures)
    cube = np.stack(slices)  # depth, spacing, poisson, grams, variable
    coords = {
        "depth_mm": ("depth_mm", depths, {"units": "mm"}),
        "spacing_mm": ("spacing_mm", spacings, {"units": "mm"}),
        "poisson_ratio": ("poisson_ratio", poissons, {"units": "1"}),
        "load_g": ("load_g", loads, {"units": "g"}),
    }
    data = {
        name: (
            ("depth_mm", "spacing_mm", "poisson_ratio", "load_g"),
            cube[..., k],
            {"units": unit, "long_name": text},
        )
        for k, (name, (unit, text)) in enumerate(variables_of(sensor).items())
    }
    return xr.Dataset(
        data,
        coords=coords,
        attrs={"sensor": sensor.name, "sensor_toml": toml, "source": "tactsense design sweep"},
    )


def draw_map(dataset, *, designs: dict[str, tuple[float, float]], note: str | None = None):
    """The figure of :func:`plot_map` (matplotlib ``Figure``), not yet saved.

    Each named design is a star with its name beside it, on a white ground. A name goes
    first above or below its star (alternately, in order of spacing) on the side away
    from the nearer edge of the plot; where that would meet another name or star or leave
    the plot, the other side, below or above, then farther off, until one is clear: two
    designs of the same depth and close spacings (the paper's two fingers) or close
    depths and spacings (two pads) never write over each other. ``note``: one line under
    the panels.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    view = dataset.isel(poisson_ratio=0, load_g=0)
    d, s = view["depth_mm"].values, view["spacing_mm"].values
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2 if note is None else 4.5), layout="constrained")
    ordered = sorted(designs.items(), key=lambda item: (item[1][1], item[1][0]))
    pad = "crb_position_mm" in view
    for ax, (name, title) in zip(
        axes,
        (
            ("counts_per_gram", "sensitivity [A/D units per g]"),
            ("xi", "aliasing xi (eq. 45, in 2-D)" if pad else "aliasing xi (eq. 45)"),
            (
                "crb_position_mm" if pad else "crb_axial_mm",
                "best possible position sd [mm] (CRB)",
            ),
        ),
        strict=True,
    ):
        values = view[name].values.astype(float)
        unbounded = bool(np.isinf(values).any())
        values = np.where(np.isfinite(values), values, np.nan)  # inf: not observable, blank
        norm = None
        if name.startswith("crb") and np.nanmin(values, initial=np.inf) > 0:
            from matplotlib.colors import LogNorm

            finite = values[np.isfinite(values)]
            norm = LogNorm(finite.min(), finite.max()) if finite.size else None
        mesh = ax.pcolormesh(s, d, values, shading="nearest", cmap="viridis", norm=norm)
        fig.colorbar(mesh, ax=ax)
        if unbounded:
            title = f"{title}\n(blank: not observable, no overlap between taxels)"
        for _, (depth, spacing) in ordered:
            ax.plot(spacing, depth, "r*", ms=12, mec="white", mew=0.8)
        ax.set_xlabel("taxel pitch [mm]" if pad else "tactel spacing along the finger [mm]")
        ax.set_ylabel("sensing depth [mm]" if pad else "effective depth [mm]")
        ax.set_title(title, fontsize=10)
    nu, load = float(view["poisson_ratio"]), float(view["load_g"])
    fig.suptitle(f"Design map (nu = {nu:g}, {load:g}-g probe)")
    if note:
        import textwrap

        fig.supxlabel(textwrap.fill(note, 190), fontsize=9, color="0.25")
    # settle the layout, then keep it: the names are placed where they will be drawn
    fig.canvas.draw()
    fig.set_layout_engine("none")
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        _name_designs(ax, ordered, renderer)
    return fig


def _name_designs(ax, ordered, renderer) -> None:
    """Write each design's name beside its star where it meets no other name or star and
    stays inside the plot (see :func:`draw_map`)."""
    low, high = ax.get_xlim()
    inside = ax.get_window_extent(renderer)
    stars = []
    for _, (depth, spacing) in ordered:
        x, y = ax.transData.transform((spacing, depth))
        stars.append(_bbox(x - 7, y - 7, x + 7, y + 7))
    taken = []
    for k, (label, (depth, spacing)) in enumerate(ordered):
        away = -1 if spacing > 0.5 * (low + high) else 1  # toward the middle of the plot
        first = 1 if k % 2 == 0 else -1  # above, below, above...
        tried = [
            (side, up * distance)
            for distance in (9, 22, 36)
            for up in (first, -first)
            for side in (away, -away)
        ]
        own = stars[k]
        for n, (side, dy) in enumerate(tried):
            text = ax.annotate(
                label,
                (spacing, depth),
                color="r",
                fontsize=9,
                xytext=(6 * side, dy),
                textcoords="offset points",
                ha="left" if side > 0 else "right",
                va="bottom" if dy > 0 else "top",
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85},
            )
            box = text.get_window_extent(renderer).padded(2)
            clear = (
                box.x0 >= inside.x0
                and box.x1 <= inside.x1
                and box.y0 >= inside.y0
                and box.y1 <= inside.y1
                and not any(box.overlaps(other) for other in taken)
                and not any(box.overlaps(star) for star in stars if star is not own)
            )
            if clear or n == len(tried) - 1:
                taken.append(box)
                break
            text.remove()


def _bbox(x0: float, y0: float, x1: float, y1: float):
    """A matplotlib ``Bbox`` in display coordinates [px]."""
    from matplotlib.transforms import Bbox

    return Bbox.from_extents(x0, y0, x1, y1)


def plot_map(
    dataset, path, *, designs: dict[str, tuple[float, float]], note: str | None = None
) -> None:
    """Sensitivity, aliasing and the position bound over depth x spacing, with the named
    designs (name -> (depth, spacing)) marked and ``note`` under them; first Poisson's
    ratio and load."""
    import matplotlib.pyplot as plt

    fig = draw_map(dataset, designs=designs, note=note)
    fig.savefig(path, dpi=100)
    plt.close(fig)

"""Tabulate the 3-D finger's tip for ``simulate --forward finger3d``, and its mesh study.

Run: ``PYTHONPATH=src python scripts/finger3d_tip.py [--level 1] [--study]``. Solves the
finite-element half finger with its hemispherical tip (``tactsense.physics.finger3d_tip``:
rubber of nu 0.49 on the rigid core, which ends in a flat face 2.7 mm beyond the junction
so that 10 mm of rubber cover it at the apex, section 3.6) once per tactel functional, and
by reciprocity writes each tactel's strain per newton of the 50-g Hertz probe centred
anywhere on the skin to ``src/tactsense/physics/data/finger3d_tip.npz``:

* ``tip``: the tip row's tactel as its capacitor reads it, the mean normal strain of the
  dielectric between the core's end face and the plate (the plate's normal displacement
  over the gap, ``dd / d_o``), averaged over the electrode: the sector of the face under
  one strip, radius a/2 to a (the disc's outer half; the strips, 5.1 mm wide, cannot all
  reach the centre), the strip's width at the rim around. The gap is the 0.65 mm of
  rubber under a cylinder ring's plate (``PLATE_GAP``) on the solid skin, the foam layer
  with ``--foam``. Against the probe's surface coordinate ``s`` (apex to 12 mm along the
  cylinder) and its angle from the tactel. This mean converges under mesh refinement
  where the point strain at the plate does not (``docs/model.md`` section 3b).
* ``tip_rim``: the same over the outer quarter only (a/4 wide), to show how much the
  assumed plate matters.
* ``cylinder``: the radial strain at the ring depth of a cylinder tactel at axial
  position ``row_mm`` (0-12 mm), for probes on the hemisphere (``s < 0``), which the
  cylinder's table does not cover: the point strain on the solid skin, as the cylinder's
  own table (``finger3d_probe.npz``) reads it, so the two meet at the junction; the foam
  layer's mean strain with ``--foam``.

``--study`` also solves every level of ``TIP_LEVELS`` and stores each level's peaks in
the table's file (level 2, 140,580 dof in mixed form, did not finish within 10 minutes
on a shared 2-core machine). The tables are always those of ``--level`` (level 1, mixed:
about 80 s of CPU and 3.3 GB). ``--study-only`` solves a family of meshes with
``--formulation`` (peaks only, no tables: the shipped tables stay as they are) and records
them, mesh by mesh, in ``docs/data/finger3d_tip_study.json``: the levels, the ``radial``
family (level 0's surface, 3-5 elements through the rubber) or the ``surface`` family
(the levels' surfaces, 3 through; level 1's and level 2's together in about 90 s of
CPU, 3.4 GB at most). Each mesh records the tip's peak both as the table reads it (the gap's mean
strain) and as the point strain at the plate. docs/model.md quotes the study
(``scripts/finger3d_tip_figure.py`` reads it, with the observed orders and the
extrapolated peaks).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from tactsense.physics import finger3d_tip as tip
from tactsense.physics.finger3d import Dielectric

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "src" / "tactsense" / "physics" / "data"
STUDY = ROOT / "docs" / "data" / "finger3d_tip_study.json"
S_MM = np.round(np.r_[np.arange(tip.APEX_S_M * 1e3, 12.0, 0.25), 12.0], 4)
S_TIP_MM = S_MM[S_MM <= 0.5]
ANGLE_DEG = np.round(np.r_[np.arange(0.0, 40.0, 1.0), np.arange(40.0, 180.01, 4.0)], 3)
ROW_MM = np.round(np.arange(0.0, 12.01, 0.5), 3)
FORCE_N = 0.05 * 9.80665
STRIP_WIDTH_M = 5.1e-3


PLATE_GAP = Dielectric(tip.PLATE_ABOVE_CORE_M)
"""The rubber between the core and a tactel's plate as a "layer" for the functionals
only (never assembled): with it they read the mean normal strain over those 0.65 mm,
the plate's displacement over the gap, instead of the point strain at the plate."""
FOAM = Dielectric(0.5e-3, 7.0e4, 0.3)
"""The foam dielectric of section 2.3, as ``scripts/finger3d_table.py --foam`` has it."""


def tip_functional(solution, inner_fraction, n=8, layer=None, reading="mean"):
    """The tip tactel's functional over the sector of the end face (radius inner_fraction
    a to a, half the strip's angle: the half model).

    ``reading="mean"`` (the table's): the mean normal strain of the gap between the face
    and the plate, its top's normal displacement over its thickness (what the capacitor
    reads), the gap being the dielectric ``layer`` or, without one, ``PLATE_GAP`` (the
    0.65 mm of rubber under the plate). ``reading="point"``: the point normal strain at
    the plate, 0.65 mm above the face (the table before round 10; the mesh study)."""
    if reading == "mean" and layer is None:
        layer = PLATE_GAP
    elif reading == "point" and layer is not None:
        raise ValueError("the point strain is read on the solid skin only (no layer)")
    a = tip.CORE_M
    rho = inner_fraction * a + (np.arange(n) + 0.5) * (1 - inner_fraction) * a / n
    half = STRIP_WIDTH_M / (2 * a)
    theta = (np.arange(n) + 0.5) * half / n
    r, th = np.meshgrid(rho, theta, indexing="ij")
    above = tip.PLATE_ABOVE_CORE_M if layer is None else layer.thickness_m
    x = -(tip.CORE_END_M + above)
    points = np.stack([np.full(r.size, x), (r * np.sin(th)).ravel(), (r * np.cos(th)).ravel()])
    normals = np.tile([[-1.0], [0.0], [0.0]], (1, r.size))
    if layer is not None:
        g = solution.normal_displacement_functional(points, normals, r.ravel() / r.sum())
        return g / layer.thickness_m
    return solution.normal_strain_functional(points, normals, r.ravel() / r.sum())


def row_functional(solution, row_m, layer=None):
    """Radial strain at the ring depth over the load's meridian at axial ``row_m``; with
    a dielectric ``layer``, the layer's mean radial strain there."""
    if layer is not None:
        top = [[row_m], [0.0], [tip.CORE_M + layer.thickness_m]]
        g = solution.normal_displacement_functional(top, [[0.0], [0.0], [1.0]])
        return g / layer.thickness_m
    rho = tip.CORE_M + tip.PLATE_ABOVE_CORE_M
    return solution.normal_strain_functional([[row_m], [0.0], [rho]], [[0.0], [0.0], [1.0]])


def solve_level(level, with_tables, formulation="displacement", layer=None, spec=None):
    start = time.perf_counter()
    spec = tip.TIP_LEVELS[level] if spec is None else spec
    solution = tip.assemble(spec, formulation=formulation, dielectric=layer)
    s, angle = np.meshgrid(S_MM, ANGLE_DEG, indexing="ij")
    out = {"dofs": solution.n_dofs}
    for name, inner in (("tip", 0.5), ("tip_rim", 0.75)):
        v = solution.solve(tip_functional(solution, inner, layer=layer))
        out[name] = solution.influence(v, s, angle) if with_tables else None
        meridian = solution.influence(v, S_MM, 0 * S_MM)
        k = int(np.argmin(meridian))
        out[f"{name}_peak"] = (S_MM[k], meridian[k])
        if layer is None and not with_tables:  # the mesh study: the point strain too
            v = solution.solve(tip_functional(solution, inner, reading="point"))
            meridian = solution.influence(v, S_MM, 0 * S_MM)
            k = int(np.argmin(meridian))
            out[f"{name}_point_peak"] = (S_MM[k], meridian[k])
    if with_tables:
        s_tip, angle_tip = np.meshgrid(S_TIP_MM, ANGLE_DEG, indexing="ij")
        rows = [solution.solve(row_functional(solution, x * 1e-3, layer)) for x in ROW_MM]
        out["cylinder"] = np.stack([solution.influence(v, s_tip, angle_tip) for v in rows])
    row1 = solution.solve(row_functional(solution, 1.1e-3, layer))
    out["row1_at_junction"] = solution.influence(row1, 0.0, 0.0).item()
    out["row1_peak"] = solution.influence(row1, 1.1, 0.0).item()
    if layer is None and not with_tables:
        # the mesh study: row 1 read as a mean strain between the core and the plate (a
        # displacement over 0.65 mm) besides the point strain its table holds
        row1 = solution.solve(row_functional(solution, 1.1e-3, PLATE_GAP))
        out["row1_mean_peak"] = solution.influence(row1, 1.1, 0.0).item()
    out["seconds"] = time.perf_counter() - start
    peak_s, peak = out["tip_peak"]
    print(f"level {level}: {out['dofs']} dof, {out['seconds']:.0f} s; tip peak (mean "
          f"strain) {peak:.4g} per N at s = {peak_s:.2f} mm", flush=True)  # fmt: skip
    return out


RADIAL_N_T = (3, 4, 5)
"""The ``radial`` family: elements through the rubber on level 0's surface mesh (level 0
itself is its first member), the direction where the cylinder's error lies."""
SURFACE_N_T = 3
"""The ``surface`` family: the surface meshes of ``TIP_LEVELS`` (along the meridian and
around) with level 0's ``SURFACE_N_T`` elements through the rubber (level 0 itself is its
first member): cheaper than the levels, whose finest did not fit a solve's 10 minutes."""


def _study_row(level, spec, out) -> dict:
    """One mesh of the study. Its keys keep their recorded meaning: ``tip_peak`` and
    ``tip_rim_peak`` are the point strain at the plate, ``tip_mean_peak`` (the table's
    quantity since round 10) and ``tip_rim_mean_peak`` the gap's mean strain."""
    return {
        "level": level,
        "mesh": {"n_t": spec.n_t, "h_mm": spec.h_m * 1e3, "n_theta": spec.n_fine_theta},
        "dofs": int(out["dofs"]),
        "seconds": out["seconds"],
        "tip_peak": float(out["tip_point_peak"][1]),
        "tip_peak_s_mm": float(out["tip_point_peak"][0]),
        "tip_rim_peak": float(out["tip_rim_point_peak"][1]),
        "row1_peak": out["row1_peak"],
        "row1_at_junction": out["row1_at_junction"],
        "tip_mean_peak": float(out["tip_peak"][1]),
        "tip_mean_peak_s_mm": float(out["tip_peak"][0]),
        "tip_rim_mean_peak": float(out["tip_rim_peak"][1]),
        "row1_mean_peak": out["row1_mean_peak"],
    }


def study_only(formulation, family="levels", max_level=None) -> None:
    """Solve a family of meshes (peaks only) and record each as it lands, keeping what
    is recorded already: ``levels``, the levels of ``TIP_LEVELS`` up to ``max_level``
    (all if None); ``radial``, level 0's surface with ``RADIAL_N_T`` elements through the
    rubber; ``surface``, the levels' surfaces up to ``max_level`` with ``SURFACE_N_T``."""
    data = json.loads(STUDY.read_text()) if STUDY.exists() else {}
    if data.get("formulation") != formulation:
        data = {"formulation": formulation}
    if family == "levels":
        top = len(tip.TIP_LEVELS) - 1 if max_level is None else max_level
        specs = [(k, spec) for k, spec in enumerate(tip.TIP_LEVELS) if k <= top]
    elif family == "radial":
        specs = [(0, dataclasses.replace(tip.TIP_LEVELS[0], n_t=n)) for n in RADIAL_N_T]
    else:
        specs = [
            (k, dataclasses.replace(spec, n_t=SURFACE_N_T))
            for k, spec in enumerate(tip.TIP_LEVELS)
            if max_level is None or k <= max_level
        ]
    rows = data.setdefault(family, [])
    done = {(r["level"], r["mesh"]["n_t"]) for r in rows}
    for level, spec in specs:
        if (level, spec.n_t) in done:
            continue
        if family != "levels" and spec == tip.TIP_LEVELS[0]:
            known = [r for r in data.get("levels", []) if r["level"] == 0]
            if known:
                rows.append(known[0])
                continue
        out = solve_level(level, False, formulation, spec=spec)
        rows.append(_study_row(level, spec, out))
        STUDY.parent.mkdir(parents=True, exist_ok=True)
        tmp = STUDY.with_suffix(".tmp")
        tmp.write_text(json.dumps(data, indent=1))
        tmp.replace(STUDY)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=1, help="mesh level of TIP_LEVELS")
    parser.add_argument("--study", action="store_true", help="also solve every other level")
    parser.add_argument(
        "--study-only",
        choices=("levels", "radial", "surface"),
        help="solve a family of meshes (peaks only, the tables untouched) into "
        "docs/data/finger3d_tip_study.json: the levels up to --level, level 0's surface "
        "with 3, 4, 5 elements through the rubber, or the levels' surfaces up to --level "
        "with 3 through it",
    )
    parser.add_argument(
        "--formulation",
        choices=("mixed", "displacement"),
        default="displacement",
        help="finite elements: displacement only (the shipped table) or mixed u-p "
        "(locking-free, docs/model.md section 3a; slower)",
    )
    parser.add_argument(
        "--foam",
        action="store_true",
        help="the skin on the foam dielectric (FOAM; mixed elements): what the capacitor "
        "reads, the layer's mean strain, to finger3d_tip_foam.npz",
    )
    args = parser.parse_args(argv)
    layer = FOAM if args.foam else None
    formulation = "mixed" if args.foam else args.formulation
    if args.study_only:
        study_only(formulation, args.study_only, args.level)
        return
    levels = list(range(len(tip.TIP_LEVELS))) if args.study else [args.level]
    study = [solve_level(k, k == args.level, formulation, layer) for k in levels]
    main_level = study[levels.index(args.level)]
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / ("finger3d_tip_foam.npz" if args.foam else "finger3d_tip.npz")
    extra = {}
    if layer is not None:
        extra = {
            "dielectric_thickness_mm": layer.thickness_m * 1e3,
            "dielectric_modulus_pa": layer.youngs_pa,
            "dielectric_poisson_ratio": layer.poisson_ratio,
        }
    tmp = path.with_name(path.stem + ".tmp.npz")
    np.savez_compressed(
        tmp,
        **extra,
        s_mm=S_MM,
        s_tip_mm=S_TIP_MM,
        angle_deg=ANGLE_DEG,
        row_mm=ROW_MM,
        tip_strain_per_n=main_level["tip"].astype(np.float32),
        tip_rim_strain_per_n=main_level["tip_rim"].astype(np.float32),
        cylinder_strain_per_n=main_level["cylinder"].astype(np.float32),
        study_levels=np.array(levels),
        study_dofs=np.array([x["dofs"] for x in study]),
        study_seconds=np.array([x["seconds"] for x in study]),
        study_tip_peak=np.array([x["tip_peak"][1] for x in study]),
        study_tip_peak_s_mm=np.array([x["tip_peak"][0] for x in study]),
        study_tip_rim_peak=np.array([x["tip_rim_peak"][1] for x in study]),
        study_row1_peak=np.array([x["row1_peak"] for x in study]),
        study_row1_at_junction=np.array([x["row1_at_junction"] for x in study]),
        mesh_level=args.level,
        formulation=formulation,
        tip_reading=(
            "mean normal strain of the gap between the core's end face and the plate "
            f"({(layer or PLATE_GAP).thickness_m * 1e3:g} mm"
            + (", the foam layer" if layer is not None else " of rubber")
            + ") over the electrode"
        ),
        cylinder_reading=(
            "the foam layer's mean radial strain"
            if layer is not None
            else "point radial strain at the ring depth"
        ),
        poisson_ratio=0.49,
        youngs_modulus_pa=tip.YOUNGS_PA,
        core_end_mm=tip.CORE_END_M * 1e3,
        plate_above_core_mm=tip.PLATE_ABOVE_CORE_M * 1e3,
        strip_width_mm=STRIP_WIDTH_M * 1e3,
        description=(
            "tip: the gap's mean normal strain (tip_reading), cylinder rows: "
            "cylinder_reading, per newton of a 1.6-mm-radius Hertz sphere centred at surface "
            "coordinate s and angle from the tactel, on the 3-D finite-element finger with "
            "its tip (tactsense.physics.finger3d_tip); scripts/finger3d_tip.py"
        ),
    )
    tmp.replace(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()

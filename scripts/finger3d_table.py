"""Tabulate the three-dimensional finger's response for ``simulate --forward finger3d``.

Run: ``python scripts/finger3d_table.py [--level 1]``. Solves the finite-element model
of the skin (``tactsense.physics.finger3d``: a thick shell of nu 0.49 bonded to the
rigid core, triquadratic hexahedra with trilinear pressure, ``finger3d.TABLE_MESH``)
under the 50-g Hertz probe (a 1.6-mm-radius sphere) on top of the cylinder, and under
the knife edge of section 4.1 (10 mm around the finger, 0.2 mm wide), and writes the
radial strain at the ring depth (3.2 mm under the surface) per newton on a grid of
axial distance (0-24 mm) and angle (0-180 deg) from the load to
``src/tactsense/physics/data/finger3d_probe.npz``. With ``--foam``, the skin lies on the
foam dielectric of section 2.3 (0.5 mm, 7e4 Pa) and the table holds what the capacitor
reads, the layer's mean radial strain, in ``finger3d_probe_foam.npz``. The load is
symmetric about both planes through it, so the table covers every tactel's offset from a
probe on the cylinder. The skin is linear: the response to F newtons is F times the table.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from tactsense.physics import finger3d

OUT = Path(__file__).resolve().parents[1] / "src" / "tactsense" / "physics" / "data"
# fine near the load, where the strain peaks sharply; coarser beyond
AXIAL_MM = np.round(np.r_[np.arange(0.0, 4.0, 0.05), np.arange(4.0, 24.01, 0.25)], 3)
ANGLE_DEG = np.round(np.r_[np.arange(0.0, 20.0, 0.25), np.arange(20.0, 180.01, 2.0)], 3)
FORCE_N = 0.05 * 9.80665
KNIFE_FORCE_N, KNIFE_LENGTH_MM, KNIFE_WIDTH_MM = 0.5, 10.0, 0.2
FOAM = finger3d.Dielectric(0.5e-3, 7.0e4, 0.3)
"""The foam dielectric of section 2.3: 0.5 mm, its measured 7e4 Pa, nu 0.3 (a guess)."""


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--level",
        type=int,
        default=None,
        help="mesh level of finger3d.LEVELS (default: finger3d.TABLE_MESH)",
    )
    parser.add_argument(
        "--formulation",
        choices=("mixed", "displacement"),
        default="mixed",
        help="finite elements: mixed u-p (default) or displacement only (locks)",
    )
    parser.add_argument(
        "--foam",
        action="store_true",
        help="with the foam dielectric (FOAM) on the core: the capacitor's reading, the "
        "layer's mean strain (docs/model.md, section 3c), to finger3d_probe_foam.npz",
    )
    args = parser.parse_args(argv)
    spec = finger3d.TABLE_MESH if args.level is None else finger3d.LEVELS[args.level]
    start = time.perf_counter()
    layer = FOAM if args.foam else None

    def reading(solution, x, theta):
        if layer is None:
            return solution.radial_strain(x, theta)
        return solution.dielectric_strain(x, theta)

    pressure, radius = finger3d.hertz_probe(FORCE_N)
    solution = finger3d.solve_load(
        pressure, FORCE_N, spec=spec, dielectric=layer, formulation=args.formulation
    )
    x, theta = np.meshgrid(AXIAL_MM * 1e-3, np.radians(ANGLE_DEG), indexing="ij")
    strain = reading(solution, x, theta) / FORCE_N
    # the knife edge of section 4.1 as the twin presses it (a line 10 mm long around the
    # finger, 0.2 mm wide: tactsense.physics.contact.knife_edge)
    knife = finger3d.knife_edge(half_width_m=KNIFE_WIDTH_MM / 2e3, half_arc_m=KNIFE_LENGTH_MM / 2e3)
    knife_strain = reading(
        finger3d.solve_load(
            knife, KNIFE_FORCE_N, spec=spec, dielectric=layer, formulation=args.formulation
        ),
        x,
        theta,
    )
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / ("finger3d_probe_foam.npz" if args.foam else "finger3d_probe.npz")
    tmp = path.with_name(path.stem + ".tmp.npz")
    extra = {}
    if layer is not None:
        extra = {
            "dielectric_thickness_mm": layer.thickness_m * 1e3,
            "dielectric_modulus_pa": layer.youngs_pa,
            "dielectric_poisson_ratio": layer.poisson_ratio,
        }
    np.savez_compressed(
        tmp,
        **extra,
        axial_mm=AXIAL_MM,
        angle_deg=ANGLE_DEG,
        strain_per_n=strain,
        knife_strain_per_n=knife_strain / KNIFE_FORCE_N,
        knife_length_mm=KNIFE_LENGTH_MM,
        knife_width_mm=KNIFE_WIDTH_MM,
        ring_depth_mm=finger3d.RING_DEPTH_M * 1e3,
        poisson_ratio=0.49,
        youngs_modulus_pa=finger3d.YOUNGS_PA,
        contact_radius_mm=radius * 1e3,
        mesh_level=-1 if args.level is None else args.level,
        mesh_n_r=spec.n_r,
        mesh_n_fine=spec.n_fine,
        mesh_n_coarse=spec.n_coarse,
        mesh_fine_mm=spec.fine_m * 1e3,
        formulation=args.formulation,
        description=(
            (
                "mean radial strain of the foam dielectric"
                if args.foam
                else "radial strain eps_rr at the ring depth"
            )
            + " per newton of a 1.6-mm-radius Hertz "
            "sphere on the 3-D finite-element skin (tactsense.physics.finger3d), against "
            "the axial distance and the angle from the load; scripts/finger3d_table.py"
        ),
    )
    tmp.replace(path)
    print(f"wrote {path}: {strain.shape} in {time.perf_counter() - start:.1f} s; "
          f"peak {strain.min():.4g} per N at the load")  # fmt: skip


if __name__ == "__main__":
    main()

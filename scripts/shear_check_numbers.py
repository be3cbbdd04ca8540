"""The layer model's tangential response, checked: the figures of docs/model.md section 8.

Run: ``PYTHONPATH=src python scripts/shear_check_numbers.py [--write]`` (about a minute
on one core). It compares ``physics.layer.LayerResponse(..., tangential=True)`` under a
tangential disc traction with the two references of
``tactsense.analysis.layer_truth_shear`` (Cerruti's point force integrated over the
disc, for the half space; Hankel transforms of the order-1 fields, for the bonded
layer) and with the finite-element solution of ``tests/physics/test_layer_shear_fem.py``,
prints the block docs/model.md quotes (``--write`` replaces it there, between
``<!-- r7-shear -->`` and ``<!-- /r7-shear -->``) and draws
``docs/images/layer_shear_profiles.png``. ``tests/physics/test_layer_shear.py`` checks
the same comparisons against stated tolerances.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))
from docblock import replace_block, save_figure  # noqa: E402
from tests.physics import test_layer_shear_fem as fe  # noqa: E402

from tactsense.analysis import layer_truth_shear as truth  # noqa: E402
from tactsense.physics import layer  # noqa: E402

DOC = ROOT / "docs" / "model.md"
FIGURE = ROOT / "docs" / "images" / "layer_shear_profiles.png"
BEGIN, END = "<!-- r7-shear -->", "<!-- /r7-shear -->"
E = 2.5e5  # [Pa]
A = 1.5e-3  # disc radius [m]
F = 0.1  # tangential force [N]
H = 3e-3  # layer thickness [m]
DX = A / 12  # load sample spacing [m]
PROBES = [(0, 0), (0, 8), (0, -8), (10, 0), (12, 16), (-6, 24)]  # (row, col) from the centre
FIELDS = truth.QUANTITIES


def probe_xy():
    return np.array([c * DX for _, c in PROBES]), np.array([r * DX for r, _ in PROBES])


def fft_at_probes(load, depth, thickness, nu, padding=None):
    response = layer.LayerResponse(
        load.shape,
        DX,
        depth,
        thickness=thickness,
        youngs_modulus=E,
        poisson_ratio=nu,
        quantities=FIELDS,
        tangential=True,
        padding=padding,
    )
    out = response(np.zeros_like(load), load, None)
    c = load.shape[0] // 2
    return {q: np.array([out[q][c + r, c + k] for r, k in PROBES]) for q in FIELDS}


def errors(got, ref):
    """Largest |got - ref| over the probes, relative to the largest |ref| [-]."""
    return {q: float(np.max(np.abs(got[q] - ref[q])) / np.max(np.abs(ref[q]))) for q in FIELDS}


def reference_against_cerruti():
    x, y = probe_xy()
    worst = 0.0
    for nu in (0.3, 0.5):
        for z in (0.5 * A, A, 2 * A):
            kw = dict(youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
            hankel = truth.bonded_layer_shear_fields(x, y, z, thickness=np.inf, **kw)
            cerruti = truth.cerruti_disc_fields(x, y, z, **kw)
            worst = max(worst, max(errors(hankel, cerruti).values()))
    return worst


def layer_against_hankel():
    rows = []
    x, y = probe_xy()
    for profile in ("hertz", "uniform"):
        load = truth.sampled_disc_traction(128, DX, A, F, profile)
        for nu in (0.3, 0.5):
            for z in (0.5e-3, 1.5e-3, 2.5e-3):
                got = fft_at_probes(load, z, H, nu)
                ref = truth.bonded_layer_shear_fields(
                    x,
                    y,
                    z,
                    thickness=H,
                    youngs_modulus=E,
                    poisson_ratio=nu,
                    radius=A,
                    force=F,
                    profile=profile,
                )
                rows.append((profile, nu, z, errors(got, ref)))
    return rows


def surface_against_hankel():
    """(worst displacement error, worst strain error but eps_yz) on the surface z = 0."""
    load = truth.sampled_disc_traction(128, DX, A, F, "hertz")
    x, y = probe_xy()
    disp, strain = 0.0, 0.0
    for nu in (0.3, 0.5):
        got = fft_at_probes(load, 0.0, H, nu)
        ref = truth.bonded_layer_shear_fields(
            x, y, 0.0, thickness=H, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F
        )
        err = errors(got, ref)
        disp = max(disp, *(err[q] for q in FIELDS[:3]))
        strain = max(strain, *(err[q] for q in FIELDS[3:] if q != "eps_yz"))
    return disp, strain


def finite_elements():
    """Worst FEM-vs-Hankel errors (displacements, strains) per (nu, mesh), and layer.py
    against the coarse FEM."""
    rows = []
    for nu in (0.3, 0.45):
        for nr, nz in ((48, 15), (96, 31)):
            worst = fe.worst_errors(fe.fem_shear(nu, nr, nz), nu)
            rows.append(
                (
                    nu,
                    f"{nr} x {nz}",
                    max(worst[q] for q in ("U", "V", "W")),
                    max(worst[q] for q in ("eps_zz", "eps_rz")),
                )
            )
    dx, n = fe.A / 20, 128
    load = truth.sampled_disc_traction(n, dx, fe.A, fe.F, "hertz")
    cols = np.rint(fe.RADII / dx).astype(int)
    c = n // 2
    model = [0.0, 0.0]
    for nu in (0.3, 0.45):
        for z, fields in fe.fem_shear(nu).items():
            out = layer.LayerResponse(
                load.shape,
                dx,
                z,
                thickness=fe.H,
                youngs_modulus=fe.E,
                poisson_ratio=nu,
                quantities=("u_x", "u_z", "eps_zz", "eps_xz"),
                tangential=True,
            )(np.zeros_like(load), load, None)
            for i, pairs in enumerate(
                ((("u_x", "U"), ("u_z", "W")), (("eps_zz", "eps_zz"), ("eps_xz", "eps_rz")))
            ):
                for name, fe_name in pairs:
                    err = np.max(np.abs(out[name][c, c + cols] - fields[fe_name]))
                    model[i] = max(model[i], err / np.max(np.abs(fields[fe_name])))
    return rows, model


def thick_layer_limit():
    nu, n = 0.5, 96
    load = truth.sampled_disc_traction(n, DX, A, F, "hertz")
    x, y = probe_xy()
    rows = []
    ref = truth.cerruti_disc_fields(x, y, A, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
    for ratio in (5, 10, 20, 40, np.inf):
        padding = (7 * n, 7 * n) if ratio == np.inf else None
        fft = errors(fft_at_probes(load, A, ratio * A, nu, padding), ref)
        exact = errors(
            truth.bonded_layer_shear_fields(
                x,
                y,
                A,
                thickness=ratio * A,
                youngs_modulus=E,
                poisson_ratio=nu,
                radius=A,
                force=F,
            ),
            ref,
        )
        rows.append((ratio, exact, fft))
    return rows


def half_space_offset():
    nu, n, z = 0.5, 64, 1.5e-3
    load = truth.sampled_disc_traction(n, DX, A, F, "hertz")
    ref = truth.bonded_layer_shear_fields(
        0.0, 0.0, z, thickness=np.inf, youngs_modulus=E, poisson_ratio=nu, radius=A, force=F
    )["u_x"]
    out = []
    for grids in (1, 3, 7, 15):
        response = layer.LayerResponse(
            load.shape,
            DX,
            z,
            thickness=np.inf,
            youngs_modulus=E,
            poisson_ratio=nu,
            quantities=("u_x",),
            tangential=True,
            padding=(grids * n, grids * n),
        )
        got = response(np.zeros_like(load), load, None)["u_x"][n // 2, n // 2]
        out.append((grids, float(got / ref - 1)))
    return out


def draw(path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nu, z, n = 0.5, 1.0e-3, 128
    load = truth.sampled_disc_traction(n, DX, A, F, "hertz")
    response = layer.LayerResponse(
        load.shape,
        DX,
        z,
        thickness=H,
        youngs_modulus=E,
        poisson_ratio=nu,
        quantities=FIELDS,
        tangential=True,
    )
    out = response(np.zeros_like(load), load, None)
    c = n // 2
    cols = np.arange(-36, 37, 2)
    xs = cols * DX
    fine = np.linspace(xs[0], xs[-1], 181)
    kw = dict(youngs_modulus=E, poisson_ratio=nu, radius=A, force=F)
    layer_ref = truth.bonded_layer_shear_fields(fine, 0.0, z, thickness=H, **kw)
    half_ref = truth.bonded_layer_shear_fields(fine, 0.0, z, thickness=np.inf, **kw)
    panels = [("u_x", 1e6, "u_x [um]"), ("u_z", 1e6, "u_z [um]")]
    panels += [("eps_xz", 100, "eps_xz [%]"), ("eps_xx", 100, "eps_xx [%]")]
    panels += [("eps_zz", 100, "eps_zz [%]"), ("eps_yy", 100, "eps_yy [%]")]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6), sharex=True)
    for ax, (q, scale, label) in zip(axes.ravel(), panels, strict=True):
        ax.plot(1e3 * fine, scale * half_ref[q], ":", color="0.5", label="half space (Cerruti)")
        ax.plot(1e3 * fine, scale * layer_ref[q], "-", color="C0", label="bonded layer (Hankel)")
        ax.plot(
            1e3 * xs, scale * out[q][c, c + cols], "o", ms=3, color="C3", label="layer.py (FFT)"
        )
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("x [mm] (y = 0)")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(
        f"Hertzian tangential traction along +x, F = {F} N, a = {1e3 * A:g} mm; "
        f"layer h = {1e3 * H:g} mm, nu = {nu}, E = {E / 1e3:g} kPa; depth z = {1e3 * z:g} mm",
        fontsize=9,
    )
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    centre = np.argmin(np.abs(fine))
    return {q: float(layer_ref[q][centre] / half_ref[q][centre]) for q in ("u_x", "eps_xz")}


def block():
    cerruti = reference_against_cerruti()
    rows = layer_against_hankel()
    thick = thick_layer_limit()
    surface_disp, surface_strain = surface_against_hankel()
    fe_rows, fe_model = finite_elements()
    offset = half_space_offset()
    centre_ratio = draw(FIGURE)
    lines = [
        BEGIN,
        "<!-- generated by scripts/shear_check_numbers.py: do not edit by hand -->",
        "",
        "**Tangential load, checked** (issue 35 item 1; `tests/physics/test_layer_shear.py`).",
        "The model's response to a tangential surface traction (all three displacements and",
        "the six strains at a depth) against two solutions written apart from `layer.py`, in",
        "`tactsense.analysis.layer_truth_shear`: Cerruti's closed-form point force on the half",
        "space (Johnson 1985, eq. 2.19) integrated over the loaded disc, and the bonded layer",
        "of finite thickness by Hankel transforms in cylindrical coordinates (the azimuthal",
        "order-1 fields u_r = U cos theta, u_theta = V sin theta, u_z = W cos theta,",
        "transformed with orders 0, 2 and 1; Navier's equations solved per wavenumber by a",
        "numerical 4x4 system; Muki 1960), where `layer.py` solves Cartesian Fourier modes",
        "split into plane strain and anti-plane shear with Papkovich-Neuber potentials; and",
        "a finite-element solution (below). Surface loads and sign conventions as above. The",
        f"load: q_x = tau(r) on a disc of a = {1e3 * A:g} mm carrying F = {F} N, either",
        "Hertzian (`q0 sqrt(1 - r^2/a^2)`, the full-slip traction under a Hertz contact) or",
        f"uniform, sampled for `layer.py` at a / {round(A / DX)} with each sample the mean over",
        "its cell; six probes on and off the axes out to 2a. Errors are the largest difference",
        "over the probes relative to the field's largest magnitude there.",
        "",
        f"* The two references agree in the half space to **{cerruti:.1e}** of each field's",
        "  peak (nu = 0.3 and 0.5, z = a/2, a, 2a): the Cerruti strains are central",
        "  differences, which limit it. The layer reference also satisfies Navier's equations",
        "  (finite differences), u = 0 on the base and the surface tractions (the test).",
        f"* `layer.py` on the bonded layer (h = {1e3 * H:g} mm, E = {E / 1e3:g} kPa) against the",
        "  layer reference, in % of each field's peak:",
        "",
        "| load | nu | z [mm] | " + " | ".join(FIELDS) + " |",
        "|---|---|---|" + "---|" * len(FIELDS),
    ]
    for profile, nu, z, err in rows:
        cells = " | ".join(f"{100 * err[q]:.2f}" for q in FIELDS)
        lines.append(f"| {profile} | {nu} | {1e3 * z:g} | {cells} |")
    worst_hertz = max(max(e.values()) for p, _, _, e in rows if p == "hertz")
    worst_uniform_deep = max(max(e.values()) for p, _, z, e in rows if p == "uniform" and z > 1e-3)
    worst_uniform_top = max(max(e.values()) for p, _, z, e in rows if p == "uniform" and z < 1e-3)
    lines += [
        "",
        f"  At most {100 * worst_hertz:.2f} % under the Hertzian traction and"
        f" {100 * worst_uniform_deep:.2f} % under the uniform one at z >= h/2; the uniform",
        f"  disc's step edge, sampled on the grid, gives {100 * worst_uniform_top:.1f} % four"
        " samples below the surface (a sampling limit, as for pressure: sample the load",
        "  finer than the depth). The test allows 0.5 % (Hertzian, and uniform at z >= h/2),",
        "  and the same for a traction along y and at 30 degrees (q_x and q_y together).",
        f"  On the surface (z = 0, Hertzian) the displacements agree within"
        f" {100 * surface_disp:.2f} %; the",
        f"  strains there see the sampled load's edge unsmoothed: up to"
        f" {100 * surface_strain:.1f} % (not counting",
        "  eps_yz, which vanishes on the free surface).",
        "* A third solution by another method: **finite elements** (scikit-fem, quadratic",
        "  quadrilaterals on the (r, z) half-plane for the order-1 harmonic, clamped at 15 h;",
        "  `tests/physics/test_layer_shear_fem.py`) at z = h/4, h/2, 3h/4 and four radii out",
        "  to 1.9 a, largest error in % of each quantity's peak against the Hankel solution:",
        "",
        "| nu | elements (r x z) | displacements U, V, W | strains eps_zz, eps_rz |",
        "|---|---|---|---|",
        *(f"| {nu} | {mesh} | {100 * d:.3f} | {100 * e:.2f} |" for nu, mesh, d, e in fe_rows),
        "",
        "  The FEM converges onto the Hankel solution as its mesh is refined; `layer.py`",
        f"  (sampled at a / 20) against the coarse FEM directly: {100 * fe_model[0]:.2f} %"
        f" (displacements), {100 * fe_model[1]:.2f} %",
        "  (strains), mostly the FEM's own error.",
        "* The thick-layer limit: the fields at z = a (nu = 0.5, Hertzian) against Cerruti,",
        "  for the layer reference (exact) and for `layer.py`, largest error in %:",
        "",
        "| h / a | exact layer: displacements | exact: strains | layer.py: displacements"
        " | layer.py: strains |",
        "|---|---|---|---|---|",
    ]
    for ratio, exact, fft in thick:
        disp = [max(d[q] for q in FIELDS[:3]) for d in (exact, fft)]
        strain = [max(d[q] for q in FIELDS[3:]) for d in (exact, fft)]
        label = "inf (half space)" if ratio == np.inf else f"{ratio:g}"
        lines.append(
            f"| {label} | {100 * disp[0]:.2f} | {100 * strain[0]:.3f} | {100 * disp[1]:.2f} |"
            f" {100 * strain[1]:.3f} |"
        )
    lines += [
        "",
        "  The bonded base moves the fields by O(a / h) in displacement and faster in strain,",
        "  and `layer.py` follows the exact layer toward Cerruti until the automatic padding",
        "  (10 h) reaches its cap of 8 grids, from where on it no longer follows closely;",
        "  the half space (`thickness=np.inf`, here 7 grids of padding) gets the strains,",
        "  u_y and u_z but not **u_x, which decays as 1 / r: the padded FFT's periodic images",
        "  offset it almost uniformly** by an amount that halves as the period doubles (on the",
        "  axis at z = 1.5 mm, 64-sample grid: "
        + ", ".join(f"{100 * v:+.1f} % at {g} grid{'s' if g > 1 else ''}" for g, v in offset)
        + ").",
        "  Under pressure the surface w has the same limit (above). A bonded layer of finite",
        "  thickness has no such offset: its response dies out within a few h.",
        "* Nothing in `layer.py` had to change: the tangential path agrees with all three",
        "  within the sampling of the load (and, on the grid, obeys Betti's reciprocity between",
        "  pressure and traction to round-off: `test_betti_reciprocity_on_the_surface`).",
        "",
        "![Fields along x under a tangential disc traction](images/layer_shear_profiles.png)",
        "",
        "*Along the line y = 0 at z = 1 mm: `layer.py` (dots) on the bonded layer reference"
        " (line), and the half space (dotted) for scale: the base at 3 mm cuts u_x under the"
        f" centre to {centre_ratio['u_x']:.2f} of the half space's"
        f" (eps_xz: {centre_ratio['eps_xz']:.2f}).*",
        END,
    ]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="replace the block in docs/model.md")
    args = parser.parse_args()
    text = block()
    print(text)
    if args.write:
        replace_block(DOC, BEGIN, END, text)


if __name__ == "__main__":
    main()

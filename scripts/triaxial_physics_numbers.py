"""The three-axis pad's model, presets and checks: the figures of docs/triaxial.md's
``triphys`` block.

Run: ``PYTHONPATH=src python scripts/triaxial_physics_numbers.py [--write]`` (some 20 s).
It prints the presets' derived numbers (magnet moment, rest field), the checks of
``tests/physics/test_triaxial.py`` as measured figures (Cattaneo-Mindlin's traction
against its closed form, the point dipole against the magnet's cylinder), the signal a
50-g press and its shear give against the read noise, and the default ``slide-to-slip``
run's onset; ``--write`` replaces the block between ``<!-- r8-triphys -->`` and
``<!-- /r8-triphys -->`` in docs/triaxial.md and draws ``docs/images/triaxial_slip.png``.
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
from scipy import integrate  # noqa: E402
from tests.physics import test_triaxial as checks  # noqa: E402

from tactsense.flat_scenarios import FIFTY_GRAMS, shear, slide_to_slip  # noqa: E402
from tactsense.kinds.triaxial import MAGNET, SOURCES  # noqa: E402
from tactsense.physics import triaxial as tri  # noqa: E402
from tactsense.physics.indenters import SphereProbe  # noqa: E402
from tactsense.physics.pad_response import modulus_star_pa  # noqa: E402
from tactsense.sensor import preset  # noqa: E402
from tactsense.simulate import simulate  # noqa: E402

DOC = ROOT / "docs" / "triaxial.md"
FIGURE = ROOT / "docs" / "images" / "triaxial_slip.png"
BEGIN, END = "<!-- r8-triphys -->", "<!-- /r8-triphys -->"
MU0 = 4e-7 * np.pi


def preset_rows() -> list[str]:
    rows = []
    for name in ("mag4x4", "magtip"):
        spec = preset(name)
        t, g = spec.transduction, spec.grid
        rest = tri.rest_field_t(spec) * 1e6
        counts = tri.field_counts(spec, tri.rest_field_t(spec))
        middle = (g.rows // 2 - 1, g.cols // 2 - 1)
        rows.append(
            f"| `{name}` | {g.rows} x {g.cols} | {g.row_pitch_mm:g} mm | "
            f"{t.moment_a_m2 * 1e3:.3g} mA m^2 | {spec.layer.thickness_mm:g} mm, magnets "
            f"{spec.layer.sensing_depth_mm:g} mm deep, Hall {t.hall_depth_mm:g} mm | "
            f"{t.lsb_xy_ut:g} / {t.lsb_z_ut:g} uT | {rest[middle][2]:.0f} uT "
            f"({counts[middle][2]:.0f} counts) | {rest[0, 0, 0]:.0f}, {rest[0, 0, 1]:.0f}, "
            f"{rest[0, 0, 2]:.0f} uT |"
        )
    return rows


def traction_checks() -> dict:
    e_star, p, radius = checks.E_STAR, checks.P, checks.R
    out = {"quad": [], "grid": [], "stick": []}
    a = SphereProbe(0, 0, p, radius_mm=radius).contact_radius_mm(e_star)
    for ratio in (0.05, 0.3, 0.6, 0.9, 0.99):
        c = a * (1 - ratio) ** (1 / 3)
        total, _ = integrate.quad(
            lambda r, c=c: 2 * np.pi * r * 1e-6 * checks.closed_form_q(r, a, c, 0.8, p),
            0.0, a, points=[c], epsabs=0, epsrel=1e-11, limit=200,
        )  # fmt: skip
        out["quad"].append(abs(total / (ratio * 0.8 * p) - 1))
    for ratio in (0.2, 0.5, 0.8):
        probe = SphereProbe(0, 0, p, radius_mm=radius, shear_x_n=ratio * p)
        h = a / 60
        x = h * np.arange(-80, 81)
        q = tri.tangential_traction_pa(probe, x, x, modulus_star_pa=e_star)
        stick = tri.slip_state(probe)[1]
        expected = checks.cell_averaged(
            lambda r, s=stick: checks.closed_form_q(r, a, s * a, 1.0, p), x
        )
        out["grid"].append(np.max(np.abs(q - expected)) / expected.max())
    for ratio in (0.1, 0.4, 0.7, 0.95):
        probe = SphereProbe(0, 0, p, radius_mm=radius, shear_y_n=ratio * 0.6 * p, friction=0.6)
        h = a / 80
        x = h * np.arange(-100, 101)
        q = tri.tangential_traction_pa(probe, x, x, modulus_star_pa=e_star)
        pressure = probe.pressure_pa(x, x, modulus_star_pa=e_star)
        r = np.hypot(*np.meshgrid(x, x, indexing="ij"))
        read = r[(r < a - 2 * h) & (q < 0.999 * 0.6 * pressure)].max()
        out["stick"].append(abs(read - a * (1 - ratio) ** (1 / 3)) / h)
    out["a_mm"] = a
    return out


def dipole_checks(spec) -> dict:
    br, radius = MAGNET["remanence_t"], MAGNET["diameter_mm"] / 2e3
    height = MAGNET["height_mm"] * 1e-3
    gap = (spec.transduction.hall_depth_mm - spec.layer.sensing_depth_mm) * 1e-3
    m = spec.transduction.moment_a_m2

    def dipole(point):
        p = np.asarray(point)
        r = np.linalg.norm(p)
        return 1e-7 * (3 * m * p[2] * p / r**5 - np.array([0, 0, m]) / r**3)

    out = {}
    for label, point in (
        ("own sensor, on the axis", (0.0, 0.0, -gap)),
        ("own sensor, magnet moved 0.5 mm", (0.5e-3, 0.0, -gap)),
        ("own sensor, magnet moved 1 mm toward it", (0.0, 0.0, -(gap - 1e-3))),
        ("neighbour, 4.7 mm across", (spec.grid.row_pitch_mm * 1e-3, 0.0, -gap)),
    ):
        cylinder = checks.cylinder_field_t(point, radius, height, br / MU0)
        out[label] = np.linalg.norm(dipole(point) - cylinder) / np.linalg.norm(cylinder)
    return out


def signal_sizes(spec) -> dict:
    centre = (spec.grid.row_pitch_mm, spec.grid.col_pitch_mm)
    still = tri.rest_field_t(spec)
    press = SphereProbe(*centre, FIFTY_GRAMS, radius_mm=1.6)
    pushed = SphereProbe(*centre, FIFTY_GRAMS, radius_mm=1.6, shear_x_n=0.3 * FIFTY_GRAMS)
    d_press = tri.magnet_displacement(spec, [press])
    d_push = tri.magnet_displacement(spec, [pushed])
    b_press = tri.dipole_field_t(spec, d_press) + tri.background_field_t(spec)
    b_push = tri.dipole_field_t(spec, d_push) + tri.background_field_t(spec)
    lsb = spec.lsb_t
    return {
        "dz_um": -d_press[1, 1, 2] * 1e3,
        "dx_um": d_push[1, 1, 0] * 1e3,
        "bz_counts": (b_press - still)[1, 1, 2] / lsb[2],
        "bx_counts": (b_push - b_press)[1, 1, 0] / lsb[0],
        "modulus": modulus_star_pa(spec.layer),
    }


def slip_run(spec):
    scene = slide_to_slip(spec)
    rec = simulate(spec, scene, flaws="all", rng=0)
    slip = rec.truth["step_slip"][rec.truth["frame_step"]]
    first = int(np.argmax(slip == 2))
    return scene, rec, first


def figure(spec, scene, rec, first) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.8))
    a = SphereProbe(0, 0, checks.P, radius_mm=checks.R).contact_radius_mm(checks.E_STAR)
    h = a / 60
    x = h * np.arange(-80, 81)
    p0 = 3 * checks.P / (2 * np.pi * (a * 1e-3) ** 2)
    for ratio in (0.0, 0.3, 0.6, 0.9, 1.0):
        probe = SphereProbe(0, 0, checks.P, radius_mm=checks.R, shear_x_n=ratio * checks.P)
        q = tri.tangential_traction_pa(probe, x, x, modulus_star_pa=checks.E_STAR)[:, 80]
        left.plot(x / a, q / p0, label=f"Q/(mu P) = {ratio:g}")
    left.set_xlim(-1.2, 1.2)
    left.set_xlabel("x / a")
    left.set_ylabel("q / (mu p0)")
    left.set_title("Cattaneo-Mindlin traction (code, cell-averaged)")
    left.legend(fontsize=7)
    frames = rec.frames.astype(float)
    t = rec.time_s
    base = frames[10]
    right.plot(
        t, frames[:, 1, 1, 0] - base[1, 1, 0], label="taxel (1, 1), 3.3 mm from the contact: x"
    )
    right.plot(t, frames[:, 1, 1, 2] - base[1, 1, 2], label="taxel (1, 1): z")
    right.axvline(t[first], color="k", ls="--", label="gross slip (truth)")
    right.set_xlabel("time [s]")
    right.set_ylabel("change from rest [counts]")
    right.set_title(f"slide-to-slip on {spec.name}, all flaws")
    right.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, FIGURE)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="replace the block in the doc")
    args = parser.parse_args()
    spec = preset("mag4x4")
    traction = traction_checks()
    dipole = dipole_checks(spec)
    signal = signal_sizes(spec)
    scene, rec, first = slip_run(spec)
    shear_scene = shear(spec)
    lines = [
        BEGIN,
        "",
        "*Written by `scripts/triaxial_physics_numbers.py` (`--write`); the checks are "
        "`tests/physics/test_triaxial.py` and `tests/simulate/test_triaxial.py`.*",
        "",
        "**The model.** Each taxel is a magnet in the elastic layer over a three-axis Hall "
        "sensor on the substrate (`sensor/triaxial.py`). A contact's pressure and "
        "tangential traction load the free surface; the bonded layer's response "
        "(`LayerResponse(..., tangential=True)`, checked against Cerruti and a Hankel "
        "solution in docs/model.md) gives each magnet's displacement, averaged over its "
        "footprint; every sensor reads the point-dipole field of all the magnets (its own "
        "and its neighbours': the physical crosstalk of a magnetic skin) plus the "
        "background field, converted to counts (offset binary, zero field at 32768). "
        "Frames are `(rows, cols, 3)`, components x, y, z (x along the rows, z outward).",
        "",
        "**Tangential traction (Cattaneo-Mindlin).** A sphere's Hertz contact under a "
        "tangential force Q below mu P sticks in a central disc of radius "
        "`c = a (1 - Q/(mu P))^(1/3)` and slips in the annulus outside it: "
        "`q = mu p0 sqrt(1 - r^2/a^2) - mu p0 (c/a) sqrt(1 - r^2/c^2)` (r < c), along Q "
        "(Johnson 1985, ch. 7). The code writes the second term as the Hertz pressure of "
        "the same sphere under `P (c/a)^3` (whose contact radius is c), both cell-averaged "
        "and scaled to their loads, so the traction sums to Q exactly. At Q >= mu P the "
        "whole contact slides: `q = mu p`, the force passed is mu P. Other indenters: the "
        "traction is the pressure times min(Q, mu P)/P (a rigid flat punch's sticking "
        "traction has the pressure's shape; for a disc, a knife or a stamp an assumption: "
        "their partial slip is not modelled). Limits of the model: the contact radius "
        "is Hertz's on a half space (the layer's thickness ignored, as for the "
        "pressure); with nu = 0.5 the normal and tangential problems uncouple (Dundurs' "
        "beta = 0 for a rigid sphere on an incompressible layer), as Cattaneo-Mindlin "
        "assume; the traction depends on the present Q alone, so a tangential force "
        "ramped down retraces the loading solution (the reverse slip and hysteresis of "
        "Mindlin-Deresiewicz unloading are not modelled).",
        "",
        f"- The closed form integrated by quadrature (scipy) gives Q to "
        f"{max(traction['quad']):.1e} (relative) at Q/(mu P) = 0.05-0.99.",
        f"- The code's grid traction against the closed form averaged over each cell, at "
        f"Q/(mu P) = 0.2, 0.5, 0.8 on a grid of a/60 (a = {traction['a_mm']:.3g} mm, a "
        f"5-mm sphere under 50 g): largest difference "
        f"{100 * max(traction['grid']):.2f} % of the peak.",
        f"- The stick radius read back from where the traction stays below mu p: within "
        f"{max(traction['stick']):.2f} cells (a/80) of `(1 - Q/(mu P))^(1/3) a`, at "
        "Q/(mu P) = 0.1-0.95.",
        "",
        "**The magnet as a point dipole.** A 1 x 1 mm N42 cylinder (Br 1.32 T, an "
        "assumption), moment `Br V / mu0`, against the cylinder's own field (its face "
        "charges integrated numerically, itself checked against the closed form on the "
        "axis to 1e-10):",
        "",
        "| where | point-dipole error |",
        "|---|---|",
        *[f"| {label} | {100 * err:.2f} % |" for label, err in dipole.items()],
        "",
        "Signs (tests): a +x (+y) push moves the magnet under it +x (+y) and raises Bx "
        "(By) there; a press pushes it toward its sensor and raises Bz.",
        "",
        "**Presets** (the numbers' sources are in each preset's description):",
        "",
        f"> {SOURCES}.",
        "",
        "| preset | taxels | pitch | magnet moment | layer | LSB (x, y / z) | rest Bz, middle "
        "| rest field at the corner (x, y, z) |",
        "|---|---|---|---|---|---|---|---|",
        *preset_rows(),
        "",
        "Assumptions (no source found): the magnets' size, grade and depth, the layer's "
        "thickness and modulus, the Hall elements' depth, the read noise (3 counts: the "
        "MLX90393's noise table was not available to us), the flaws' sizes, and magtip's "
        "6 x 4 layout. The Earth's field (20, 0, -44) uT (48 uT, a mid-latitude value in "
        "the pad's frame as mounted) is always on (it is the world's, not a flaw).",
        "",
        f"**Signal against noise** on `mag4x4`, a 50-g, 1.6-mm sphere on taxel (1, 1): "
        f"the magnet sinks {signal['dz_um']:.1f} um and Bz rises "
        f"{signal['bz_counts']:.0f} counts; a tangential force of 0.3 P along x moves it "
        f"{signal['dx_um']:.1f} um more and raises Bx {signal['bx_counts']:.0f} counts, "
        f"against a read noise of {spec.flaws.read_noise_counts:g} counts.",
        "",
        "**Flaws** (`simulate --flaws`, frames deterministic for a seed): `gain_spread` "
        "(each sensor's sensitivity, 5 %, all three axes, and its offset per axis, 20 uT "
        "sd: the Hall element's offset and the magnet's placement at assembly; both drawn "
        "from the skin's own `gain_seed`), `noise` (3 counts), `quantization`, "
        "`viscoelastic` (the layer's memory on every displacement component: 10 % delayed "
        "at 50 ms, 5 % creep at 10 s, assumptions), `dead` (0 on all three axes); the "
        "neighbours' fields are the physical crosstalk (`transduction.neighbours`); the "
        "background field (`earth_field_*_ut`) is always read. `jitter` moves the "
        "indenters (their tangential force kept); `nonlinearity`, `hysteresis`, `drift` "
        "and `crosstalk` (the resistive and capacitive chains' habits) do not act on "
        "this kind.",
        "",
        "**Scenarios.** `simulate --scenario shear` presses a sphere, ramps a tangential "
        f"force to `--shear-ratio` (Q/P, default {shear_scene.parameters['shear_ratio']:g}) "
        "along `--shear-angle-deg`, holds it, ramps it down and lifts; `--scenario "
        "slide-to-slip` ramps it over `--ramp-s` past `--friction` (mu): slip spreads in "
        "from the edge, then at Q = mu P the whole contact slides at `--speed-mm-s`. "
        "Ramps move one step per scan period. `slide` on this kind drags the skin with "
        "the friction of gross slip (mu P, mu = 1) along the motion. Truth per step "
        "(any kind that senses shear and is pressed by indenters): `step_shear_x_n`, "
        "`step_shear_y_n` (the force passed, at most mu P), `step_slip` (0 stick, "
        "1 partial slip, 2 gross slip), `step_stick_ratio` (c/a); "
        "`scenario.parameters['slip_onset_s']` is the onset. "
        f"The default slide-to-slip on `mag4x4`: onset at "
        f"{scene.parameters['slip_onset_s']:.3f} s, frame {first} "
        f"({rec.frames.shape[0]} frames at {spec.electronics.scan_rate_hz:g} Hz).",
        "",
        "![Cattaneo-Mindlin traction and a slide-to-slip run](images/triaxial_slip.png)",
        "",
        "`frames_from_contacts` takes the contacts' tangential forces on this kind (the "
        "reference path, `simulate`'s own scan; frames `(N, taxels, 3)`); the forces "
        "given are the forces applied (friction taken as max(1, Q/P)).",
        "",
        END,
    ]
    text = "\n".join(lines)
    print(text)
    if args.write:
        replace_block(DOC, BEGIN, END, text)
        figure(spec, scene, rec, first)


if __name__ == "__main__":
    main()

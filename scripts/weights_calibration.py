"""Calibration with a box of weights, measured on the twin (docs/calibration.md, "Force
from weights alone").

Run: ``python scripts/weights_calibration.py [SENSOR ...]`` (default ``pad16``; about a
minute per sensor). For each sensor it runs the commands of :data:`COMMANDS` in a
temporary folder: a series of weights placed, held and removed on the twin (gain spread
on, read noise 1 % of full scale, the weights' mass exact), ``calibrate`` from the
weights alone, then ``locate`` on a second series of other weights (another seed) with
that calibration; and the same with the weights placed light to heavy and back
(hysteresis). It rewrites the block between ``<!-- weights:start -->`` and
``<!-- weights:end -->`` of docs/calibration.md and draws
``docs/images/calibration_weights.png``. ``tests/test_calibration_doc.py`` checks that
the document holds what :func:`block` computes.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docblock import replace_block, save_figure

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "calibration.md"
FIGURE = ROOT / "docs" / "images" / "calibration_weights.png"
START, END = "<!-- weights:start -->", "<!-- weights:end -->"

NOISE_SHARE = 0.01
"""The twin's read noise [share of the converter's full scale]: 1 %, as real arrays read
(issue 32), not the paper's 0.3 counts."""

SERIES_G = {
    "pad16": ("10:150:15", "15:145:14", "10,20,30,40,50,60,70,80,70,60,50,40,30,20,10"),
    "fsr16": ("20:400:20", "30:390:19", "20,60,100,140,180,220,260,220,180,140,100,60,20"),
}
"""Per sensor, the box of weights [g] (past saturation), a second series between the
first's, located with the calibration, and weights light to heavy and back (the
hysteresis). fsr16 reads 10 g within a few noise deviations of its threshold, where
``locate`` loses the held contact: its box starts at 20 g."""

COMMANDS = [
    "simulate --sensor SENSOR.toml --scenario loads --forces-g {weights} --dwell-s 2 "
    "--lift-s 2 --out weights.h5",
    "calibrate weights.h5 --force-log weights.csv --out cal.json",
    "simulate --sensor SENSOR.toml --scenario loads --forces-g {check} --dwell-s 2 "
    "--lift-s 2 --seed 7 --out check.h5",
    "locate check.h5 --calibration cal.json --out check.csv",
    "simulate --sensor SENSOR.toml --scenario loads --forces-g {updown} --dwell-s 2 "
    "--lift-s 2 --seed 3 --out updown.h5",
    "calibrate updown.h5 --force-log updown.csv --out updown.json",
]
"""The commands, with SENSOR.toml the twin described with :data:`NOISE_SHARE` of noise
and exact weights (:func:`describe`)."""


SENSORS = ("pad16", "fsr16")
"""The twins measured by default."""


def grams(spec: str) -> np.ndarray:
    """The masses of a ``--forces-g`` value [g]."""
    if ":" in spec:
        start, stop, count = spec.split(":")
        return np.linspace(float(start), float(stop), int(count))
    return np.array([float(v) for v in spec.split(",")])


def describe(sensor: str, folder: Path) -> tuple[Path, float]:
    """The twin of ``sensor`` as a lab's description: read noise :data:`NOISE_SHARE` of
    full scale, no force jitter (a weight's mass is exact). Returns the TOML's path and
    the default contact threshold [-] (five standard deviations of that noise)."""
    import tactsense as ts

    spec = ts.load_sensor(sensor)
    full = 2**spec.electronics.adc_bits - 1
    noise = NOISE_SHARE * full
    path = folder / f"{spec.name}_weights.toml"
    path.write_text(
        f'extends = "{spec.name}"\nname = "{spec.name}"\n\n[flaws]\n'
        f"read_noise_counts = {noise:.6g}\n"
        "force_jitter_n = 0.0\n",
        encoding="utf-8",
    )
    from tactsense.estimate.contacts import default_threshold

    return path, default_threshold(ts.load_sensor(path))


def as_measured(path: Path) -> None:
    """Mark a simulated recording as measured (its ``source`` attribute), as a lab's own
    array's recording is: neither ``calibrate`` nor ``locate`` then takes out the twin's
    creep (a real array's creep is not described unless ``creep_known``). (The twin's
    creep compensation, which ``locate`` applies to a simulation, amplifies 1 % of noise
    into a press-to-press scatter of the totals that is larger than the curve's error.)"""
    import h5py

    with h5py.File(path, "r+") as h5:
        h5.attrs["source"] = "the twin, as a lab's array (creep not described)"


def _weights_csv(path: Path, masses) -> None:
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("press,mass_g\n")
        for k, m in enumerate(masses, 1):
            stream.write(f"{k},{m:g}\n")


def run(sensor: str, folder: Path) -> dict:
    """Run :data:`COMMANDS` for ``sensor`` in ``folder``: the calibrations and the
    second series' per-press forces."""
    import os

    import pandas as pd
    from typer.testing import CliRunner

    import tactsense as ts
    from tactsense.cli import app
    from tactsense.estimate.contacts.array_calibration import load_calibration

    toml, threshold = describe(sensor, folder)
    weights, check, updown = SERIES_G[ts.load_sensor(sensor).name]
    _weights_csv(folder / "weights.csv", grams(weights))
    _weights_csv(folder / "updown.csv", grams(updown))
    runner = CliRunner()
    here = os.getcwd()
    os.chdir(folder)
    try:
        for line in COMMANDS:
            line = line.format(weights=weights, check=check, updown=updown).replace(
                "SENSOR.toml", toml.name
            )
            result = runner.invoke(app, line.split())
            if result.exit_code == 2 and line.startswith("calibrate weights.h5"):
                # refused with a reason (one line): that is the finding for this sensor
                said = " ".join(result.output.split()).removeprefix("error: ")
                return {"sensor": ts.load_sensor(toml), "refused": said}
            if result.exit_code != 0:
                raise RuntimeError(f"tactsense {line}: {result.output}")
            if line.startswith("simulate"):
                as_measured(Path(line.split("--out ")[1].split()[0]))
        cal = load_calibration("cal.json")
        updown = load_calibration("updown.json")
        rec = ts.read_recording("check.h5")
        table = pd.read_csv("check.csv")
    finally:
        os.chdir(here)
    return {"sensor": ts.load_sensor(toml), "threshold": threshold, "cal": cal,
            "updown": updown, "check": _check(rec, table, cal)}  # fmt: skip


def _check(rec, table, cal) -> list[dict]:
    """Each press of the second series: its load, and what ``locate`` gave over its
    settled part (the median of the frames' summed force; the share of those frames
    flagged beyond the calibration or saturated)."""
    from tactsense.estimate.contacts.array_calibration import _plateau
    from tactsense.estimate.finger.deflection import Flag

    step = np.asarray(rec.truth["frame_step"])
    force = np.asarray(rec.truth["step_force_n"])
    n = len(rec.frames)
    per_frame = np.zeros(n)
    flagged = np.zeros(n, bool)
    np.add.at(per_frame, table.frame.to_numpy(), table.force_n.fillna(0).to_numpy())
    bad = (table["flags"].to_numpy() & int(Flag.BEYOND_CALIBRATION | Flag.SATURATED)) != 0
    flagged[table.frame.to_numpy()[bad]] = True
    nan = np.zeros(n, bool)
    nan[table.frame.to_numpy()[table.force_n.isna().to_numpy()]] = True
    out = []
    for k in np.unique(step):
        if not (np.isfinite(force[k]) and force[k] > 0):
            continue
        frames = np.flatnonzero(step == k)
        settled = np.arange(n)[_plateau(int(frames[0]), int(frames[-1]) + 1)]
        out.append({
            "force_n": float(force[k]),
            "located_n": float(np.median(per_frame[settled])),
            "flagged_share": float(np.mean(flagged[settled])),
            "nan_share": float(np.mean(nan[settled])),
            "within": bool(force[k] <= cal.force_curve[1][-1]),
        })  # fmt: skip
    return out


def summary(result: dict) -> dict:
    """The figures the document quotes, from :func:`run`."""
    cal, check = result["cal"], result["check"]
    notes = cal.notes
    inside = [c for c in check if c["within"]]
    errors = [100 * (c["located_n"] / c["force_n"] - 1) for c in inside]
    beyond = [c for c in check if not c["within"]]
    hysteresis = result["updown"].notes["hysteresis"]
    return {
        "name": result["sensor"].name,
        "threshold": result["threshold"],
        "top_n": cal.force_curve[1][-1],
        "saturation": notes["saturation"],
        "loo": notes["loo_max_error_percent"],
        "loo_off": [
            (w["force_n"], w["loo_error_percent"])
            for w in notes["weights"]
            if w.get("loo_between") and abs(w["loo_error_percent"]) > 5.0
        ],
        "loo_rest": max(
            (
                abs(w["loo_error_percent"])
                for w in notes["weights"]
                if w.get("loo_between") and abs(w["loo_error_percent"]) <= 5.0
            ),
            default=float("nan"),
        ),
        "lightest": notes["loo_lightest_error_percent"],
        "check_within": len(inside),
        "check_error": max(abs(e) for e in errors) if errors else float("nan"),
        "check_light": min(c["force_n"] for c in inside) if inside else float("nan"),
        "check_light_error": errors[0] if errors else float("nan"),
        "check_rest_error": max(abs(e) for e in errors[1:]) if len(errors) > 1 else float("nan"),
        "check_beyond": len(beyond),
        "beyond_flagged": min((c["flagged_share"] for c in beyond), default=float("nan")),
        "beyond_nan": min((c["nan_share"] for c in beyond), default=float("nan")),
        "hysteresis": hysteresis,
    }


GRAM = 9.80665e-3
"""[N] per gram-force."""


def block(results) -> str:
    """The Markdown between the markers, from :func:`run` of each sensor."""
    refused = [r for r in results if "refused" in r]
    s = [summary(r) for r in results if "refused" not in r]
    rows = [
        "| measured on the twin (`python scripts/weights_calibration.py`) | "
        + " | ".join(f"`{v['name']}`" for v in s)
        + " |",
        "|---" * (len(s) + 1) + "|",
    ]

    def row(label, cells):
        rows.append(f"| {label} | " + " | ".join(cells) + " |")

    row("contact threshold (5 x the 1 % noise)", [f"{v['threshold']:.3g}" for v in s])
    row("calibrated range (heaviest unsaturated weight)",
        [f"{v['top_n'] / GRAM:.0f} g" for v in s])  # fmt: skip
    row("saturation flagged from",
        [f"{v['saturation']['from_n'] / GRAM:.0f} g ({v['saturation']['reason']})"
         if v["saturation"] else "none seen" for v in s])  # fmt: skip
    row("leave-one-out, weights between two others (largest error)",
        [f"{v['loo']:.1f} %" for v in s])  # fmt: skip
    row("  of which above 5 % / the largest of the others",
        [(", ".join(f"{f / GRAM:.0f} g ({e:+.1f} %)" for f, e in v["loo_off"]) or "none")
         + f" / {v['loo_rest']:.1f} %" for v in s])  # fmt: skip
    row("leave-one-out, the lightest (from the origin)", [f"{v['lightest']:+.1f} %" for v in s])
    row("second series within the range: presses, largest error",
        [f"{v['check_within']}, {v['check_error']:.1f} %" for v in s])  # fmt: skip
    row("  of which the lightest / the others",
        [f"{v['check_light'] / GRAM:.0f} g: {v['check_light_error']:+.1f} % / "
         f"{v['check_rest_error']:.1f} %" for v in s])  # fmt: skip
    row("second series beyond the range: presses, frames flagged (force NaN)",
        [f"{v['check_beyond']}, {100 * v['beyond_flagged']:.0f} % ({100 * v['beyond_nan']:.0f} %)"
         for v in s])  # fmt: skip
    row("hysteresis, light to heavy and back (largest difference, share of full scale)",
        [f"{v['hysteresis']['max_difference_n'] / GRAM:.1f} g, "
         f"{v['hysteresis']['percent_of_full_scale']:.1f} %"
         if v["hysteresis"]["measured"] else "not measured" for v in s])  # fmt: skip
    for r in refused:
        weights = SERIES_G[r["sensor"].name][0]
        rows.append(f"\n`{r['sensor'].name}` (weights {weights} g): `calibrate` refuses: "
                    f"\"{r['refused']}\"")  # fmt: skip
    return f"{START}\n" + "\n".join(rows) + f"\n{END}"


def figure(results, path: Path) -> None:
    """Total signal against load for each sensor's weights (the curve, the saturated
    presses, the top of the range) and each weight's leave-one-out error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = [r for r in results if "refused" not in r]
    fig, axes = plt.subplots(len(results), 2, figsize=(10, 3.6 * len(results)), squeeze=False)
    for (left, right), result in zip(axes, results, strict=True):
        cal = result["cal"]
        weights = cal.notes["weights"]
        g = np.array([w["force_n"] for w in weights]) / GRAM
        t = np.array([w["signal_total"] for w in weights])
        sat = np.array([w["saturated"] for w in weights])
        x, y = cal.force_curve
        left.plot(np.array(y) / GRAM, x, "-", color="C0", label="weight curve (knots)")
        left.plot(g[~sat], t[~sat], "o", color="C0", label="weights")
        left.plot(g[sat], t[sat], "x", color="C3", ms=8, label="saturated (flagged)")
        left.axhline(cal.curve_top, color="0.5", ls=":", label="top of the range")
        left.set_xlabel("weight [g]")
        left.set_ylabel("total signal [-]")
        left.set_title(f"{result['sensor'].name}: total signal per press")
        left.legend(fontsize=8)
        held = [(w["force_n"] / GRAM, w["loo_error_percent"]) for w in weights
                if w.get("loo_error_percent") is not None]  # fmt: skip
        step = float(np.min(np.diff(np.unique(g)))) if len(g) > 1 else 10.0
        right.bar([h[0] for h in held], [h[1] for h in held], width=0.6 * step, color="C0")
        right.axhline(5, color="C3", ls="--", lw=1)
        right.axhline(-5, color="C3", ls="--", lw=1)
        right.set_xlabel("weight held out [g]")
        right.set_ylabel("leave-one-out error [%]")
        right.set_title("each weight predicted from the others")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def measure(sensors) -> list[dict]:
    results = []
    for sensor in sensors:
        with tempfile.TemporaryDirectory() as folder:
            results.append(run(sensor, Path(folder)))
    return results


def main(argv=None) -> None:
    sensors = (argv if argv is not None else sys.argv[1:]) or list(SENSORS)
    results = measure(sensors)
    text = block(results)
    replace_block(DOC, START, END, text)
    figure(results, FIGURE)
    print(text)


if __name__ == "__main__":
    main()

"""Writing the reproduction report: report.md, a self-contained report.html, results.json."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

from tactsense.reproduce._common import Claim, Figure
from tactsense.reproduce.basis import (
    ARITHMETIC,
    BY_CONSTRUCTION,
    FITTED,
    HOLDOUTS,
    PREDICTED,
    RESTATED,
)


def _format(value: float | None) -> str:
    if value is None:
        return "-"
    return f"{value:.4g}"


def claims_table_markdown(claims: list[Claim]) -> str:
    """The claims table as Markdown."""
    lines = [
        "| id | the paper says | paper | tactsense | unit | difference | basis | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for claim in claims:
        diff = claim.relative_difference
        diff_text = "-" if diff is None else f"{100 * diff:+.1f} %"
        lines.append(
            f"| `{claim.id}` | {claim.statement} | {_format(claim.paper)} "
            f"| {_format(claim.computed)} | {claim.unit} | {diff_text} "
            f"| {claim.basis} | **{claim.verdict}** |"
        )
    return "\n".join(lines)


def summary(claims: list[Claim]) -> str:
    """One sentence: predictions that agree, and what the rest are."""
    predicted = [c for c in claims if c.basis == PREDICTED]
    agree = sum(c.verdict == "agrees" for c in predicted)
    echoes = [c for c in claims if c.basis in (FITTED, BY_CONSTRUCTION)]
    consistent = sum(c.verdict == "consistent" for c in echoes)
    sums = [c for c in claims if c.basis == ARITHMETIC]
    sums_agree = sum(c.verdict == "agrees" for c in sums)
    restated = sum(c.basis == RESTATED for c in claims)
    return (
        f"{agree} of {len(predicted)} predictions agree with the paper; "
        f"{consistent} of {len(echoes)} claims the twin was fitted to (or holds by "
        f"construction) are consistent, which is not evidence; {sums_agree} of {len(sums)} "
        "arithmetic checks of the paper's formulas agree"
        + (
            f"; {restated} restate a prediction in other units and are not counted."
            if restated
            else "."
        )
    )


def write_results(out: Path, claims: list[Claim], figures: list[Figure], meta: dict) -> Path:
    data = {
        "meta": meta,
        "claims": {claim.id: claim.to_dict() for claim in claims},
        "figures": [
            {
                "number": f.number,
                "label": f.name,
                "title": f.title,
                "file": f.path.name,
                "paper": f.paper_did,
                "simulated": f.simulated,
                "result": f.came_out,
            }
            for f in figures
        ],
    }
    path = out / "results.json"
    path.write_text(json.dumps(data, indent=1), encoding="utf-8")
    return path


BASIS_TEXT = (
    "The basis column says how each value was obtained: *predicted* (computed from "
    "parameters not set from this claim), *fitted* (a constant of the twin was chosen to "
    "match it; the note names it), *by construction* (true of the model by definition, "
    "e.g. a fit recovering the twin's own parameters, or a residual that is the twin's "
    "own noise), *arithmetic* (a formula of the paper evaluated, a unit conversion) or "
    "*restated* (a prediction already in the table, in other units: shown, not "
    "counted). Fitted and by-construction claims within tolerance are *consistent*, "
    "never *agrees*: they are echoes, not evidence."
)

INTRO = (
    "This report runs the experiments of R. S. Fearing, *Tactile Sensing Mechanisms* "
    "(IJRR 1990) on tactsense's digital twin of the finger and puts every quantitative "
    "claim of the paper next to what the model computes. Each figure says what the paper "
    "did, what was simulated and what came out. Where we disagree with the paper, the "
    "note says why: a misprint, an approximation the paper made, or a limit of the model."
)


def write_markdown(out: Path, claims: list[Claim], figures: list[Figure], meta: dict) -> Path:
    parts = [
        f"# Tactile Sensing Mechanisms, reproduced on the digital twin\n\n{INTRO}\n",
        f"Sensor: `{meta['sensor']}`; run: {meta['mode']}; tactsense {meta['version']}; "
        f"{meta['seconds']:.0f} s.\n",
        "## Claims\n",
        summary(claims) + "\n",
        BASIS_TEXT + "\n",
        claims_table_markdown(claims),
        "\n### Notes\n",
    ]
    for claim in claims:
        parts.append(
            f"- `{claim.id}` ({claim.basis}, {claim.verdict}): {claim.basis_note} {claim.note}"
        )
    parts.append("\n### Hold-out checks of the fitted constants\n")
    parts.extend(f"- **{constant}:** {text}" for constant, text in HOLDOUTS)
    parts.append("\n## Figures\n")
    for figure in sorted(figures, key=lambda f: f.number):
        parts.append(
            f"### {figure.name}: {figure.title}\n\n"
            f"![{figure.name}]({figure.path.name})\n\n"
            f"- **The paper:** {figure.paper_did}\n"
            f"- **Simulated:** {figure.simulated}\n"
            f"- **Result:** {figure.came_out}\n" + (f"\n{figure.table}\n" if figure.table else "")
        )
    path = out / "report.md"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


def write_html(out: Path, claims: list[Claim], figures: list[Figure], meta: dict) -> Path:
    e = html.escape
    rows = []
    for claim in claims:
        diff = claim.relative_difference
        colour = {"agrees": "#dff0d8", "consistent": "#e8eef7"}.get(claim.verdict, "#fcf8e3")
        rows.append(
            f"<tr style='background:{colour}'><td><code>{e(claim.id)}</code></td>"
            f"<td>{e(claim.statement)}</td><td>{e(_format(claim.paper))}</td>"
            f"<td>{e(_format(claim.computed))}</td><td>{e(claim.unit)}</td>"
            f"<td>{'-' if diff is None else f'{100 * diff:+.1f} %'}</td>"
            f"<td>{e(claim.basis)}</td><td><b>{e(claim.verdict)}</b></td>"
            f"<td>{e(claim.basis_note)} {e(claim.note)}</td></tr>"
        )
    sections = []
    for figure in sorted(figures, key=lambda f: f.number):
        data = base64.b64encode(figure.path.read_bytes()).decode("ascii")
        sections.append(
            f"<h3>{e(figure.name)}: {e(figure.title)}</h3>"
            f"<img alt='{e(figure.name)}' src='data:image/png;base64,{data}'>"
            f"<ul><li><b>The paper:</b> {e(figure.paper_did)}</li>"
            f"<li><b>Simulated:</b> {e(figure.simulated)}</li>"
            f"<li><b>Result:</b> {e(figure.came_out)}</li></ul>"
            + (f"<pre>{e(figure.table)}</pre>" if figure.table else "")
        )
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>Tactile Sensing Mechanisms, reproduced</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 2em auto; line-height: 1.4; }}
table {{ border-collapse: collapse; font-size: 0.85em; }}
td, th {{ border: 1px solid #bbb; padding: 4px 6px; vertical-align: top; }}
img {{ max-width: 100%; }}
</style></head><body>
<h1>Tactile Sensing Mechanisms, reproduced on the digital twin</h1>
<p>{e(INTRO)}</p>
<p>Sensor: <code>{e(meta["sensor"])}</code>; run: {e(meta["mode"])};
tactsense {e(meta["version"])}; {meta["seconds"]:.0f} s.</p>
<h2>Claims</h2>
<p><b>{e(summary(claims))}</b></p>
<p>{e(BASIS_TEXT)}</p>
<table><tr><th>id</th><th>the paper says</th><th>paper</th><th>tactsense</th><th>unit</th>
<th>difference</th><th>basis</th><th>verdict</th><th>why</th></tr>
{"".join(rows)}
</table>
<h3>Hold-out checks of the fitted constants</h3>
<ul>{"".join(f"<li><b>{e(c)}:</b> {e(t)}</li>" for c, t in HOLDOUTS)}</ul>
<h2>Figures</h2>
{"".join(sections)}
</body></html>
"""
    path = out / "report.html"
    path.write_text(page, encoding="utf-8")
    return path

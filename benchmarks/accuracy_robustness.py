"""The inverse-crime study of docs/accuracy.md: estimates on fingers that differ from
the estimator's description, without and with calibration.

Run: ``python benchmarks/accuracy_robustness.py`` (about 15 s); prints the tables that
docs/accuracy.md quotes. See :mod:`tactsense.analysis.robustness` for the setup.
"""

from __future__ import annotations

import tactsense as ts
from tactsense.analysis.robustness import markdown_table, robustness_study


def main() -> None:
    for name in ("initial", "improved"):
        spec = ts.preset(name)
        rows = robustness_study(spec, n_positions=48, seed=0)
        print(f"### {name} finger ({spec.description.split(':')[-1].strip()})\n")
        print(markdown_table(rows, spec))
        print()


if __name__ == "__main__":
    main()

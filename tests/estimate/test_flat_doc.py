"""The flat-contacts table of docs/contacts.md is what benchmarks/accuracy_flat.py gives."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_flat_block_is_what_the_script_gives(capsys):
    spec = importlib.util.spec_from_file_location(
        "accuracy_flat", ROOT / "benchmarks" / "accuracy_flat.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    text = module.main(write=False)
    assert text in (ROOT / "docs" / "contacts.md").read_text(encoding="utf-8"), (
        "run: python benchmarks/accuracy_flat.py --write"
    )

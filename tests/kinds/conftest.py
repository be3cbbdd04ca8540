"""The toy kind registers as a lab's package would: a ``toy_kind-0.0.dist-info`` with an
entry point in the ``tactsense.kinds`` group, in a directory on ``sys.path`` (and on the
``PYTHONPATH`` of every command the suite runs), so that ``importlib.metadata`` finds it
and ``tactsense.kinds.kinds()`` lists it next to the built-in kinds."""

from __future__ import annotations

import atexit
import importlib
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]

ENTRY_POINTS = """\
[tactsense.kinds]
hexpatch = toy_kind:KIND
"""

METADATA = """\
Metadata-Version: 2.1
Name: toy-kind
Version: 0.0
Summary: A hexagonal patch of taxels: the kind suite's toy kind (tests/kinds/toy_kind.py)
"""


def install_toy_kind(where: Path) -> Path:
    """Write the toy kind's distribution metadata (no code: the module stays in
    tests/kinds/) into ``where``; return ``where``."""
    info = where / "toy_kind-0.0.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text(METADATA)
    (info / "entry_points.txt").write_text(ENTRY_POINTS)
    return where


SITE = install_toy_kind(Path(tempfile.mkdtemp(prefix="toy_kind_site_")))
atexit.register(shutil.rmtree, SITE, ignore_errors=True)
PATHS = [str(SITE), str(HERE)]
for entry in reversed(PATHS):
    if entry not in sys.path:
        sys.path.insert(0, entry)
importlib.invalidate_caches()

from tactsense.kinds import registry  # noqa: E402  (after the path holds the toy)

registry.kinds.cache_clear()


@pytest.fixture(scope="session")
def cli_env() -> dict[str, str]:
    """The environment of a command: tactsense's src, and the toy kind's site and module
    (as a lab's installed package would be)."""
    import tactsense

    src = str(Path(tactsense.__file__).resolve().parents[1])
    # the user's own PYTHONPATH stays (a kind of theirs made visible through it joins)
    path = os.pathsep.join([src, *PATHS, *filter(None, [os.environ.get("PYTHONPATH")])])
    return dict(os.environ, PYTHONPATH=path, COLUMNS="200", NO_COLOR="1")

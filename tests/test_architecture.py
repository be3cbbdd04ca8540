"""The house rules, as tests (issue 33, item 4).

1. Import contracts (``[tool.importlinter]`` in pyproject.toml, run with import-linter):
   the layers of tactsense's packages, from the top down::

       cli
       reproduce
       analysis
       interop : view : cluster : plotting
       batch : stream : (flat_scenarios)
       estimate : simulate
       io
       kinds
       physics : (geometry)
       sensor
       _validation : _jit : _signals : _version

   (derived with grimp from main at 240fd91: every package imports only from its own
   layer and those below, except ``sensor.finger -> geometry``, the circle issue 33
   removes); estimation never imports the simulator (``simulate``, ``flat_scenarios``,
   ``physics.pad_response``, ``physics.indenters``); ``sensor`` and ``physics`` never
   import ``kinds``.
2. No import circle between two modules (every import grimp sees, in a function or not,
   except those under ``if TYPE_CHECKING:``).
3. No comparison of a sensor kind's name outside ``sensor/`` and ``kinds/`` (the names
   and spec classes of the registered kinds, ``tactsense.kinds.kinds()``), but for the
   few in :data:`ALLOWED`, each with its reason.
4. No source file over :data:`MAX_LINES` lines.

Each checker is also run on a planted violation, so that none can pass vacuously.
"""

from __future__ import annotations

import ast
import itertools
import os
import subprocess
import sys
import textwrap
import tomllib
from dataclasses import dataclass
from pathlib import Path

import grimp
import pytest
import tomli_w

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PACKAGE = SRC / "tactsense"
MAX_LINES = 600

# The comparisons of a kind's name allowed outside sensor/ and kinds/: at most six,
# (path under src/tactsense, the line's text stripped) -> why it stays.
ALLOWED: dict[tuple[str, str], str] = {}
MAX_ALLOWED = 6

# Where a kind's name may be compared: the descriptions and the kinds themselves.
KIND_HOMES = ("sensor", "kinds")


# ---- 1. import contracts ----------------------------------------------------------


def lint_imports(config: Path, pythonpath: Path, cwd: Path) -> subprocess.CompletedProcess:
    """Run import-linter's ``lint-imports`` on ``config`` with ``pythonpath`` first."""
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    code = "import sys; from importlinter.cli import lint_imports_command; lint_imports_command()"
    return subprocess.run(
        [sys.executable, "-c", code, "--no-cache", str(config)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def contracts() -> dict:
    """The ``[tool.importlinter]`` section of pyproject.toml."""
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]


def test_import_contracts_hold():
    result = lint_imports(ROOT / "pyproject.toml", SRC, ROOT)
    report = result.stdout + result.stderr
    assert result.returncode == 0, "import contracts broken:\n" + report
    assert "BROKEN" not in report


def test_import_contracts_are_the_stated_ones():
    config = contracts()
    by_id = {c["id"]: c for c in config["contracts"]}
    assert config["root_package"] == "tactsense"
    layers = by_id["layers"]["layers"]
    order = [layer.split(":")[0].strip(" ()") for layer in layers]
    # sensor at the bottom of tactsense proper, then physics, then kinds, then the rest
    assert order.index("sensor") > order.index("physics") > order.index("kinds")
    assert order.index("kinds") > order.index("estimate") > order.index("cli")
    assert order[0] == "cli"
    assert set(by_id["estimate-not-simulator"]["forbidden_modules"]) == {
        "tactsense.simulate",
        "tactsense.flat_scenarios",
        "tactsense.physics.pad_response",
        "tactsense.physics.indenters",
    }
    assert set(by_id["descriptions-below-kinds"]["source_modules"]) == {
        "tactsense.sensor",
        "tactsense.physics",
    }


def test_every_package_has_a_layer():
    """A new package or module of tactsense is placed in the layers (pyproject.toml), so
    that no part of the house escapes the contract unnoticed."""
    layered = set()
    for layer in contracts()["contracts"][0]["layers"]:
        layered |= {part.strip(" ()") for part in layer.split(":")}
    top = {
        path.stem if path.is_file() else path.name
        for path in PACKAGE.iterdir()
        if (path.suffix == ".py" or (path / "__init__.py").is_file())
    }
    missing = sorted(top - layered - {"__init__", "__main__"})
    assert not missing, f"not in any layer of [tool.importlinter] (pyproject.toml): {missing}"


def _plant_package(root: Path, violations: dict[str, str]) -> None:
    """A skeleton ``tactsense`` under ``root``: one empty package per layer (and the two
    physics modules estimation may not import), plus ``violations`` (package -> source of
    its ``__init__``)."""
    pkg = root / "tactsense"
    names = {"physics/pad_response.py", "physics/indenters.py", "__init__.py"}
    for layer in contracts()["contracts"][0]["layers"]:
        names |= {part.strip(" ()") + "/__init__.py" for part in layer.split(":")}
    for name in sorted(names):
        (pkg / name).parent.mkdir(parents=True, exist_ok=True)
        (pkg / name).write_text("")
    for name, source in violations.items():
        (pkg / name.removeprefix("tactsense.") / "__init__.py").write_text(source)


@pytest.mark.parametrize(
    ("violations", "message"),
    [
        ({}, None),
        (
            {"tactsense.sensor": "import tactsense.kinds\n"},
            "tactsense.sensor is not allowed to import tactsense.kinds",
        ),
        (
            {"tactsense.physics": "def f():\n    from tactsense import kinds\n"},
            "tactsense.physics is not allowed to import tactsense.kinds",
        ),
        (
            {"tactsense.estimate": "from tactsense.physics import pad_response\n"},
            "tactsense.estimate is not allowed to import tactsense.physics.pad_response",
        ),
        (
            {"tactsense.estimate": "import tactsense.simulate\n"},
            "tactsense.estimate is not allowed to import tactsense.simulate",
        ),
        (
            {"tactsense.kinds": "import tactsense.io\n"},
            "tactsense.kinds is not allowed to import tactsense.io",
        ),
    ],
    ids=[
        "clean",
        "sensor-kinds",
        "physics-kinds-lazy",
        "estimate-pad-response",
        "estimate-sim",
        "layer",
    ],
)
def test_import_contracts_catch_a_planted_violation(tmp_path, violations, message):
    _plant_package(tmp_path / "src", violations)
    config = tmp_path / "contracts.toml"
    config.write_text(tomli_w.dumps({"tool": {"importlinter": contracts()}}))
    result = lint_imports(config, tmp_path / "src", tmp_path)
    report = result.stdout + result.stderr
    if message is None:
        assert result.returncode == 0, report
    else:
        assert result.returncode != 0, report
        assert message in report, report


# ---- 2. no import circle ----------------------------------------------------------


def import_cycles(package: str) -> list[list[str]]:
    """Every circle of imports between modules of ``package``: one list of modules per
    strongly connected group (a shortest circle through its first module), sorted."""
    graph = grimp.build_graph(package, cache_dir=None, exclude_type_checking_imports=True)
    edges = {m: sorted(graph.find_modules_directly_imported_by(m)) for m in graph.modules}
    # Tarjan's strongly connected components, iteratively
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []
    counter = 0
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(edges[start]))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(edges[child])))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    group = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        group.append(member)
                        if member == node:
                            break
                    if len(group) > 1:
                        groups.append(sorted(group))
    cycles = []
    for group in sorted(groups):
        first = group[0]
        best: tuple[str, ...] | None = None
        for child in edges[first]:
            if child in group:
                chain = graph.find_shortest_chain(importer=child, imported=first)
                if chain and (best is None or len(chain) < len(best)):
                    best = chain
        circle = [first, *best] if best else group
        lines = []
        for importer, imported in itertools.pairwise(circle):
            details = graph.get_import_details(importer=importer, imported=imported)
            where = ", ".join(f"l.{d['line_number']}" for d in details) or "?"
            lines.append(f"{importer} -> {imported} ({where})")
        cycles.append([f"{len(group)} modules: {', '.join(group)}", *lines])
    return cycles


def test_no_import_circle():
    cycles = import_cycles("tactsense")
    report = "\n\n".join("\n  ".join(c) for c in cycles)
    assert not cycles, f"{len(cycles)} import circle(s):\n{report}"


def test_import_circle_check_catches_a_planted_circle(tmp_path, monkeypatch):
    pkg = tmp_path / "circle_pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from circle_pkg.sub import b\n")
    (pkg / "sub" / "b.py").write_text(
        "def f():\n    from circle_pkg import a  # lazy: still a circle\n"
    )
    (pkg / "c.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import circle_pkg.d\n"
    )
    (pkg / "d.py").write_text("import circle_pkg.c\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    cycles = import_cycles("circle_pkg")
    assert len(cycles) == 1, cycles
    assert cycles[0][0] == "2 modules: circle_pkg.a, circle_pkg.sub.b"
    assert "circle_pkg.sub.b -> circle_pkg.a (l.2)" in cycles[0]


# ---- 3. no comparison of a kind's name outside sensor/ and kinds/ ------------------


@dataclass(frozen=True)
class KindComparison:
    path: str
    line_number: int
    line: str
    what: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line_number}: {self.what}: {self.line}"


def kind_vocabulary() -> tuple[frozenset[str], frozenset[str]]:
    """The names of the registered sensor kinds and of their spec classes."""
    from tactsense.kinds import kinds

    every = kinds()
    return frozenset(every), frozenset(k.spec_class.__name__ for k in every.values())


def _strings(node: ast.AST) -> list[str]:
    """The string constants ``node`` is, or holds (a tuple, list or set of them)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [s for elt in node.elts for s in _strings(elt)]
    return []


def _names(node: ast.AST) -> list[str]:
    """The class names ``node`` refers to: ``A``, ``m.A``, ``(A, B)``, ``A | B``."""
    if isinstance(node, ast.Name):
        return [node.id]
    if isinstance(node, ast.Attribute):
        return [node.attr]
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [n for elt in node.elts for n in _names(elt)]
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr):
        return _names(node.left) + _names(node.right)
    return []


def _is_about_a_kind(node: ast.AST) -> bool:
    """Whether an expression names a kind: ``spec.kind``, ``kind``, ``sensor_kind``,
    ``getattr(s, "kind", ...)``, ``meta.get("kind")``, ``_kind_of(r)``... (so that a
    ROS frame called ``"finger"`` or a transduction kind is not a sensor kind)."""
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name) and "kind" in sub.id.lower():
            return True
        if isinstance(sub, ast.Attribute) and "kind" in sub.attr.lower():
            return True
        if isinstance(sub, ast.Constant) and sub.value == "kind":
            return True
    return False


def _is_transduction(node: ast.AST) -> bool:
    return any(
        isinstance(sub, ast.Attribute | ast.Name)
        and "transduction" in (sub.attr if isinstance(sub, ast.Attribute) else sub.id)
        for sub in ast.walk(node)
    )


def kind_comparisons(
    path: Path, label: str, names: frozenset[str], classes: frozenset[str]
) -> list[KindComparison]:
    """Every place in one source file that dispatches on a sensor kind's name."""
    source = path.read_text()
    lines = source.splitlines()
    found: list[KindComparison] = []

    def hit(node: ast.AST, what: str) -> None:
        text = lines[node.lineno - 1].strip() if node.lineno <= len(lines) else ""
        found.append(KindComparison(label, node.lineno, text, what))

    for node in ast.walk(ast.parse(source, filename=str(path))):
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            for left, op, right in zip(operands, node.ops, operands[1:], strict=False):
                for a, b in ((left, right), (right, left)):
                    named = names.intersection(_strings(b))
                    if named and _is_about_a_kind(a) and not _is_transduction(a):
                        hit(node, f"compares a kind with {sorted(named)}")
                        break
                    if isinstance(
                        op, ast.Is | ast.IsNot | ast.Eq | ast.NotEq
                    ) and classes.intersection(_names(b)):
                        hit(node, "compares a type with a kind's spec class")
                        break
                else:
                    continue
                break
        elif isinstance(node, ast.Match):
            for case in node.cases:
                for sub in ast.walk(case.pattern):
                    if (
                        isinstance(sub, ast.MatchValue)
                        and names.intersection(_strings(sub.value))
                        and _is_about_a_kind(node.subject)
                    ):
                        hit(case.pattern, "matches a kind's name")
                    elif isinstance(sub, ast.MatchClass) and classes.intersection(_names(sub.cls)):
                        hit(case.pattern, "matches a kind's spec class")
        elif isinstance(node, ast.Call):
            func = node.func
            called = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
            if called in ("isinstance", "issubclass") and len(node.args) == 2:
                if classes.intersection(_names(node.args[1])):
                    hit(node, f"{called} with a kind's spec class")
            elif called == "require_kind":
                hit(node, "require_kind")
            elif called == "dict" and names.intersection(k.arg for k in node.keywords if k.arg):
                hit(node, "a dict keyed by kind names")
        elif isinstance(node, ast.Dict):
            keys = [s for k in node.keys if k is not None for s in _strings(k)]
            if names.intersection(keys):
                hit(node, f"a dict keyed by kind names {sorted(names.intersection(keys))}")
    return sorted(set(found), key=lambda c: (c.path, c.line_number, c.what))


def scan_kind_comparisons(package: Path, homes=KIND_HOMES) -> list[KindComparison]:
    """:func:`kind_comparisons` over every module of ``package`` outside ``homes``."""
    names, classes = kind_vocabulary()
    found = []
    for path in sorted(package.rglob("*.py")):
        label = path.relative_to(package).as_posix()
        if label.split("/")[0] in homes:
            continue
        found += kind_comparisons(path, label, names, classes)
    return found


def test_allowlist_is_short_and_explained():
    print(f"\n{len(ALLOWED)} comparison(s) of a kind's name allowed outside sensor/ and kinds/:")
    for (path, line), reason in ALLOWED.items():
        print(f"  {path}: {line}\n      because {reason}")
    assert len(ALLOWED) <= MAX_ALLOWED
    assert all(reason.strip() for reason in ALLOWED.values())


def test_no_kind_name_comparison_outside_the_kinds():
    found = scan_kind_comparisons(PACKAGE)
    used = {(c.path, c.line) for c in found if (c.path, c.line) in ALLOWED}
    left = [c for c in found if (c.path, c.line) not in ALLOWED]
    stale = set(ALLOWED) - used
    for key in sorted(used):
        print(f"allowed: {key[0]}: {key[1]}  ({ALLOWED[key]})")
    assert not left, (
        f"{len(left)} comparison(s) of a sensor kind's name outside sensor/ and kinds/ "
        "(ask the kind instead: tactsense.kinds.kind_of(spec), docs/kinds.md):\n"
        + "\n".join(map(str, left))
    )
    assert not stale, f"allowlist entries that match no line any more: {sorted(stale)}"


PLANTED = """
from tactsense.sensor import PadSpec, SensorSpec
import tactsense.sensor as ts_sensor

GEOMETRY = {"finger": 1, "pad": 2}                       # 1 dict keyed by kind names
SPACING = dict(points=3)                                 # 2 dict(...) keyed by kind names

def f(spec, meta, frame_id, transduction):
    if spec.kind == "pad":                               # 3
        pass
    if "finger" != spec.kind:                            # 4 (reversed)
        pass
    if getattr(spec, "kind", None) in ("pad", "points"): # 5
        pass
    if meta.get("kind", "finger") != "finger":           # 6
        pass
    if isinstance(spec, PadSpec | ts_sensor.PointsSpec): # 7
        pass
    if type(spec) is SensorSpec:                         # 8
        pass
    spec.require_kind("finger", what="this")             # 9
    match spec.kind:
        case "points":                                   # 10
            pass
    match spec:
        case PadSpec():                                  # 11
            pass
    # not sensor kinds: a ROS frame called "finger", a transduction kind, other text
    if frame_id != "finger" or transduction.kind == "capacitive":
        pass
    if spec.transduction.kind in ("capacitive", "piezoresistive"):
        pass
    return {"kind": "pad", "name": "finger"}
"""


def test_kind_comparison_check_catches_planted_comparisons(tmp_path):
    package = tmp_path / "pkg"
    (package / "sensor").mkdir(parents=True)
    (package / "kinds").mkdir()
    (package / "planted.py").write_text(PLANTED)
    # the kinds' own homes may compare names
    (package / "sensor" / "home.py").write_text('def f(s):\n    return s.kind == "pad"\n')
    (package / "kinds" / "home.py").write_text('def f(s):\n    return s.kind == "pad"\n')
    found = scan_kind_comparisons(package)
    assert {c.path for c in found} == {"planted.py"}
    numbered = {c.line_number for c in found}
    lines = PLANTED.splitlines()
    expected = {
        i + 1 for i, line in enumerate(lines) if line.rstrip().split("# ")[-1][:2].strip().isdigit()
    }
    assert len(expected) == 11
    assert numbered == expected, "\n".join(map(str, found))


def test_kind_names_come_from_the_registry(tmp_path, monkeypatch):
    from tactsense.kinds import base

    class Hex(base.Kind):  # a kind nobody registers (the toy kind may be registered)
        name = "planted_hexagon"
        spec_class = type("PlantedHexSpec", (), {})

    names, classes = kind_vocabulary()
    assert {"finger", "pad", "points"} <= names
    assert {"SensorSpec", "PadSpec", "PointsSpec"} <= classes
    extended = names | {Hex.name}
    path = tmp_path / "m.py"
    path.write_text(
        'def f(s):\n    return s.kind == "planted_hexagon" or isinstance(s, PlantedHexSpec)\n'
    )
    assert kind_comparisons(path, "m.py", names, classes) == []
    assert len(kind_comparisons(path, "m.py", extended, classes | {"PlantedHexSpec"})) == 2


# ---- 4. no long source file ---------------------------------------------------------


def long_files(root: Path, limit: int = MAX_LINES) -> list[tuple[str, int]]:
    """Every .py file under ``root`` longer than ``limit`` lines, with its length."""
    found = []
    for path in sorted(root.rglob("*.py")):
        n = len(path.read_text().splitlines())
        if n > limit:
            found.append((path.relative_to(root).as_posix(), n))
    return found


def test_no_source_file_over_600_lines():
    found = long_files(SRC)
    assert not found, f"{len(found)} file(s) over {MAX_LINES} lines: " + ", ".join(
        f"{p} ({n})" for p, n in found
    )


def test_long_file_check_catches_a_planted_long_file(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "ok.py").write_text("x = 1\n" * MAX_LINES)
    (tmp_path / "sub" / "long.py").write_text(textwrap.dedent("x = 1\n") * (MAX_LINES + 1))
    assert long_files(tmp_path) == [("sub/long.py", MAX_LINES + 1)]

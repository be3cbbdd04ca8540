"""docs/kinds.md stays true: its example is tests/kinds/toy_kind.py, character for
character, and its table of the Kind protocol is generated from the docstrings of
src/tactsense/kinds/base.py (never typed by hand).

After a change to either, regenerate the doc's two generated blocks with::

    python tests/kinds/test_kinds_doc.py
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "kinds.md"
TOY = ROOT / "tests" / "kinds" / "toy_kind.py"
BASE = ROOT / "src" / "tactsense" / "kinds" / "base.py"

BLOCKS = {
    "toy_kind.py": "the toy kind, tests/kinds/toy_kind.py",
    "protocol": "the Kind protocol, generated from src/tactsense/kinds/base.py",
}
"""Generated block name -> what it holds (the markers say so)."""


def _first_paragraph(doc: str | None) -> str:
    if not doc:
        return ""
    text = ast.get_docstring(ast.parse(f"def f():\n    {doc!r}\n").body[0]) or ""
    paragraph = text.strip().split("\n\n")[0]
    return " ".join(line.strip() for line in paragraph.splitlines()).replace("|", "\\|")


def protocol_members(source: str) -> list[tuple[str, list[tuple[str, str, str]]]]:
    """The members of ``class Kind`` in ``source``, by group: (group, [(member, default,
    what)]). Groups are the ``# ---- group ----`` comments of the class body; an
    attribute's doc is the string under it, a method's its docstring's first paragraph."""
    tree = ast.parse(source)
    kind = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Kind")
    lines = source.splitlines()
    heads = []
    for number, line in enumerate(lines, 1):
        found = re.match(r"\s+# -{3,} (.+?) -*$", line)
        if found and kind.lineno < number <= kind.end_lineno:
            heads.append((number, re.sub(r"\s*-+$", "", found.group(1)).strip()))
    groups: dict[str, list[tuple[str, str, str]]] = {}

    def group_of(line: int) -> str:
        name = "members"
        for number, head in heads:
            if number < line:
                name = head
        return name

    body = kind.body
    for i, node in enumerate(body):
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            name = node.target.id
            annotation = ast.unparse(node.annotation)
            annotation = re.sub(r"^ClassVar\[(.*)\]$", r"\1", annotation)
            default = "required" if node.value is None else f"`{ast.unparse(node.value)}`"
            doc = ""
            following = body[i + 1] if i + 1 < len(body) else None
            if isinstance(following, ast.Expr) and isinstance(following.value, ast.Constant):
                doc = _first_paragraph(following.value.value)
            member = f"`{name}: {annotation}`"
        elif isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            args = ast.unparse(node.args).removeprefix("self, ").removeprefix("self")
            returns = f" -> {ast.unparse(node.returns)}" if node.returns else ""
            member = f"`{node.name}({args}){returns}`"
            default = "method"
            doc = _first_paragraph(ast.get_docstring(node))
        else:
            continue
        groups.setdefault(group_of(node.lineno), []).append((member, default, doc))
    return list(groups.items())


def render_protocol(source: str) -> str:
    out = []
    for group, members in protocol_members(source):
        out += [f"**{group}**", "", "| member | default | what |", "|---|---|---|"]
        out += [f"| {m} | {d} | {w} |" for m, d, w in members]
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def render_toy(source: str) -> str:
    return "```python\n" + source.rstrip() + "\n```\n"


def generated() -> dict[str, str]:
    return {
        "toy_kind.py": render_toy(TOY.read_text()),
        "protocol": render_protocol(BASE.read_text()),
    }


def _block(name: str) -> re.Pattern:
    return re.compile(
        rf"(<!-- begin {re.escape(name)}: [^>]*-->\n)(.*?)(<!-- end {re.escape(name)} -->)",
        re.DOTALL,
    )


def blocks_of(text: str) -> dict[str, str]:
    found = {}
    for name in BLOCKS:
        match = _block(name).search(text)
        assert match, f"docs/kinds.md has no generated block {name!r}"
        found[name] = match.group(2)
    return found


def regenerate() -> None:
    text = DOC.read_text()
    for name, content in generated().items():
        text = _block(name).sub(lambda m, c=content: m.group(1) + c + m.group(3), text)
    DOC.write_text(text)


def test_the_doc_shows_the_toy_kind_as_it_is():
    assert blocks_of(DOC.read_text())["toy_kind.py"] == generated()["toy_kind.py"], (
        "docs/kinds.md's example differs from tests/kinds/toy_kind.py: run "
        "python tests/kinds/test_kinds_doc.py"
    )


def test_the_doc_lists_the_protocol_as_base_py_defines_it():
    assert blocks_of(DOC.read_text())["protocol"] == generated()["protocol"], (
        "docs/kinds.md's table of the Kind protocol differs from kinds/base.py: run "
        "python tests/kinds/test_kinds_doc.py"
    )


def test_the_table_holds_every_public_member_of_kind():
    from tactsense.kinds import Kind

    listed = {
        re.match(r"`(\w+)", member).group(1)
        for _, members in protocol_members(BASE.read_text())
        for member, _, _ in members
    }
    public = {name for name in vars(Kind) if not name.startswith("_")}
    public |= {name for name in getattr(Kind, "__annotations__", {}) if not name.startswith("_")}
    assert public <= listed, sorted(public - listed)


def test_the_generator_reads_groups_attributes_and_methods():
    source = '''
class Kind:
    """The protocol."""

    # ---- what it is ----------
    name: ClassVar[str]
    """Its name.

    More words."""
    size: ClassVar[int] = 3
    """How many [-]."""

    # ---- forms -------------
    def urdf(self, spec: Any, *, link: str = "x") -> str:
        """The URDF | form."""

    def _private(self):
        pass
'''
    assert protocol_members(source) == [
        ("what it is", [("`name: str`", "required", "Its name."),
                        ("`size: int`", "`3`", "How many [-].")]),
        ("forms", [('`urdf(spec: Any, *, link: str=\'x\') -> str`', "method",
                    "The URDF \\| form.")]),
    ]  # fmt: skip


if __name__ == "__main__":
    regenerate()
    print(f"regenerated {', '.join(BLOCKS)} in {DOC.relative_to(ROOT)}", file=sys.stderr)

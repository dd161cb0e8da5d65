"""The layers hold: no import from a lower layer into a higher one, no circle between packages.

The layers and the reader of imports are in tests/layering.py (and docs/architecture.md says
what goes where). Every kind of import counts, function-local, TYPE_CHECKING and module names
written as strings included.
"""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import layering

ROOT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "mlaunch")


def test_every_package_is_in_one_layer():
    packages = {layering.package_of(m) for m in layering.modules(ROOT)}
    for package in packages:
        layering.layer_of(package)  # raises, naming the package, if it is in no layer
    seen: dict[str, str] = {}
    for name, members in layering.LAYERS:
        for member in members:
            assert member not in seen, f"{member} is in the layers {seen[member]} and {name}"
            seen[member] = name


def test_no_import_runs_from_a_lower_layer_into_a_higher_one():
    edges = layering.back_edges(ROOT)
    assert not edges, "imports from a lower layer into a higher one:\n" + "\n".join(map(str, edges))


def test_no_circle_between_packages():
    cycles = layering.package_cycles(ROOT)
    assert not cycles, f"packages that import each other, around a circle: {cycles}"


def _tree(root: Path, files: dict[str, str]) -> str:
    for name, text in files.items():
        path = root / "mlaunch" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return str(root / "mlaunch")


def test_a_planted_back_edge_is_found_in_every_spelling(tmp_path: Path):
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "plan/__init__.py": "",
            "plan/steps.py": '''\
                """Mentions mlaunch.engine.supervisor in a docstring: not an import."""
                TYPE_CHECKING = False
                if TYPE_CHECKING:
                    from mlaunch.engine.supervisor import Supervisor
                def late():
                    from mlaunch.engine import supervisor
                TABLE = {"x": "mlaunch.engine.supervisor"}
                ''',
            "engine/__init__.py": "",
            "engine/supervisor.py": "from mlaunch.plan.steps import late\n",
        },
    )
    edges = layering.back_edges(root)
    assert [(e.line, e.kind) for e in edges] == [(4, "import"), (6, "import"), (7, "string")]
    assert all(e.target == "mlaunch.engine.supervisor" for e in edges)
    assert layering.package_cycles(root) == [["engine", "plan"]]


def test_a_circle_within_one_layer_is_found(tmp_path: Path):
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "frontends/__init__.py": "from mlaunch import ros1\n",
            "ros1/__init__.py": "import mlaunch.frontends\n",
        },
    )
    assert layering.back_edges(root) == []
    assert layering.package_cycles(root) == [["frontends", "ros1"]]

"""docs/conventions.md's ranking.json format names every key `modc design` writes: the keys are
read from the code that writes them (dict literals in the functions below), so a key added there
fails here until it is documented."""
from __future__ import annotations

import ast

from conftest import ROOT

WRITERS = {
    "modc/design/write.py": ("ranking", "_entry", "task_figures", "base_figures"),
    "modc/design/reference.py": ("to_json", "reference"),
    "modc/plan/task.py": ("to_json",),
}


def _written_keys() -> set[str]:
    keys: set[str] = set()
    for path, functions in WRITERS.items():
        tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
        for fn in ast.walk(tree):
            if not (isinstance(fn, ast.FunctionDef) and fn.name in functions):
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.Dict):
                    keys |= {k.value for k in node.keys if isinstance(k, ast.Constant) and isinstance(k.value, str)}
    return keys


def test_every_ranking_key_is_documented():
    text = (ROOT / "docs" / "conventions.md").read_text(encoding="utf-8")
    section = text[text.index("### Design rankings"):text.index("### Exit codes")]
    keys = _written_keys()
    assert {"designs", "stopped", "complete", "unfinished_shapes", "alternatives"} <= keys
    missing = sorted(k for k in keys if f'"{k}"' not in section)
    assert not missing, f"ranking.json keys written but not in docs/conventions.md: {missing}"

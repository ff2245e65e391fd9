"""The README and the docs site: the README's two first commands stay as they are, every relative
link resolves (to a file, a generated reference page, and a heading when it names one), the
generated reference pages cover their one source, the YAML worked example is a valid file,
nothing points outside the repository, and the site builds strictly."""
from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"

README_TOP = """# modc — a compiler for modular robot arms

```sh
python3 -m venv .venv && .venv/bin/pip install -e '.[full]' && .venv/bin/modc examples/farm.mod -o out/
python3 -m venv .venv && .venv/bin/pip install -e '.[full,test]' && .venv/bin/python -m pytest
```
"""


def _pages_module():
    spec = importlib.util.spec_from_file_location("docs_pages", ROOT / "scripts" / "docs_pages.py")
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


PAGES = _pages_module()


def _documents() -> dict[Path, str]:
    """Every Markdown text a reader sees: README, the hand-written pages, the generated ones."""
    docs = {ROOT / "README.md": (ROOT / "README.md").read_text(encoding="utf-8")}
    docs |= {p: p.read_text(encoding="utf-8") for p in DOCS.rglob("*.md")}
    docs |= {DOCS / rel: make() for rel, make in PAGES.PAGES.items()}
    return docs


def _slug(heading: str) -> str:
    """Python-Markdown's toc slug (what mkdocs links to)."""
    text = re.sub(r"[`*_]", "", heading).strip().lower()
    text = re.sub(r"[^\w\s-]", "", text)
    return re.sub(r"[-\s]+", "-", text).strip("-")


def _anchors(text: str) -> set[str]:
    text = re.sub(r"(?ms)^```.*?^```", "", text)
    return {_slug(m.group(1)) for m in re.finditer(r"(?m)^#{1,6}\s+(.*?)\s*$", text)}


LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def _links(text: str) -> list[str]:
    text = re.sub(r"(?ms)^```.*?^```", "", text)  # code blocks hold no links
    text = re.sub(r"`[^`\n]*`", "", text)
    return [m.group(1) for m in LINK.finditer(text)]


def test_readme_starts_with_the_two_commands_unchanged():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme.startswith(README_TOP)


def test_every_relative_link_resolves():
    docs = _documents()
    bad = []
    for path, text in docs.items():
        for link in _links(text):
            if re.match(r"[a-z][a-z0-9+.-]*:", link):  # http:, https:, mailto: — checked by nobody offline
                continue
            target, _, anchor = link.partition("#")
            dest = (path.parent / target).resolve() if target else path
            if not (dest.exists() or dest in docs):
                bad.append(f"{path.relative_to(ROOT)}: {link} (no such file)")
                continue
            if anchor and dest.suffix == ".md" and anchor not in _anchors(docs.get(dest) or dest.read_text("utf-8")):
                bad.append(f"{path.relative_to(ROOT)}: {link} (no such heading)")
    assert bad == []
    assert len([lk for t in docs.values() for lk in _links(t)]) > 40  # the check saw the links


def test_no_reference_outside_the_repository():
    offenders = []
    paths = [ROOT / "README.md", *DOCS.rglob("*.md"), *(ROOT / "modc").rglob("*.py"), ROOT / "grammar" / "modc.lark",
             *(ROOT / "libraries").glob("*.yaml"), *(ROOT / "examples").glob("*.mod")]
    texts = {p: p.read_text(encoding="utf-8") for p in paths}
    for path, text in texts.items():
        for pattern in (r"\.\./shared", r"shared/reference", r"SPEC (section|§)", r"\bSPEC\.md", r"example\.org"):
            if re.search(pattern, text):
                offenders.append(f"{path.relative_to(ROOT)}: {pattern}")
    assert offenders == []


def test_the_paper_is_cited():
    for path in (ROOT / "README.md", DOCS / "conventions.md", DOCS / "index.md"):
        text = " ".join(re.sub(r"[>*]", " ", path.read_text(encoding="utf-8")).split())
        assert "Dogra" in text and "Unified Modeling of Unconventional Modular and Reconfigurable" in text
        assert "arXiv:2111.11143" in text


def test_generated_pages_cover_their_source():
    from modc.diagnostics.codes import REGISTRY
    from modc.syntax import keywords
    from modc.syntax.document import json_schema

    codes = PAGES.diagnostics_page()
    assert all(f"| `{name}` |" in codes for name in REGISTRY)
    language = PAGES.language_page()
    for block in keywords.declaration_keywords():
        assert all(f"| `{kw}` |" in language for kw in keywords.statements(block))
    assert (ROOT / "grammar" / "modc.lark").read_text(encoding="utf-8").strip() in language
    yaml_page = PAGES.yaml_page()
    schema = json_schema()
    assert all(f"### {name}" in yaml_page for name in schema["$defs"])
    for sub in schema["$defs"].values():
        assert all(f"| `{key}` |" in yaml_page for key in sub.get("properties", {}))


def test_generated_pages_are_not_committed():
    assert not any((DOCS / rel).exists() for rel in PAGES.PAGES)


def test_the_worked_yaml_example_is_a_full_valid_file():
    from modc.compiler import check_file

    example = DOCS / "snippets" / "farm.yaml"
    checked = check_file(example)
    assert checked.ok and not checked.diagnostics, checked.diagnostics
    robot = checked.design.robots[0]
    assert robot.poses and robot.obstacles and robot.targets and robot.payload is not None and robot.limits
    assert {o.shape for o in robot.obstacles} == {"box", "cylinder", "sphere"}
    assert checked.design.problems and checked.design.problems[0].rank


@pytest.mark.slow
def test_the_site_builds_strictly(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    pytest.importorskip("mkdocstrings")
    mkdocs = shutil.which("mkdocs", path=str(Path(sys.executable).parent)) or "mkdocs"
    r = subprocess.run([mkdocs, "build", "--strict", "--site-dir", str(tmp_path / "site")], cwd=ROOT,
                       capture_output=True, text=True, env={"NO_MKDOCS_2_WARNING": "1", "PATH": "/usr/bin:/bin",
                                                            "PYTHONPATH": str(ROOT), "HOME": str(tmp_path)})
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "site" / "reference" / "diagnostics" / "index.html").is_file()
    assert "load_all" in (tmp_path / "site" / "api" / "index.html").read_text(encoding="utf-8")

"""What `modc design` tells a reader: every objective as a column, in words what decided each rank
(report.html and ranking.json's "why"), a reference arm (`compare with chain …`) evaluated with the
ranking's own checks beside the designs, pictures captioned with rank and chain, a plot whose axes
start at 0. And the `compare with` statement itself: .mod, YAML, `modc fmt`, located diagnostics."""
from __future__ import annotations

import io
import json
import re
import warnings
from dataclasses import dataclass

import pytest
from conftest import SMALL_CELL

from modc.compiler import check_text
from modc.design.rank import why
from modc.objectives import REGISTRY
from modc.syntax.format import format_text

# the shared small cell, ranked by every static objective and compared with the paper's chain
SMALL = SMALL_CELL.replace("    modules H1, L3\n", "    modules H1, L3\n    rank modules, mass, margin\n"
                           "    compare with chain H1 - L3 - L3(link=180mm)\n")


def problem(text: str = SMALL):
    c = check_text(text, "small.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


@dataclass(frozen=True)
class Fake:
    """Just what the ranking's keys read of a design."""

    modules: int
    mass: float
    margin: float
    text: str

    def chain(self) -> str:
        return self.text


def test_why_names_the_ties_and_the_objective_that_decided():
    rank = ("modules", "mass", "margin")
    ds = [Fake(2, 1.411, 0.99, "A"), Fake(2, 1.411, 0.97, "B"), Fake(2, 1.5, 0.2, "C"), Fake(3, 1.2, 0.5, "D")]
    assert sorted(ds, key=lambda d: tuple(REGISTRY[o].key(d) for o in rank)) == ds
    assert why(ds, rank) == [
        "ties rank 2 on modules and mass; ahead by torque margin 99 % vs 97 %",
        "ties rank 3 on modules; ahead by mass 1.411 kg vs 1.500 kg",
        "ahead of rank 4 by modules 2 vs 3",
        "behind rank 3 by modules 3 vs 2",
    ]
    # close figures get the decimals that tell them apart, never "99 % vs 99 %"
    close = [Fake(2, 1.0, 0.9944, "A"), Fake(2, 1.0, 0.9911, "B")]
    assert why(close, rank)[0] == "ties rank 2 on modules and mass; ahead by torque margin 99.4 % vs 99.1 %"
    same = [Fake(2, 1.0, 0.9, "A"), Fake(2, 1.0, 0.9, "B")]
    assert why(same, rank)[0] == "ties rank 2 on every objective; before it by the chain's name (A)"
    assert why(ds[:1], rank) == ["the only design found"]


def test_compare_with_in_mod_yaml_and_fmt():
    from modc.syntax.yaml_form import parse_yaml

    messy = SMALL.replace("compare with chain H1 - L3 - L3(link=180mm)", "compare  with chain H1-L3 -L3( link=180mm )")
    formatted, diags = format_text(messy, "small.mod")
    assert not diags and formatted == SMALL and format_text(SMALL)[0] == SMALL
    ref = problem().reference
    assert [(u.name, u.variant, u.kind, u.link) for u in ref.units] == [("H1", "H", 1, None), ("L3", "L", 3, None),
                                                                      ("L3", "L", 3, 0.18)]
    assert ref.targets == problem().cell.targets and ref.payload == problem().cell.payload  # the cell's own
    yaml_text = """designs:
  - name: small
    payload: {mass: 100 g}
    targets: {a: "(0.30, 0.10, 0.25) m"}
    compare_with: ["H1", {unit: L3}, "L3(link=180mm)"]
"""
    tree, diags = parse_yaml(yaml_text, "small.yaml")
    assert not diags
    c = check_text(yaml_text, "small.yaml")
    assert c.ok, c.diagnostics
    y = c.design.problems[0].reference
    assert [(u.name, u.link) for u in y.units] == [(u.name, u.link) for u in ref.units]
    from modc.syntax.document import json_schema

    assert "compare_with" in json_schema()["$defs"]["DesignDoc"]["properties"]


def test_a_bad_reference_chain_is_located_with_a_hint(capsys):
    from modc.cli import main

    bad = SMALL.replace("compare with chain H1 - L3 - L3(link=180mm)", "compare with chain L3 - H1(pivot=7deg)")
    c = check_text(bad, "small.mod")
    found = {(d.code, d.span.line, d.span.col) for d in c.diagnostics}
    assert {("first-variant", 9, 24), ("illegal-succession", 9, 29), ("last-variant", 9, 29),
            ("twist-not-realisable", 9, 32)} <= found
    assert all(d.hint for d in c.diagnostics)
    # and through the command line, with the caret under the unit
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "small.mod"
        f.write_text(bad, encoding="utf-8")
        with pytest.raises(SystemExit) as e:
            main(["lint", str(f)])
    assert e.value.code == 1
    err = capsys.readouterr()
    text = err.out + err.err
    assert "small.mod:9:29: error[illegal-succession]" in text and "| " + " " * 28 + "^" * 14 in text


def _png() -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGB", (4, 3), (200, 10, 10)).save(buf, format="PNG")
    return buf.getvalue()


@pytest.fixture(scope="module")
def small():
    """The small cell's search (about 30 s on a loaded machine), shared by the tests below."""
    from modc.design import run

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run.design(problem(), top=3, seed=0)


@pytest.mark.slow
def test_report_and_ranking_say_why_and_show_the_reference(small):
    from modc.design import reference, write
    from modc.design.rank import worst_share

    o = small
    assert len(o.designs) >= 2
    files = write.files([o], {"small_1.mod": _png()})
    ranking = json.loads(files["ranking.json"])
    html = files["report.html"]
    reasons = why(o.designs, o.problem.rank)
    for entry, d, said in zip(ranking["designs"], o.designs, reasons, strict=True):
        # the SPEC keys as they were, and the new ones beside them
        assert {"rank", "file", "chain", "modules", "mass_kg", "targets", "torque_margin"} <= set(entry)
        assert entry["why"] == said and said in html.replace("&#x27;", "'")
        assert entry["worst_error_share"] == round(worst_share(d.verified.targets, o.problem.cell), 6)
        assert 0 <= entry["worst_error_share"] <= 1
    assert reasons[0].startswith(("ties rank 2", "ahead of rank 2"))
    for heading in ("<th>modules</th>", "<th>mass (kg)</th>", "<th>torque margin (%)</th>",
                    "<th>worst target error</th>", "<th>why this rank</th>"):
        assert heading in html
    # the picture's caption is its rank and chain, not a file name
    assert f"<figcaption>rank 1: {o.designs[0].chain()}</figcaption>" in html and "small_1.mod" not in html

    # the reference misses both targets: shown with what it fails, not hidden
    ref = ranking["reference"]["small"]
    assert ref["chain"] == "H1 - L3 - L3(link=180mm)" and not ref["feasible"]
    assert any(f.startswith("target 'a' missed by") for f in ref["fails"]) and ref["mass_kg"] > 0
    assert "<td>reference</td>" in html and "fails: target" in html.replace("&#x27;", "'")

    # the plot: margin from 0 to 100 %, mass from 0; each design where its figures put it
    svg = html[html.index("<svg"):html.index("</svg>")]
    from modc.design.report import PAD, H, W

    cys = [float(v) for v in re.findall(r'<circle cx="[\d.]+" cy="([\d.]+)"', svg)]
    cxs = [float(v) for v in re.findall(r'<circle cx="([\d.]+)"', svg)]
    x1 = max([d.mass for d in o.designs] + [ref["mass_kg"]]) * 1.15
    for d, cx, cy in zip(o.designs, cxs, cys, strict=True):
        assert cy == pytest.approx(H - PAD - d.margin * (H - 2 * PAD), abs=0.06)
        assert cx == pytest.approx(PAD + d.mass / x1 * (W - 2 * PAD), abs=0.06)
    assert "axis from 0" in svg

    # the same code as the ranking: rank 1's own chain as the reference gets rank 1's figures
    best = o.designs[0]
    again = problem(SMALL.replace("H1 - L3 - L3(link=180mm)", best.chain()))
    r = reference.evaluate(again, seed=0)
    assert r is not None and r.feasible and r.chain == best.chain()
    assert r.mass == pytest.approx(best.mass) and r.margin == pytest.approx(best.margin)
    assert r.worst_share() is not None and r.worst_share() <= 1


@pytest.mark.slow
def test_the_report_opens_in_headless_chromium(small, tmp_path):
    """report.html as a browser shows it (the view tests' Chromium helper): the table's rows, the
    plot drawn, every picture decoded, nothing fetched from elsewhere."""
    from test_view_browser import BROWSER, _wait, chromium

    if BROWSER is None:
        pytest.skip("no Chromium installed (Debian: apt-get install chromium)")
    from modc.design import write

    files = write.files([small], {"small_1.mod": _png()})
    page = tmp_path / "report.html"
    page.write_text(files["report.html"], encoding="utf-8")
    with chromium() as browser:
        browser.call("Network.enable")
        browser.call("Page.navigate", url=page.as_uri())
        _wait(lambda: browser.js("document.readyState") == "complete", 60, "the report to load")
        rows = browser.js("[...document.querySelectorAll('tr')].map(r => r.cells[0].textContent)")
        assert rows == ["rank", *[str(k) for k in range(1, len(small.designs) + 1)], "reference"]
        assert browser.js("document.querySelector('svg').getBoundingClientRect().height") > 200
        assert browser.js("[...document.images].every(i => i.complete && i.naturalWidth > 0)")
        assert browser.js("document.querySelector('figcaption').textContent") == f"rank 1: {small.designs[0].chain()}"
        sent = [e for e in browser.events if e.get("method") == "Network.requestWillBeSent"]
        asked = [e["params"]["request"]["url"] for e in sent]
        assert all(u.startswith(("file:", "data:")) for u in asked), asked


def test_a_new_objective_is_one_registry_entry(small, monkeypatch):
    """An objective is its module and its line in modc.objectives: once registered, `rank` accepts
    it, the ranking sorts by it, and report.html and ranking.json show it, with no other change."""
    from dataclasses import replace

    from modc.design import report, write
    from modc.design.rank import order
    from modc.objectives import Objective

    heavy = Objective("heaviest", "the heaviest arm first", "arm mass", lambda d: d.mass, unit=" kg", digits=2,
                      larger_first=True)
    monkeypatch.setitem(REGISTRY, "heaviest", heavy)
    text = SMALL.replace("rank modules, mass, margin", "rank heaviest")
    p = problem(text)  # the check accepts it; the default objectives follow it
    assert p.rank == ("heaviest", "modules", "mass", "margin")
    ranked = order(list(small.designs), p.rank)
    assert [d.mass for d in ranked] == sorted((d.mass for d in small.designs), reverse=True)
    o = replace(small, problem=p, designs=ranked)
    html = report.report_html([o], {})
    assert "<th>arm mass (kg)</th>" in html and f"<td>{ranked[0].mass:.2f} kg</td>" in html
    doc = write.ranking([o])
    assert [d["objectives"]["heaviest"] for d in doc["designs"]] == [round(d.mass, 9) for d in ranked]
    if len(ranked) > 1 and ranked[0].mass != ranked[1].mass:
        assert doc["designs"][0]["why"].startswith("ahead of rank 2 by arm mass")
    # unknown until registered: the check names every registered objective
    monkeypatch.delitem(REGISTRY, "heaviest")
    c = check_text(text, "small.mod")
    assert [d.code for d in c.diagnostics if d.is_error] == ["unknown-objective"]
    assert "modules, mass, margin, cycle_time, energy, coverage" in (c.diagnostics[0].hint or "")

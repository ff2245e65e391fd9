"""DIR/report.html: the ranking with every objective as a column and, per rank, in words what
decided it; the block's reference arm (`compare with chain …`) beside the designs; a plot of mass
against torque margin (inline SVG, both axes from 0); pictures of the top designs in the cell
(PNG, inline) captioned with their rank and chain. One self-contained file: no scripts, no links
out. Every user-given text is HTML-escaped."""
from __future__ import annotations

import base64
from html import escape

from ..formatting import counted
from ..objectives import REGISTRY
from .outcome import Outcome
from .rank import TASK, pareto, shown, static, versus, why, worst_share
from .write import file_name

W, H, PAD = 520, 320, 52
REF = "#2471a3"  # the reference arm's colour, in the plot and the table


def _columns(o: Outcome) -> list[str]:
    """The objectives shown: the ranked ones in order, and the task figures of a planned cell."""
    timed = any(d.plans for d in o.designs)
    cols = [k for k in o.problem.rank if timed or k not in TASK]
    return cols + [k for k, o in REGISTRY.items() if o.planned_column and timed and k not in cols]


def _cell(objective: str, d) -> str:
    _, value, unit = shown(objective, d)
    return f"{value:.{REGISTRY[objective].digits}f}{unit}"


def _share(share: float | None, worst_m: float | None) -> str:
    if share is None:
        return "—"
    mm = "" if worst_m is None else f" ({worst_m * 1000:.2f} mm)" if worst_m >= 5e-6 else " (< 0.01 mm)"
    return f"{share * 100:.0f} % of tolerance{mm}" if share >= 0.005 else f"< 1 % of tolerance{mm}"


def _svg(o: Outcome) -> str:
    """Mass against torque margin, both axes from 0 (margin up to 100 %): close figures look close."""
    if not o.designs:
        return ""
    ref = o.reference if o.reference is not None and o.reference.mass is not None else None
    front = pareto([(d.mass, -d.margin) for d in o.designs])
    masses = [d.mass for d in o.designs] + ([ref.mass] if ref else [])
    margins = [d.margin * 100 for d in o.designs] + ([ref.margin * 100] if ref and ref.margin is not None else [])
    x1 = max(masses) * 1.15
    y0, y1 = min(0.0, min(margins)), max(100.0, max(margins))

    def px(x: float, y: float) -> tuple[float, float]:
        return PAD + x / x1 * (W - 2 * PAD), H - PAD - (y - y0) / (y1 - y0) * (H - 2 * PAD)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" role="img">',
             f'<rect x="{PAD}" y="{PAD}" width="{W - 2 * PAD}" height="{H - 2 * PAD}" fill="#f7f8fa" stroke="#bbb"/>',
             f'<text x="{W / 2}" y="{H - 12}" text-anchor="middle" font-size="12">'
             'arm mass (kg, axis from 0), lighter is better</text>',
             f'<text x="14" y="{H / 2}" transform="rotate(-90 14 {H / 2})" text-anchor="middle" font-size="12">'
             f'torque margin (%, axis from {y0:.0f}), higher is better</text>']
    for k in range(5):  # ticks at 0, ¼, ½, ¾ and the end of each axis
        x, y = x1 * k / 4, y0 + (y1 - y0) * k / 4
        tx, _ = px(x, y0)
        _, ty = px(0, y)
        parts.append(f'<text x="{tx:.1f}" y="{H - PAD + 14}" font-size="10" text-anchor="middle">{x:.2f}</text>')
        parts.append(f'<text x="{PAD - 4}" y="{ty + 3:.1f}" font-size="10" text-anchor="end">{y:.0f}</text>')
    taken: list[tuple[float, float]] = []

    def label(x: float, y: float, text: str, colour: str = "#222") -> None:
        # labels of close points stacked upwards rather than drawn over each other
        ly = y - 8
        while any(abs(ly - ty) < 11 and abs(x - tx) < 40 for tx, ty in taken):
            ly -= 11
        taken.append((x, ly))
        parts.append(f'<text x="{x + 8:.1f}" y="{ly:.1f}" font-size="11" fill="{colour}">{escape(text)}</text>')

    for rank, (d, on_front) in enumerate(zip(o.designs, front, strict=True), start=1):
        x, y = px(d.mass, d.margin * 100)
        colour = "#c0392b" if on_front else "#7f8c8d"
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="5" fill="{colour}">'
                     f'<title>rank {rank}: {escape(d.chain())}</title></circle>')
        label(x, y, str(rank))
    if ref is not None and ref.margin is not None:
        x, y = px(ref.mass, ref.margin * 100)
        parts.append(f'<rect x="{x - 5:.1f}" y="{y - 5:.1f}" width="10" height="10" fill="{REF}" '
                     f'transform="rotate(45 {x:.1f} {y:.1f})"><title>reference: {escape(ref.chain)}</title></rect>')
        label(x, y, "reference", REF)
    parts.append("</svg>")
    return "".join(parts)


def _table(o: Outcome) -> str:
    cols = _columns(o)
    head = "".join(f"<th>{escape(_heading(k, o))}</th>" for k in cols)
    rows = [f"<tr><th>rank</th><th>chain</th>{head}<th>worst target error</th><th>why this rank</th>"
            "<th>alternatives (other H/L variants)</th></tr>"]
    cell = o.problem.cell
    for rank, (d, said) in enumerate(zip(o.designs, why(o.designs, o.problem.rank), strict=True), start=1):
        worst = max((t["position_error_m"] for t in d.verified.targets.values()), default=0.0)
        rows.append(f"<tr><td>{rank}</td><td><code>{escape(d.chain())}</code></td>"
                    + "".join(f"<td>{_cell(k, d)}</td>" for k in cols)
                    + f"<td>{escape(_share(worst_share(d.verified.targets, cell), worst))}</td><td>{escape(said)}</td>"
                    f"<td>{'<br>'.join(f'<code>{escape(x.chain())}</code> ({x.mass:.3f} kg)' for x in d.alternatives)}"
                    "</td></tr>")
    if o.reference is not None:
        rows.append(_reference_row(o, cols))
    return "<table>" + "".join(rows) + "</table>"


def _heading(objective: str, o: Outcome) -> str:
    words, _, unit = shown(objective, o.designs[0])
    return f"{words} ({unit.strip()})" if unit.strip() else words


def _reference_row(o: Outcome, cols: list[str]) -> str:
    r = o.reference
    cells = []
    for k in cols:
        if (k in TASK and r.plans) or (k not in TASK and REGISTRY[k].value(r) is not None):
            cells.append(_cell(k, r))
        else:  # not known: task figures of a reference that could not be planned, a chain that does not compile
            cells.append("—")
    errors = [t["position_error_m"] for t in r.targets.values() if t["position_error_m"] is not None]
    verdict = "passes every check" if r.feasible else "fails: " + "; ".join(r.fails)
    return (f'<tr style="color:{REF}"><td>reference</td><td><code>{escape(r.chain)}</code></td>'
            + "".join(f"<td>{c}</td>" for c in cells)
            + f"<td>{escape(_share(r.worst_share(), max(errors, default=None)))}</td>"
            f"<td>{escape(verdict)}</td><td></td></tr>")


def _reference_text(o: Outcome) -> str:
    """The reference arm against rank 1, in words."""
    r = o.reference
    if r is None:
        return ""
    head = f"<h3>Reference arm</h3><p><code>{escape(r.chain)}</code> (<code>compare with</code>), "
    if not r.feasible:
        return head + escape(f"evaluated on this cell with the ranking's checks, fails: {'; '.join(r.fails)}.") + "</p>"
    best = o.designs[0]
    ties, decided, (a, b) = versus(o.problem.rank if r.plans else static(o.problem.rank), best, r)
    if decided is None:
        said = "it ties rank 1 on every objective"
    else:
        key = REGISTRY[decided].key
        ahead = "rank 1 is ahead" if key(best) < key(r) else "the reference is ahead"
        said = (f"it ties rank 1 on {', '.join(ties)}; " if ties else "") + \
            f"{ahead} by {shown(decided, best)[0]}: {a} (rank 1) vs {b} (reference)"
    return head + escape(f"passes every check the designs passed; {said}.") + "</p>"


def _coverage(o: Outcome) -> str:
    if not o.searched:
        return f"Not searched: the search stopped ({o.stopped}) before this design block."
    if o.not_planned:
        return (f"Not complete: the search stopped ({o.stopped}) before {len(o.not_planned)} of the designs found "
                "were planned and timed; a better design may exist.")
    if o.stopped:
        return (f"Not complete: the search stopped ({o.stopped}) with {counted(len(o.unfinished), 'shape')} "
                "not finished; a better design may exist.")
    if o.coarse:
        return (f"Not complete: {counted(len(o.coarse), 'shape')} too large to enumerate were searched on a coarse "
                "twist grid.")
    return "Complete within the bounds: every twist setting of every shape was screened or excluded by a sound bound."


def _pictures(o: Outcome, renders: dict[str, bytes]) -> list[str]:
    out = []
    for rank, d in enumerate(o.designs, start=1):
        png = renders.get(file_name(o.problem.name, rank))
        if png is None:
            continue
        data = base64.b64encode(png).decode("ascii")
        caption = f"rank {rank}: {d.chain()}"
        out.append(f'<figure><img alt="{escape(caption)}" src="data:image/png;base64,{data}">'
                   f"<figcaption>{escape(caption)}</figcaption></figure>")
    return ["<h3>Top designs in the cell</h3><div class=pics>", *out, "</div>"] if out else []


def report_html(outcomes: list[Outcome], renders: dict[str, bytes]) -> str:
    body = []
    for o in outcomes:
        name = escape(o.problem.name)
        body.append(f"<h2>design {name}</h2>")
        body.append(f"<p>{counted(len(o.designs), 'design')}; {o.evaluated:,} twist settings screened over "
                    f"{counted(o.shapes, 'shape')} in {o.seconds:.1f} s ({o.excluded:,} excluded by sound bounds). "
                    f"Ranked by {escape(', '.join(o.problem.rank))}, in that order; a tie on every objective is "
                    f"broken by the chain's name. {escape(_coverage(o))}</p>")
        if not o.designs:
            continue
        body.append(_table(o))
        body.append(_reference_text(o))
        body.append("<h3>Mass and torque margin</h3><p>Both axes start at 0 (margin up to 100 %). Red: no other "
                    "design is both lighter and has more torque margin"
                    + ("; blue: the reference arm" if o.reference is not None else "") + ".</p>")
        body.append(_svg(o))
        body += _pictures(o, renders)
    style = ("body{font-family:sans-serif;max-width:72em;margin:2em auto;color:#222}"
             "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.3em .6em;text-align:left}"
             ".pics{display:flex;flex-wrap:wrap;gap:1em}figure{margin:0}img{max-width:400px}")
    return ("<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>modc design</title>"
            f"<style>{style}</style></head><body><h1>modc design</h1>{''.join(body)}</body></html>\n")

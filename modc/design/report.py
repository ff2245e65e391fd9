"""DIR/report.html: the ranking, a Pareto plot of mass against torque margin (inline SVG) and
pictures of the top designs in the cell (PNG, inline). One self-contained file: no scripts, no
links out. Every user-given text is HTML-escaped."""
from __future__ import annotations

import base64
from html import escape

from .rank import pareto
from .run import Outcome

W, H, PAD = 480, 300, 48


def _svg(o: Outcome) -> str:
    pts = [(d.mass, -d.margin) for d in o.designs]
    if not pts:
        return ""
    front = pareto(pts)
    xs, ys = [d.mass for d in o.designs], [d.margin * 100 for d in o.designs]
    x0, x1 = min(xs), max(xs)
    y0, y1 = min(ys), max(ys)
    x0, x1 = (x0 - 0.05, x1 + 0.05) if x1 - x0 < 1e-6 else (x0 - 0.05 * (x1 - x0), x1 + 0.05 * (x1 - x0))
    y0, y1 = (y0 - 5, y1 + 5) if y1 - y0 < 1e-6 else (y0 - 0.05 * (y1 - y0), y1 + 0.05 * (y1 - y0))

    def px(x: float, y: float) -> tuple[float, float]:
        return PAD + (x - x0) / (x1 - x0) * (W - 2 * PAD), H - PAD - (y - y0) / (y1 - y0) * (H - 2 * PAD)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" role="img">',
             f'<rect x="{PAD}" y="{PAD}" width="{W - 2 * PAD}" height="{H - 2 * PAD}" fill="#f7f8fa" stroke="#bbb"/>',
             f'<text x="{W / 2}" y="{H - 10}" text-anchor="middle" font-size="12">'
             'arm mass (kg), lighter is better</text>',
             f'<text x="14" y="{H / 2}" transform="rotate(-90 14 {H / 2})" text-anchor="middle" font-size="12">'
             'torque margin (%), higher is better</text>',
             f'<text x="{PAD}" y="{H - PAD + 14}" font-size="10">{x0:.3f}</text>',
             f'<text x="{W - PAD}" y="{H - PAD + 14}" font-size="10" text-anchor="end">{x1:.3f}</text>',
             f'<text x="{PAD - 4}" y="{H - PAD}" font-size="10" text-anchor="end">{y0:.0f}</text>',
             f'<text x="{PAD - 4}" y="{PAD + 8}" font-size="10" text-anchor="end">{y1:.0f}</text>']
    for rank, (d, on_front) in enumerate(zip(o.designs, front, strict=True), start=1):
        x, y = px(d.mass, d.margin * 100)
        colour = "#c0392b" if on_front else "#7f8c8d"
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="6" fill="{colour}">'
                     f'<title>{escape(d.chain())}</title></circle>')
        parts.append(f'<text x="{x + 8:.1f}" y="{y - 8:.1f}" font-size="11">{rank}</text>')
    parts.append("</svg>")
    return "".join(parts)


def _table(o: Outcome) -> str:
    timed = any(d.plans for d in o.designs)  # the cell's tasks planned and timed (modc.design.tasks)
    rows = ["<tr><th>rank</th><th>chain</th><th>modules</th><th>mass (kg)</th><th>torque margin</th>"
            "<th>worst target error</th>" + ("<th>cycle time (s)</th><th>energy (J)</th>" if timed else "")
            + "<th>alternatives (other H/L variants)</th></tr>"]
    for rank, d in enumerate(o.designs, start=1):
        worst = max(t["position_error_m"] for t in d.verified.targets.values())
        task = f"<td>{d.cycle_time:.3f}</td><td>{d.energy:.2f}</td>" if timed else ""
        rows.append(f"<tr><td>{rank}</td><td><code>{escape(d.chain())}</code></td><td>{d.modules}</td>"
                    f"<td>{d.mass:.3f}</td><td>{d.margin * 100:.0f} %</td><td>{worst * 1000:.3g} mm</td>{task}"
                    f"<td>{'<br>'.join(f'<code>{escape(x.chain())}</code> ({x.mass:.3f} kg)' for x in d.alternatives)}"
                    "</td></tr>")
    return "<table>" + "".join(rows) + "</table>"


def _coverage(o: Outcome) -> str:
    if o.stopped:
        return (f"Not complete: the search stopped ({o.stopped}) with {len(o.unfinished)} shapes not finished; "
                "a better design may exist.")
    if o.coarse:
        return f"Not complete: {len(o.coarse)} shapes too large to enumerate were searched on a coarse twist grid."
    return "Complete within the bounds: every twist setting of every shape was screened or excluded by a sound bound."


def report_html(outcomes: list[Outcome], renders: dict[str, bytes]) -> str:
    body = []
    for o in outcomes:
        name = escape(o.problem.name)
        body.append(f"<h2>design {name}</h2>")
        body.append(f"<p>{len(o.designs)} designs; {o.evaluated:,} twist settings screened over {o.shapes} shapes "
                    f"in {o.seconds:.1f} s ({o.excluded:,} excluded by sound bounds). "
                    f"Ranked by {escape(', '.join(o.problem.rank))}. {escape(_coverage(o))}</p>")
        body.append(_table(o))
        body.append("<h3>Pareto plot</h3><p>Red: no other design is both lighter and has more torque margin.</p>")
        body.append(_svg(o))
        pictures = [(f, png) for f, png in sorted(renders.items()) if f.startswith(f"{o.problem.name}_")]
        if pictures:
            body.append("<h3>Top designs in the cell</h3><div class=pics>")
            for f, png in pictures:
                data = base64.b64encode(png).decode("ascii")
                body.append(f'<figure><img alt="{escape(f)}" src="data:image/png;base64,{data}">'
                            f"<figcaption>{escape(f)}</figcaption></figure>")
            body.append("</div>")
    style = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}"
             "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.3em .6em;text-align:left}"
             ".pics{display:flex;flex-wrap:wrap;gap:1em}figure{margin:0}img{max-width:400px}")
    return ("<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>modc design</title>"
            f"<style>{style}</style></head><body><h1>modc design</h1>{''.join(body)}</body></html>\n")

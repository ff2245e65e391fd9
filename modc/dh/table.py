"""Read a DH table from CSV (header a,alpha,d,theta; metres and radians), with cell spans."""
from __future__ import annotations

from ..diagnostics import Diagnostic, Span, codes
from ..model import DHRow
from ..model.lower import DH_PARAMS, magnitude_error

COLUMNS = ("a", "alpha", "d", "theta")
REQUIRED = ("a", "alpha", "d")


def _cells(line: str) -> list[tuple[str, int]]:
    """Comma-separated cells with their 1-based start columns (numbers need no CSV quoting)."""
    out, col = [], 1
    for cell in line.split(","):
        out.append((cell, col))
        col += len(cell) + 1
    return out


def read_csv(text: str, path: str) -> tuple[list[DHRow], list[Diagnostic]]:
    diags: list[Diagnostic] = []
    lines = [
        (i, ln) for i, ln in enumerate(text.splitlines(), start=1) if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        return [], [codes.DH_EMPTY.at(Span.point(path))]
    head_no, head = lines[0]
    names = [c.strip().lower() for c, _ in _cells(head)]
    if sorted(set(names)) != sorted(names) or not set(REQUIRED) <= set(names) or not set(names) <= set(COLUMNS):
        span = Span(path, head_no, 1, head_no, len(head) + 1)
        return [], [codes.DH_CSV_HEADER.at(span, found=repr(head.strip()))]
    rows: list[DHRow] = []
    for row_no, (line_no, line) in enumerate(lines[1:], start=1):
        cells = _cells(line)
        row_span = Span(path, line_no, 1, line_no, len(line) + 1)
        if len(cells) != len(names):
            diags.append(codes.DH_CSV_VALUE.at(row_span, row=row_no, column="*",
                                               problem=f"{len(cells)} cells for {len(names)} columns"))
            continue
        values, ok = {}, True
        for name, (cell, col) in zip(names, cells, strict=True):  # counts compared just above
            span = Span(path, line_no, col, line_no, col + max(1, len(cell)))
            try:
                v = float(cell)
            except ValueError:
                diags.append(
                    codes.DH_CSV_VALUE.at(span, row=row_no, column=name, problem=f"{cell.strip()!r} is not a number")
                )
                ok = False
                continue
            bad = magnitude_error([v], f"DH {name} in row {row_no}", span, DH_PARAMS[name])
            if bad is not None:  # the check a dh block in a .mod file gets
                diags.append(bad)
                ok = False
                continue
            values[name] = v
        if ok:
            rows.append(DHRow(span=row_span, **values))
    if not rows and not diags:
        diags.append(codes.DH_EMPTY.at(Span(path, head_no, 1, head_no, len(head) + 1)))
    return rows, diags

"""Analyses of a design: `check` (torque), `dh2mod` and `dh` (Denavit-Hartenberg)."""
from __future__ import annotations

import sys
from typing import NoReturn

import click

from .app import (
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    _err,
    _print_diagnostics,
    app,
    argument,
    library_option,
    usage_errors,
)


def _mass(text: str) -> float | None:
    import math
    import re

    m = re.fullmatch(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(kg|g)?\s*", text)
    if not m:
        return None
    value = float(m.group(1)) * (0.001 if m.group(2) == "g" else 1.0)
    return value if math.isfinite(value) and value >= 0 else None


@app.command("check")
@argument("file", help=".mod file (or its YAML form)")
@click.option("--payload", help="payload at tool0 replacing the file's, e.g. 0.5kg or 500g")
@click.option("--json", "json_out", is_flag=True, help="print the torque table as JSON")
@click.option(
    "--traj", help="also the torques along this trajectory (inverse dynamics), e.g. from `modc plan --json`"
)
@library_option
def check_cmd(file: str, payload: str | None, json_out: bool, traj: str | None, library: str | None) -> None:
    """Torque feasibility: the worst static gravity torque of every joint over its range, against
    the actuator's nominal and peak torque, and with --traj the peak torques along a motion.
    Exit 1 if a joint can exceed its peak torque."""
    from ..compiler import COMPILE_ANALYSES, InputError, check_file
    from ..diagnostics import Span, codes

    mass = None
    if payload is not None:
        mass = _mass(payload)
        if mass is None:
            _print_diagnostics([codes.BAD_PAYLOAD.at(Span.point("<command line>"), value=payload)], {})
            raise SystemExit(EXIT_USAGE)
    try:
        checked = check_file(file, library, analyses=COMPILE_ANALYSES, payload_override=mass)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    robots = [r for r in checked.design.robots if r.torque is not None]
    along = _along(traj, checked.design, robots, mass) if traj is not None and checked.ok else {}
    if json_out:
        _torque_json(robots, mass, traj, along)
    else:
        _torque_table(robots, mass, traj, along)
    _print_diagnostics(checked.diagnostics, checked.sources)
    over = [j for peaks in along.values() for j in peaks if j.level == "over-peak"]
    for j in over:
        _err(f"modc check: {j.name} ({j.variant}) needs {j.tau:.3g} N·m at t = {j.t:.3f} s of {traj}, "
             f"above its peak {j.tau_max:g} N·m")
    raise SystemExit(EXIT_OK if checked.ok and not over else EXIT_ERRORS)


def _torque_json(robots, mass: float | None, traj: str | None, along: dict) -> None:
    import json

    doc = {
        "robots": [
            {
                "name": r.name,
                "payload": mass if mass is not None else (r.payload.mass if r.payload else 0.0),
                "joints": [j.to_json() for j in r.torque or ()],
                **(
                    {"trajectory": {"file": traj, "joints": [j.to_json() for j in along[r.name]]}}
                    if r.name in along
                    else {}
                ),
            }
            for r in robots
        ]
    }
    print(json.dumps(doc, indent=2))


def _torque_table(robots, mass: float | None, traj: str | None, along: dict) -> None:
    import math

    for r in robots:
        shown = mass if mass is not None else (r.payload.mass if r.payload else 0.0)
        print(f"robot {r.name} ({r.sequence}), payload {shown:g} kg")
        head = f"  {'joint':<9}{'unit':<6}{'worst |tau| N·m':>16}{'nominal':>9}{'peak':>7}{'margin':>8}"
        print(f"{head}  worst pose (deg)")
        for j in r.torque or ():
            pose = ", ".join(f"{math.degrees(x):.0f}" for x in j.q)
            row = f"  {j.name:<9}{j.variant:<6}{j.tau:>16.3f}{j.tau_nom:>9g}{j.tau_max:>7g}{j.margin:>8.0%}"
            print(f"{row}  ({pose})  {j.level}")
        if r.name in along:
            print(f"  along {traj} (inverse dynamics):")
            head = f"  {'joint':<9}{'unit':<6}{'peak |tau| N·m':>16}{'nominal':>9}{'peak':>7}{'margin':>8}"
            print(f"{head}  at t (s)")
            for j in along[r.name]:
                row = f"  {j.name:<9}{j.variant:<6}{j.tau:>16.3f}{j.tau_nom:>9g}{j.tau_max:>7g}{j.margin:>8.0%}"
                print(f"{row}  {j.t:.3f}  {j.level}")


def _along(traj_path: str, design, robots, mass) -> dict:
    """Peak torques along the trajectory for the robot it belongs to (exit 1 on a bad file)."""
    from ..diagnostics import Span, codes
    from ..dynamics.along import peaks
    from ..dynamics.worst import Dynamics
    from ..model.select import choose_robot
    from ..trajectory import diagnostics, load, validate_for

    def invalid(lines) -> NoReturn:
        _print_diagnostics(diagnostics(traj_path, lines), {})
        raise SystemExit(EXIT_ERRORS)

    try:
        traj, errors = load(traj_path)
    except OSError as e:  # missing, a directory, a FIFO, a device: a usage error, as for FILE
        _print_diagnostics([codes.FILE_NOT_FOUND.at(Span.point(traj_path), path=traj_path,
                                                    detail=e.strerror or str(e))], {})
        raise SystemExit(EXIT_USAGE) from None
    if traj is None:
        invalid(errors)
    with usage_errors("check"):
        robot = choose_robot(
            design, traj.robot, robots, say='"robot" in the trajectory file', where=Span.point(traj_path)
        )
    errors = validate_for(traj, robot)
    if errors:
        invalid(errors)
    payload = None
    if mass is not None:
        payload = (mass, robot.payload.com if robot.payload is not None else (0.0, 0.0, 0.0))
    return {robot.name: peaks(Dynamics(robot, payload), traj)}


@app.command("dh2mod")
@argument("table", help="CSV with header a,alpha,d,theta (metres, radians), one row per joint")
@click.option("--json", "json_out", is_flag=True, help="print requested vs realised DH as JSON instead of .mod text")
@click.option("--fit-links", is_flag=True, help="print link modules at the lengths that realise each a exactly")
@click.option("--name", help="robot name (default: from the file name)")
@library_option
def dh2mod_cmd(table: str, json_out: bool, fit_links: bool, name: str | None, library: str | None) -> None:
    """Convert a standard DH table into a module chain (paper section 4.2); .mod text on stdout."""
    from ..compiler import InputError, SourceError, read_source
    from ..dh2mod import convert_table

    try:
        text = read_source(table)
    except SourceError as e:  # an error in the table (not UTF-8, too large): exit 1
        _print_diagnostics([e.diagnostic], {table: e.text} if e.text is not None else {})
        raise SystemExit(EXIT_ERRORS) from None
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    out, diags, ok = convert_table(text, table, name=name, fit_links=fit_links, library=library, as_json=json_out)
    _print_diagnostics(diags, {table: text})
    if not ok:
        raise SystemExit(EXIT_ERRORS)
    sys.stdout.write(out)


@app.command("dh")
@argument("file", help=".mod file (or its YAML form)")
@click.option("--json", "json_out", is_flag=True, help="JSON instead of a table")
@library_option
def dh_cmd(file: str, json_out: bool, library: str | None) -> None:
    """Show the realised standard DH table of every robot (and the requested one, for dh tables)."""
    import json

    from ..compiler import InputError, check_file
    from ..dh.report import compare, text_table

    try:
        checked = check_file(file, library)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    if not checked.ok:
        _print_diagnostics(checked.diagnostics, checked.sources)
        raise SystemExit(EXIT_ERRORS)
    robots = checked.design.resolved_robots()
    if json_out:
        doc = {"robots": [{"name": r.name, "sequence": r.sequence, "joints": compare(r)} for r in robots]}
        print(json.dumps(doc, indent=2))
    else:
        print("\n\n".join(text_table(r) for r in robots))

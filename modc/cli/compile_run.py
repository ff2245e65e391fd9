"""`modc FILE -o OUT`'s work, and its command line read without click when that is plain: the
first compile of a new arm paid ~20 ms for click's import and its command's options
(benchmarks/bench_startup.py), as `modc lint` did (modc.cli.lint_run). Anything else (--help, a
number option, a mistake, an unusual spelling) goes to the click command in modc.cli.compile,
which reads it as before and then runs run() here.
"""
from __future__ import annotations

from .common import EXIT_ERRORS, EXIT_USAGE, Verbosity, _err, _print_diagnostics, read_plain, usage_errors

TORQUE = ("error", "warning", "off")
# option -> (its name in run(), the values it takes or None for any, or the flag's value)
_OPTIONS: dict[str, tuple[str, tuple[str, ...] | None | bool]] = {
    "-o": ("out", None), "--out": ("out", None), "--library": ("library", None), "--only": ("only", None),
    "--force": ("force", True), "--no-force": ("force", False), "--smoke": ("smoke", True),
    "--torque": ("torque", TORQUE), "--ros-distro": ("ros_distro", None), "--ik-solver": ("ik_solver", None),
    "--ros-package": ("ros_package", None), "--command-interface": ("command_interface", None),
    "--package-license": ("package_license", None), "--maintainer": ("maintainer", None),
    "-q": ("quiet", True), "--quiet": ("quiet", True), "-v": ("verbose", True), "--verbose": ("verbose", True),
}


def plain_args(args: list[str]) -> dict | None:
    """run()'s arguments when args (after `compile`) are a plain compile command line: one file,
    -o OUT, and options spelled as in `modc compile --help`, each at most once, none of the
    numbers (click checks their ranges); else None."""
    def one_file(options: dict, word: str) -> bool:
        if "file" in options:
            return False
        options["file"] = word
        return True

    options = read_plain(args, _OPTIONS, one_file)
    return options if options is not None and "file" in options and "out" in options else None


def run(file: str, out: str, library: str | None = None, only: str | None = None, force: bool = False,
        collision_samples: int = 10_000, seed: int = 0, smoke: bool = False, torque: str | None = None,
        ros: int | None = None, ros_distro: str | None = None, ik_solver: str | None = None,
        ros_package: str | None = None, command_interface: str | None = None, package_license: str | None = None,
        maintainer: str | None = None, quiet: bool = False, verbose: bool = False) -> None:
    """Check FILE and write every backend's output into OUT (the defaults are the command's)."""
    from ..compiler import COMPILE_ANALYSES, InputError, build_cached, check_compile
    from ..outputs import check_output_dir, write_tree

    Verbosity.quiet, Verbosity.verbose = quiet, verbose
    try:  # the inputs are protected before the analyses write to modc's caches (modc.outputs)
        checked, inputs = check_compile(file, library, analyses=COMPILE_ANALYSES, torque_severity=torque or "error")
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        from ..diagnostics.render import summary

        _err(f"modc: {summary(checked.diagnostics)}; nothing written to {out}")
        raise SystemExit(EXIT_ERRORS)
    with usage_errors("compile", writing=out):  # before any work: a refused OUT costs nothing
        check_output_dir(out, inputs, force)
    selected = None
    if only:
        from ..backends import load_all

        selected = [s.strip() for s in only.split(",") if s.strip()]
        unknown = [s for s in selected if s not in load_all()]
        if unknown:
            _err(f"modc: unknown backend(s) {', '.join(unknown)}; available: {', '.join(load_all())}")
            raise SystemExit(EXIT_USAGE)
    if smoke:  # before anything is written: a failed smoke test leaves OUT as it was
        from ..sim.smoke import run_sim

        ok, lines, _ = run_sim(file, library=library)
        for line in lines:
            _err(line)
        if not ok:
            _err(f"modc: smoke test failed; nothing written to {out}")
            raise SystemExit(EXIT_ERRORS)
    ros_options = _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface,
                               package_license, maintainer)
    try:
        files = build_cached(checked, selected, collision_samples=collision_samples, seed=seed, **ros_options)
    except InputError as e:  # a backend refuses a value it cannot write (mjcf: not-finite)
        _print_diagnostics([e.diagnostic], checked.sources)
        _err(f"modc: nothing written to {out}")
        raise SystemExit(EXIT_ERRORS) from None
    with usage_errors("compile", writing=out):
        write_tree(files, out, force=force, inputs=inputs)
    if verbose:
        for rel in files:
            _err(f"  wrote {out.rstrip('/')}/{rel}")
    if not quiet:
        robots = ", ".join(f"{r.file_stem} ({r.sequence})" for r in checked.design.robots)
        _err(f"modc: {len(files)} files written to {out}: {robots or 'no robot'}")
        if checked.design.problems and not checked.design.robots:  # a design problem compiles to nothing
            _err(f"modc: {file} holds design problems, no robot: `modc design {file} -o DIR` finds arms for them")


def _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface,
                 package_license=None, maintainer=None) -> dict:
    """Build fields of the ROS backend. The environment ($ROS_DISTRO, $ROS_VERSION) is read here
    and only here, below the command-line options (docs/ros.md)."""
    import os
    from types import SimpleNamespace

    from ..backends.ros_target import RosOptionError, distro_for, resolve

    try:
        options = {"ros_distro": distro_for(ros, ros_distro, dict(os.environ)), "ik_solver": ik_solver,
                   "ros_package": ros_package, "command_interface": command_interface,
                   "package_license": package_license, "maintainer": maintainer}
        if selected is None or "ros" in selected:
            resolve(SimpleNamespace(robots=checked.design.resolved_robots(), **options))  # what a Build holds
    except RosOptionError as e:
        _err(f"modc: {e}")
        raise SystemExit(EXIT_USAGE) from None
    return options

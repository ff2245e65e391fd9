"""What the benchmark scripts share: measuring this checkout, on one core when asked."""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def child_env(pycache: Path | None = None) -> dict[str, str]:
    """Environment for subprocesses that must import this checkout's modc (not another install).
    pycache: a private bytecode cache, so start-up is measured as users get it even where
    PYTHONDONTWRITEBYTECODE is set."""
    env = dict(os.environ)
    if pycache is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(pycache)
    probe = subprocess.run([sys.executable, "-c", "import modc, sys; sys.stdout.write(modc.__file__)"],
                           capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    want = ROOT / "modc" / "__init__.py"
    got = Path(probe.stdout.strip()) if probe.returncode == 0 else None
    if got is None or got.resolve() != want.resolve():
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    return env


def pin_one_core() -> int | None:
    """Run on one core (the targets say "one core"); the core's number, or None if not possible."""
    try:
        cpus = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cpus[-1]})
        return cpus[-1]
    except (AttributeError, OSError):
        return None


def report(doc: dict, table: str | None, json_arg: str | None) -> None:
    """Print the table (stderr when the JSON goes to stdout) and write the JSON: `--json -` is
    stdout, `--json FILE` a file, no --json no JSON."""
    import json

    text = json.dumps(doc, indent=2)
    if json_arg == "-":
        if table is not None:
            print(table, file=sys.stderr)
        print(text)
        return
    if table is not None:
        print(table)
    if json_arg:
        Path(json_arg).write_text(text + "\n", encoding="utf-8")

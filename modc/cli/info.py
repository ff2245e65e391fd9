"""`lsp`, `schema`, `codes`, `backends`."""
from __future__ import annotations

from .app import app


@app.command("lsp")
def lsp_cmd() -> None:
    """Language server on stdio for editors: diagnostics, hover, completion, symbols, go-to-definition, formatting."""
    from ..lsp import serve

    serve()


@app.command("schema")
def schema_cmd():
    """Print the JSON Schema of the YAML form of .mod files."""
    import json

    from ..syntax.document import json_schema

    print(json.dumps(json_schema(), indent=2))


@app.command("codes")
def codes_cmd():
    """List every diagnostic code with its severity and meaning."""
    from ..diagnostics import REGISTRY

    for code in REGISTRY.values():
        allow = " (allowable)" if code.allowable else ""
        print(f"{code.name:28} {code.severity.value:8} {code.summary}{allow}")


@app.command("backends")
def backends_cmd():
    """List the output backends."""
    from ..backends import load_all

    for b in load_all().values():
        print(f"{b.name:10} {b.summary}")

"""The modc language server (`modc lsp`, or `python -m modc.lsp`): diagnostics, hover,
completion, document symbols, go-to-definition and formatting for .mod and YAML files, over
stdio. pygls is imported only when the server starts."""


def serve() -> None:
    """Start the language server on stdio; returns when the client exits."""
    from .server import serve as _serve

    _serve()


__all__ = ["serve"]

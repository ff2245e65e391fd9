"""The exceptions that carry one diagnostic out of a reader or a writer (modc.compiler re-exports
them): below every layer that raises them, so files, outputs and backends need not import the
compiler."""
from __future__ import annotations

from .diagnostic import Diagnostic


class InputError(Exception):
    """A file that cannot be read at all (exit 2)."""

    def __init__(self, diagnostic: Diagnostic):
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


class SourceError(InputError):
    """A file that was read but whose bytes are wrong (not UTF-8, too large): an error in the
    file, exit 1 like any other (check_file reports it as the file's diagnostic)."""

    def __init__(self, diagnostic: Diagnostic, text: str | None = None):
        super().__init__(diagnostic)
        self.text = text  # what can be shown of the file (undecodable bytes replaced), for the excerpt

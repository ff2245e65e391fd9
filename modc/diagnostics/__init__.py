"""Diagnostics: spans, the code registry, the Diagnostic type and its renderers."""
from . import codes
from .codes import REGISTRY, Code, Severity
from .diagnostic import Diagnostic, sort_key
from .span import NOWHERE, Span

__all__ = ["codes", "REGISTRY", "Code", "Severity", "Diagnostic", "sort_key", "Span", "NOWHERE"]

"""Syntax: .mod text (and the YAML form) -> frozen AST nodes with spans."""
from .parser import grammar_keywords, parse

__all__ = ["parse", "grammar_keywords"]

"""The language server's features under the names tests/test_lsp.py uses (the server imports
them from their own modules)."""
from .completion import complete
from .document import Analysis
from .formatting import formatting
from .hover import hover
from .language import KEYWORDS, STATEMENTS
from .symbols import definition, symbols

__all__ = ["KEYWORDS", "STATEMENTS", "Analysis", "complete", "definition", "formatting", "hover", "symbols"]

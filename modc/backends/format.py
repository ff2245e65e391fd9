"""Number formatting shared by text backends; its home is modc/formatting.py (passes and
analyses below the backends format the same way), re-exported here for the backends."""
from __future__ import annotations

from ..formatting import num, vec

__all__ = ["num", "vec"]

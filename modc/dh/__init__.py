"""Denavit–Hartenberg: realised standard DH of any chain, and DH tables -> module chains."""

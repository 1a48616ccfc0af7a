"""analysis.numerics."""

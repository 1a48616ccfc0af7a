"""analysis.io."""

"""analysis.data."""

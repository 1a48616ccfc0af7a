"""analysis.report."""

"""siloflow.analysis.report."""

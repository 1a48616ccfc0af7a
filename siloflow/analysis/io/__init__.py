"""siloflow.analysis.io."""

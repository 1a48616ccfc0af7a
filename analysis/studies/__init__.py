"""analysis.studies."""

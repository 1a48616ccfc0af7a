"""analysis.studies.silo_flat."""

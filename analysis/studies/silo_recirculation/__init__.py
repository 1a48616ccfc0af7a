"""analysis.studies.silo_recirculation."""

"""engines.cases."""

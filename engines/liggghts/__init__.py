"""engines.liggghts.run."""

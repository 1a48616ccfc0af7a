"""analysis.studies.blender."""

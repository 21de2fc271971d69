"""softhand.studies.cli."""

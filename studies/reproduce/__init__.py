"""softhand.studies.reproduce."""

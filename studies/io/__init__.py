"""softhand.studies.io."""

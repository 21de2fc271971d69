"""softhand.studies.batch."""

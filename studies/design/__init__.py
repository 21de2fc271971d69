"""softhand.studies.design."""

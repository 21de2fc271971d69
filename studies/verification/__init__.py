"""softhand.studies.verification."""

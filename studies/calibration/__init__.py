"""softhand.studies.calibration."""

"""Fitting design parameters to measured curves: the fit, least squares, measurement files."""

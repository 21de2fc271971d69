"""Rubber: strain energies, measured data sets, fitting a material to tensile tests."""

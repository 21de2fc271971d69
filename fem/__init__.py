"""Hyperelastic FEM on scikit-fem: materials, forms, loads, constraints, contact, Newton, I/O."""

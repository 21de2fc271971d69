"""The paper's analytical virtual-work model (numpy/scipy only; no FEM imports)."""

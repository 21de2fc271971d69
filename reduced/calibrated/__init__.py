"""The FEM-calibrated models: the finger and reservoir tables, the grasp and hold of the calibrated finger."""

"""The paper's equations: kinematics, finger, reservoir, grasp, contact and the free hand."""

"""The hand in time: the plant, the angle and pressure controllers, Table II."""

"""The whole hand holding an object: the objects (primitives and closed triangle meshes), the
hand's layout (each finger's plane, each link's pad), the fast hold model on the calibrated
finger, and the result both hold models answer with."""

"""The finger frame and the hand frame of :mod:`softhand.reduced.equations.kinematics`, both ways.

Finger frame: x along the finger axis, the hinge plate at y = +d. The hinge plate's base
point (0, d) is the hand frame's (base_offset, 0); the finger axis x is the base link's
direction, inclined theta0_hat outward from the downward vertical; the finger frame's +y
(towards the plate, the finger's closing side) points inward.
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign


def hand_frame(design: HandDesign) -> tuple[np.ndarray, np.ndarray]:
    """(M, origin): hand = origin + M (finger - (0, d)) for points in the bending plane."""
    c, s = math.cos(design.theta0), math.sin(design.theta0)
    return np.array([[s, -c], [c, s]]), np.array([design.base_offset, 0.0])


def to_hand_frame(points: np.ndarray, design: HandDesign) -> np.ndarray:
    """Finger-frame (x, y) points (..., 2) [mm] -> the hand frame."""
    M, origin = hand_frame(design)
    return origin + (np.asarray(points, dtype=float) - np.array([0.0, design.d])) @ M.T


def to_finger_frame(points, design: HandDesign) -> np.ndarray:
    """Hand-frame points (..., 2) [mm] -> the finger frame (inverse of :func:`~softhand.fem.hand.frame.to_hand_frame`)."""
    M, origin = hand_frame(design)
    return np.array([0.0, design.d]) + (np.asarray(points, dtype=float) - origin) @ M

r"""What the whole-hand FEM hold (:mod:`softhand.fem.hand.hold`) accepts: its options, the symmetry
orbits of a placement, and the placement checks it makes before any FEM model is built.

Symmetry: when the object is invariant under the rotations about the palm axis that map
fingers onto fingers, sits on that axis and is pulled along it, one finger per orbit is
solved (its images carry the same state rotated) and only the object's translation and
rotation about the axis are unknowns. Otherwise every finger is solved, with all six.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softhand.fem.hand.finger_options import FingerOptions
from softhand.fem.hand.grasp import GraspOptions
from softhand.fem.hand.hold_geometry import rot_y
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


@dataclass(frozen=True)
class ContactOptions:
    """Contact treatment and tolerances of the hold."""

    #: normal penalty epsilon_N to start with [N/mm]: ~50 times a finger tip's stiffness on the
    #: CI mesh (0.2 N/mm), so an Uzawa update cuts the gap ~50-fold while a soft contact (the
    #: weight's share on a nearly vertical pad) keeps a gap window Newton's full steps do not jump
    penalty: float = 10.0
    tangent_penalty: float = 10.0  #: tangential penalty epsilon_T [N/mm]
    max_penalty: float = 1e6      #: the penalties grow x10 while Uzawa stagnates, up to this [N/mm]
    gap_tol: float = 1e-6         #: largest penetration of a touching pad at convergence [mm]
    slip_tol: float = 1e-6        #: largest slip of a sticking pad within a step [mm]
    max_updates: int = 40         #: Uzawa updates per solve
    #: object and hinge equilibrium, relative to the force scale mu a^2 l0 of the finger [-]
    rtol: float = 1e-10
    max_iter: int = 40            #: Newton iterations per Uzawa update
    #: give a Newton attempt up after this many iterations without a 10 % fall of its smallest
    #: residual (not on a path step's supported solve, which can creep and then converge). The
    #: converged solves without support stalled at most 1 iteration (sphere on and off the
    #: axis, CI mesh); a failed one ran all 40 (75 % of a hold's time, in the pulls past its limit)
    stall: int | None = 8
    keep_gap: float = 0.01        #: the Newton tangent keeps pads this near touching in contact [mm]


@dataclass(frozen=True)
class HoldOptions:
    """Discretisation, contact and path of the FEM hold."""

    finger: FingerOptions = field(default_factory=FingerOptions)
    contact: ContactOptions = field(default_factory=ContactOptions)
    placement: GraspOptions = field(default_factory=GraspOptions)  #: palm_gap, clearance, pad_offset
    pad_width: float | None = None   #: pad width across the finger [mm]; None: the design's
    close_steps: int = 4             #: pressure steps from 0 to the grasp pressure
    pull_step: float | None = None   #: first pull increment [N]; None: half the weight, at least 1 N
    #: the holding limit's resolution, relative to it (at least ``pull_floor``): the limit is the
    #: largest pull converged, so it lies up to this far below the pull where equilibrium ends
    #: (the paper's 180 mm sphere of 0.5 kg at 0.9 MPa: 19.47 N resolved to 2 %, 19.85 N to 0.5 %)
    pull_resolution: float = 0.005
    max_pull: float = 2000.0         #: stop pulling there: held beyond it [N]
    max_slide: float | None = None   #: slipped out beyond this slide after release [mm]; None: D / 4
    q_tol: float = 1e-8              #: FEM vs contact hinge angles at convergence [rad]
    max_stagger: int = 30            #: contact/FEM iterations per load step
    symmetry: bool = True            #: solve one finger per symmetry orbit where the case allows
    #: relaxation steps when a load step finds no equilibrium near the last one: the object moves
    #: against a viscous support that fades (:meth:`softhand.fem.hand.hold_model.HoldModel.step`); 0: none
    relax_steps: int = 24
    relax_force: float = 0.05        #: the step without the viscous support is tried below this share of the load
    min_weight_step: float = 1 / 16  #: not held when letting go of this share of the weight fails
    pull_floor: float = 0.02         #: the holding limit's resolution is at least this [N]
    #: "force": the pull is a force stepped up until no equilibrium is found; "displacement": the
    #: object is drawn along the pull through a stiff spring (a load cell) whose far end moves, and
    #: the limit is the first maximum of the spring's force along that path
    #: (:func:`softhand.fem.hand.hold.run_hold`)
    pull_control: str = "force"
    drive_stiffness: float = 100.0   #: the drawing spring's stiffness [N/mm]
    drive_step: float = 0.05         #: the first move of the spring's far end [mm]
    drive_max_slide: float = 1.0     #: the object slides at most about this far in one drawn step [mm]
    #: a maximum of the drawn pull is where the hand lets go once the pull is more than
    #: ``pull_resolution`` below it this much more slide on [mm] (a crease between two pads is passed)
    drive_past_peak: float = 1.0

    def __post_init__(self):
        if not self.close_steps >= 1:
            raise InputError("close_steps", self.close_steps, "must be >= 1")
        if not self.q_tol > 0:
            raise InputError("q_tol", self.q_tol, "must be positive [rad]")
        if self.pull_control not in ("force", "displacement"):
            raise InputError("pull_control", self.pull_control, 'must be "force" or "displacement"')
        for name in ("drive_stiffness", "drive_step", "drive_max_slide", "drive_past_peak"):
            if not getattr(self, name) > 0:
                raise InputError(name, getattr(self, name), "must be positive")


def symmetry_orbits(body, frames, pull_direction, tol: float = 1e-9):
    """[(solved finger, [its images])]: fingers whose rotation about the palm axis maps the
    object onto itself, when the object is centred on the axis and pulled along it; else
    every finger alone."""
    alone = [(j, [j]) for j in range(len(frames))]
    c = np.asarray(body.centre, dtype=float)
    e = np.asarray(pull_direction, dtype=float)
    if abs(c[0]) > tol or abs(c[2]) > tol or np.linalg.norm(np.cross(e, [0.0, 1.0, 0.0])) > tol:
        return alone
    rng = np.random.default_rng(0)
    probe = c + body.radius * rng.uniform(-1.5, 1.5, (200, 3))
    d0 = body.signed_distance(probe)[0]
    orbits, seen = [], set()
    for j, fj in enumerate(frames):
        if j in seen:
            continue
        images = []
        for k, fk in enumerate(frames):
            R = rot_y(fk.azimuth - fj.azimuth)
            if k not in seen and np.allclose(body.signed_distance(c + (probe - c) @ R.T)[0], d0, atol=1e-9):
                images.append(k)
        seen.update(images)
        orbits.append((j, images))
    return orbits


def check_hold(design: HandDesign, obj, pull_direction=(0.0, 1.0, 0.0)):
    """(placed body, finger frames) of ``obj`` on the design's hand: what
    :func:`softhand.fem.hand.hold.solve_hold` refuses (an object the open fingers overlap is
    refused by the model), found before any FEM model. Any placement and pull are solved: with
    the hand's symmetry one finger per orbit, else every finger."""
    from softhand.fem.hand.hold_body import body_of
    from softhand.fem.hand.hold_geometry import FingerFrame
    from softhand.reduced.holding.hand_layout import azimuths

    e = np.asarray(pull_direction, dtype=float)
    if e.shape != (3,) or not np.linalg.norm(e) > 0:
        raise InputError("pull_direction", pull_direction, "must be a nonzero 3-vector")
    body = body_of(obj, design)
    return body, tuple(FingerFrame(float(a)) for a in azimuths(design))

r"""The scene of a result, as named VTK blocks: what a person needs to see to understand it.

A finger state (free bending or a grasp) becomes, in the hand frame of
:mod:`softhand.reduced.equations.kinematics` (x outward, y down, z normal to the bending plane; the
modelled finger's bending plane is z = 0):

* ``tube``: the rubber tube, the computed half (z >= 0) and its mirror image (z <= 0,
  cell data ``mirrored`` = 1; vectors and tensors reflected), with the fields of
  :func:`softhand.fem.io.state_fields` at the reference positions plus ``displacement_mm``;
* ``link_0`` .. ``link_<n_s>``: the rigid shell's links as boxes between the tube and the
  grasping face y = d of the finger frame, in their current (rotated) position;
* ``hinge_1`` .. ``hinge_<n_s>``: the hinge pins, cylinders along z at the current hinge axes;
* for a grasp, ``object``: the object as a sphere of diameter D (the contact model sees
  only its section in the bending plane, a circle), and ``contact_forces``: one point per
  link pad at the contact point with the physical force of the object on the pad
  (``force_N``, glyph-ready point vectors) and its normal part ``normal_force_N``.

The reservoir sheet becomes one block ``sheet``: its wet and dry surfaces revolved about
the axis, at the reference (flat) position with the revolved ``displacement_mm``.

Every block carries field data (``P_cavity_MPa``, and ``n_fingers`` for a finger scene,
``volume_mm3`` for a sheet). The links and hinges are drawn with ``link_gap`` between
neighbours and a pin radius ``pin_radius`` of this module: they are pictures, not the
model's geometry (the model's shell is the tie of :mod:`softhand.fem.hand.finger`).
"""
from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from softhand.fem.hand.frame import hand_frame

LINK_GAP = 1.0    #: gap drawn between neighbouring links [mm]
PIN_RADIUS = 2.0  #: radius of the hinge pins drawn [mm]
#: point fields that are vectors (rotated and reflected with the geometry)
VECTORS = ("displacement_mm",)
#: point/cell fields that are 3 x 3 tensors, 9 components row-major
TENSORS = ("cauchy_stress_MPa",)


@dataclass(frozen=True)
class Block:
    """One dataset of a scene: points (m, 3) [mm], cells {meshio type: (k, nodes)}, data."""

    name: str
    points: np.ndarray
    cells: dict
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)


def hand_rotation(design) -> np.ndarray:
    """3 x 3 rotation finger frame -> hand frame (z kept); see :func:`softhand.fem.hand.frame.to_hand_frame`."""
    return np.block([[hand_frame(design)[0], np.zeros((2, 1))], [np.zeros((1, 2)), np.ones((1, 1))]])


def to_hand(points, design) -> np.ndarray:
    """Finger-frame points (m, 3) -> hand frame (m, 3) [mm]."""
    shift = np.array([design.base_offset, 0.0, 0.0]) - hand_rotation(design) @ [0.0, design.d, 0.0]
    return np.asarray(points, dtype=float) @ hand_rotation(design).T + shift


def finger_blocks(model, y, *, load=None) -> list[Block]:
    """The tube, links and hinges of finger ``model`` (:class:`softhand.fem.hand.finger.FingerModel`) at
    reduced state ``y``; with ``load`` (a :class:`softhand.fem.contact.ContactLoad`) the pad forces."""
    from softhand.fem.io import state_fields

    design, basis = model.design, _vector_basis(model)
    u = model.displacement(y)
    point_data, cell_data = state_fields(basis, u, model.law, J_bar=model.element_dilatation(y),
                                         extra={"rubber_stretch": model.rubber_stretch_field(y)})
    points = basis.split(u)[0][1].doflocs.T
    tube = _mirrored(Block("tube", points, {"tetra10": basis.split(u)[0][1].element_dofs.T},
                           point_data, cell_data), design)
    q = np.asarray(model.constraint.q(y), dtype=float)
    blocks = [tube, *link_blocks(model.chain, q, design), *hinge_blocks(model.chain, q, design)]
    if load is not None:
        blocks.append(force_block(load, design))
    return blocks


_BASES = weakref.WeakKeyDictionary()


def _vector_basis(model):
    """The model's vector P2 basis, built once per model (it costs a quadrature setup)."""
    if model not in _BASES:
        _BASES[model] = model.vector_basis()
    return _BASES[model]


def _mirrored(half: Block, design) -> Block:
    """The half model and its mirror image in z = 0, in the hand frame."""
    R, S = hand_rotation(design), np.diag([1.0, 1.0, -1.0])
    n, m = len(half.points), len(next(iter(half.cells.values())))
    points = to_hand(np.concatenate([half.points, half.points @ S]), design)
    cells = {k: np.concatenate([c, c + n]) for k, c in half.cells.items()}
    point_data = {k: _reflect_rotate(k, v, S, R) for k, v in half.point_data.items()}
    cell_data = {k: _reflect_rotate(k, v, S, R) for k, v in half.cell_data.items()}
    cell_data["mirrored"] = np.repeat(np.array([0, 1], dtype=np.int8), m)
    return Block(half.name, points, cells, point_data, cell_data)


def _reflect_rotate(name: str, value: np.ndarray, S, R) -> np.ndarray:
    """Values of both halves (computed, then reflected by S), rotated by R to the hand frame."""
    value = np.asarray(value, dtype=float)
    if name in VECTORS:
        both = np.concatenate([value, value @ S])
        return both @ R.T
    if name in TENSORS:
        T = value.reshape(-1, 3, 3)
        both = np.concatenate([T, S @ T @ S])
        return (R @ both @ R.T).reshape(-1, 9)
    return np.concatenate([value, value])


def link_boxes(chain, q, design) -> np.ndarray:
    """Corners (n_s + 1, 8, 3) of the links drawn as boxes, finger frame, current position."""
    ends = np.array([0.0, *design.hinge_s, design.l0])
    x0, x1 = ends[:-1] + 0.5 * LINK_GAP, ends[1:] - 0.5 * LINK_GAP
    x0[0] = 0.0
    y0, y1, w = design.a + design.b + 0.5, design.d, design.a + design.b
    corner = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                       [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    xs = np.where(corner[None, :, 0], x1[:, None], x0[:, None])            # (links, 8)
    ys = np.where(corner[:, 1], y1, y0)[None].repeat(len(ends) - 1, axis=0)
    zs = np.where(corner[:, 2], w, -w)[None].repeat(len(ends) - 1, axis=0)
    c, phi = chain.link_poses(q)
    cos, sin = np.cos(phi)[:, None], np.sin(phi)[:, None]
    return np.stack([c[:, :1] + cos * xs - sin * ys, c[:, 1:] + sin * xs + cos * ys, zs], axis=-1)


def link_blocks(chain, q, design) -> list[Block]:
    """One hexahedron block per link, hand frame, with its hinge index in ``link``."""
    boxes = link_boxes(chain, q, design)
    return [Block(f"link_{k}", to_hand(box, design), {"hexahedron": np.arange(8)[None]},
                  cell_data={"link": np.array([k])}) for k, box in enumerate(boxes)]


def hinge_blocks(chain, q, design, n: int = 24) -> list[Block]:
    """One solid cylinder (wedge cells around the axis) per hinge pin, hand frame."""
    w = design.a + design.b + 1.0
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = np.c_[PIN_RADIUS * np.cos(a), PIN_RADIUS * np.sin(a)]
    i = np.arange(n)
    wedges = np.stack([np.zeros(n, int), 1 + i, 1 + (i + 1) % n,
                       n + 1 + np.zeros(n, int), n + 2 + i, n + 2 + (i + 1) % n], axis=1)
    blocks = []
    for k, p in enumerate(chain.hinge_positions(q), start=1):
        disc = np.vstack([[0.0, 0.0], ring]) + p
        pts = np.vstack([np.c_[disc, np.full(n + 1, -w)], np.c_[disc, np.full(n + 1, w)]])
        blocks.append(Block(f"hinge_{k}", to_hand(pts, design), {"wedge": wedges},
                            cell_data={"hinge": np.full(n, k)}))
    return blocks


def force_block(load, design) -> Block:
    """The pads' contact points with the object's force on each (physical, hand frame)."""
    R = hand_rotation(design)
    n = len(load.N)
    points = to_hand(np.c_[load.points, np.zeros(n)], design)
    forces = np.c_[load.forces, np.zeros(n)] @ R.T
    return Block("contact_forces", points, {"vertex": np.arange(n)[:, None]},
                 point_data={"force_N": forces, "normal_force_N": np.asarray(load.N, dtype=float),
                             "link": np.arange(n)})


def sphere_block(centre, radius: float, n: int = 32) -> Block:
    """The object: a sphere (quads, triangles at the poles) of ``radius`` [mm] at ``centre``."""
    theta = np.linspace(0.0, np.pi, n + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, 2 * n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    points = np.asarray(centre, dtype=float) + radius * np.vstack([ring, [[0, 1, 0], [0, -1, 0]]])
    m = 2 * n
    i, j = np.meshgrid(np.arange(n - 2), np.arange(m), indexing="ij")
    jn = (j + 1) % m
    quads = np.stack([i * m + j, i * m + jn, (i + 1) * m + jn, (i + 1) * m + j], axis=-1).reshape(-1, 4)
    top, bottom = len(ring), len(ring) + 1
    k = np.arange(m)
    tris = np.vstack([np.c_[np.full(m, top), (k + 1) % m, k],
                      np.c_[np.full(m, bottom), (n - 2) * m + k, (n - 2) * m + (k + 1) % m]])
    return Block("object", points, {"quad": quads, "triangle": tris})


def sheet_block(solid, state, n_phi: int = 48) -> Block:
    """The sheet's wet and dry surfaces revolved about the axis (z), reference position,
    with ``displacement_mm`` (u_r e_r + u_z e_z), ``height_mm`` (current z) and ``hoop_stretch``."""
    from softhand.fem.hand.reservoir import surface_nodes

    phi = np.linspace(0.0, 2 * np.pi, n_phi, endpoint=False)
    cos, sin = np.cos(phi)[None], np.sin(phi)[None]
    points, quads, data = [], [], {"displacement_mm": [], "height_mm": [], "hoop_stretch": []}
    for z0 in (0.0, float(solid.mesh.p[1].max())):
        r0, r, z = surface_nodes(solid, state.u, z0)
        base = sum(len(p) for p in points)
        points.append(np.stack([np.outer(r0, cos), np.outer(r0, sin),
                                np.full((len(r0), n_phi), z0)], axis=-1).reshape(-1, 3))
        ur = (r - r0)[:, None]
        uz = np.broadcast_to((z - z0)[:, None], ur.shape[:1] + cos.shape[1:])
        data["displacement_mm"].append(np.stack([ur * cos, ur * sin, uz], axis=-1).reshape(-1, 3))
        data["height_mm"].append(np.repeat(z, n_phi))
        hoop = np.where(r0 > 0, r / np.where(r0 > 0, r0, 1.0), state.lambda_hoop[0])
        data["hoop_stretch"].append(np.repeat(hoop, n_phi))
        i, j = np.meshgrid(np.arange(len(r0) - 1), np.arange(n_phi), indexing="ij")
        jn = (j + 1) % n_phi
        quads.append(base + np.stack([i * n_phi + j, (i + 1) * n_phi + j, (i + 1) * n_phi + jn,
                                      i * n_phi + jn], axis=-1).reshape(-1, 4))
    return Block("sheet", np.concatenate(points), {"quad": np.concatenate(quads)},
                 {k: np.concatenate(v) for k, v in data.items()})


def finger_scene(model, y, P: float) -> tuple[list[Block], dict]:
    """(blocks, field data) of a free finger at state ``y`` and pressure ``P`` [MPa]."""
    q = model.constraint.q(y)
    return finger_blocks(model, y), {"P_cavity_MPa": float(P), "theta_deg": math.degrees(float(np.sum(q))),
                                     "n_fingers": model.design.n}


def grasp_scene(grasp, state) -> tuple[list[Block], dict]:
    """(blocks, field data) of a converged contact state of :class:`softhand.fem.hand.grasp.GraspModel`."""
    blocks = finger_blocks(grasp.finger, state.y, load=grasp.state_load(state))
    blocks.append(sphere_block([0.0, grasp.depth, 0.0], 0.5 * grasp.diameter))
    return blocks, {"P_cavity_MPa": float(state.P), "theta_deg": math.degrees(state.theta),
                    "n_fingers": grasp.design.n, "diameter_mm": grasp.diameter,
                    "F_v_N": float(state.F_v)}

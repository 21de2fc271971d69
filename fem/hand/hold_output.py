"""What a FEM hold gives back: the common :class:`softhand.reduced.holding.hold_result.HoldResult`, its
``result.json`` and the VTK scene of every load step (every finger, the object's surface,
arrows for the normal and friction forces at each contact)."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from softhand.fem.hand.hold_geometry import Pose, rot_y
from softhand.fem.hand.scene import TENSORS, VECTORS, Block, finger_blocks
from softhand.meshes.atomic import atomic_path
from softhand.reduced.holding.hold_result import Contact, HoldResult, LoadStep


def _contacts(record) -> tuple:
    out = []
    for c in record.contacts:
        if c["normal_N"] <= 0:
            continue
        N = np.asarray(c["normal_force_N"])
        T = -np.asarray(c["friction_force_N"])  # on the object
        size = np.linalg.norm(T)
        out.append(Contact(c["finger"], c["link"], c["normal_N"], c["friction_N"], c["state"],
                           tuple(c["point_mm"]), tuple(N / np.linalg.norm(N)),  # the object's outward normal
                           tuple(T / size) if size > 0 else ()))
    return tuple(out)


def _step_row(record) -> LoadStep:
    return LoadStep(record.stage, record.P, record.pull_N, True, tuple(record.pose[:3]),
                    tuple(np.degrees(Rotation.from_rotvec(record.pose[3:]).as_euler("xyz"))),
                    sum(c["normal_N"] > 0 for c in record.contacts),
                    {"gravity": record.gravity, "object_residual": record.residual_N,
                     "friction_cone": record.cone, "penetration_mm": record.penetration_mm,
                     "stick_slip_mm": record.stick_slip_mm, "q_mismatch_rad": record.q_mismatch,
                     "finger_residual_Nmm": record.fem_residual, "iterations": record.iterations,
                     "path_steps": record.relaxed})


def to_result(path, *, obj=None) -> HoldResult:
    """The common result of a :class:`softhand.fem.hand.hold.HoldPath`: contacts and pose under the
    object's own weight (the release step; the last closed state when not held)."""
    m = path.model
    released = [s for s in path.steps if s.stage == "release" and s.gravity == 1.0]
    at_weight = released[-1] if released else (path.steps[-1] if path.steps else None)
    notes = []
    if not path.held:
        notes.append(f"not held under its own weight: {path.failure}")
    elif not path.limit_reached:
        notes.append(f"still held at the largest pull tried ({m.options.max_pull:g} N)")
    elif path.failure:
        notes.append(f"the next pull increment: {path.failure}")
    if m.symmetric:
        notes.append(f"symmetric: {m.n_solved} of {len(m.frames)} fingers solved")
    o, c = m.options, m.options.contact
    return HoldResult(
        model="fem", held=path.held, holding_limit_N=float(path.holding_limit_N),
        pull_direction=tuple(float(v) for v in m.pull_direction),
        contacts=_contacts(at_weight) if at_weight else (),
        P_cavity_MPa=float(m.P), P_pump_MPa=math.nan, mass_kg=float(m.body.mass_kg),
        friction=float(m.body.friction), object=obj.to_dict() if obj is not None else {},
        displacement_mm=tuple(at_weight.pose[:3]) if at_weight else (0.0, 0.0, 0.0),
        rotation_deg=tuple(np.degrees(Rotation.from_rotvec(at_weight.pose[3:]).as_euler("xyz")))
        if at_weight else (0.0, 0.0, 0.0),
        steps=tuple(_step_row(s) for s in path.steps), symmetric=m.symmetric, notes=tuple(notes),
        extra={"fingers_solved": m.n_solved, "finger_unknowns": m.model.ndofs,
               "gap_tol_mm": c.gap_tol, "slip_tol_mm": c.slip_tol, "q_tol_rad": o.q_tol,
               "equilibrium_tol_Nmm": c.rtol * m.scale, "pull_resolution": o.pull_resolution,
               "wall_seconds": path.wall_seconds, "holding_limit_kg": path.holding_limit_N / 9.80665})


def _rotated(block: Block, R: np.ndarray, prefix: str) -> Block:
    def turn(name, v):
        v = np.asarray(v, dtype=float)
        if name in VECTORS:
            return v @ R.T
        if name in TENSORS:
            return (R @ v.reshape(-1, 3, 3) @ R.T).reshape(-1, 9)
        return v
    return Block(f"{prefix}{block.name}", block.points @ R.T, block.cells,
                 {k: turn(k, v) for k, v in block.point_data.items()},
                 {k: turn(k, v) for k, v in block.cell_data.items()})


def scene_blocks(model, record) -> list[Block]:
    """Every finger (a solved finger's state rotated onto its images; finger 0's blocks named as
    a one-finger scene's -- ``tube``, ``link_k``, ``hinge_k`` -- the others' prefixed
    ``finger<j>_``), the object at its pose,
    and the contact forces (point vectors ``force_N`` of the object on each pad, its parts
    ``normal_force_N`` and ``friction_force_N``, and ``stick``)."""
    blocks = []
    for (j, images), y in zip(model.orbits, record.states):
        base = finger_blocks(model.model, y)
        for k in images:
            R = rot_y(model.frames[k].azimuth)
            blocks += [_rotated(b, R, f"finger{k}_" if k else "") for b in base]
    pts, tris = model.body.surface()
    pose = Pose(model.body.centre, record.pose)
    blocks.append(Block("object", pose.to_hand(np.asarray(pts)), {"triangle": np.asarray(tris)}))
    touching = [c for c in record.contacts if c["normal_N"] > 0]
    if touching:
        blocks.append(Block(
            "contact_forces", np.array([c["point_mm"] for c in touching]),
            {"vertex": np.arange(len(touching))[:, None]},
            point_data={"force_N": np.array([np.add(c["normal_force_N"], c["friction_force_N"]) for c in touching]),
                        "normal_force_N": np.array([c["normal_force_N"] for c in touching]),
                        "friction_force_N": np.array([c["friction_force_N"] for c in touching]),
                        "stick": np.array([c["state"] == "stick" for c in touching], dtype=np.int8),
                        "finger": np.array([c["finger"] for c in touching]),
                        "link": np.array([c["link"] for c in touching])}))
    return blocks


def write_hold(path, result: HoldResult, out_dir, *, vtk: bool = True) -> Path:
    """``result.json`` (the result with every load step) and, with ``vtk``, the scene series
    ``hold.pvd`` (one scene per load step) in ``out_dir``; returns the JSON's path."""
    from softhand.fem.io import SceneSeries

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if vtk:
        series = SceneSeries(out / "hold.pvd")
        for i, record in enumerate(path.steps):
            series.write(float(i), scene_blocks(path.model, record),
                         {"P_cavity_MPa": record.P, "pull_N": record.pull_N, "n_fingers": 1})
    target = out / "result.json"
    with atomic_path(target) as tmp:
        tmp.write_text(json.dumps(result.to_json(), indent=1, allow_nan=True))
    return target

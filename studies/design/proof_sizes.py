"""The finger meshes a design's FEM proof tries: the element sizes in turn (a thick wall gets a
finer mesh, a failed proof one finer still), and the check, before the optimiser runs, that the
finest of them fits this machine's memory.
"""
from __future__ import annotations

from softhand.studies.design.task import Task


#: walls above this [mm] get at most PROOF_MESH_THICK_WALL: on the 10 mm finger mesh the FEM is
#: wrong there (b = 5.5 mm: Newton fails below 0.2 MPa; b = 6 mm: a cavity volume change larger
#: than the cavity), on 6 mm elements it is right up to b = 6 mm
THICK_WALL_MM, PROOF_MESH_THICK_WALL = 5.0, 6.0
#: a proof that fails on its meshes is tried once more on this finer one [mm]: a thin wall with
#: little room in the links (a 6, b 3, d 10, l0 200 mm) stalls on the 10 and 6 mm meshes (0.17
#: and 0.30 MPa); on 4 mm it bends to 139 deg at 0.9 MPa, as the calibration's layered mesh does
#: (140 deg), and its proof ends with a verdict (8.5 min instead of "could not be completed")
PROOF_MESH_FINEST = 4.0


def proof_meshes(design, mesh_size_mm: float) -> list[float]:
    """The finger element sizes [mm] the proof tries in turn: :func:`proof_mesh`'s, then the
    thick walls' and the finest one where they are finer."""
    h = proof_mesh(design, mesh_size_mm)
    return [h] + [s for s in (PROOF_MESH_THICK_WALL, PROOF_MESH_FINEST) if s < h]


def proof_mesh(design, mesh_size_mm: float) -> float:
    """The finger element size [mm] of the proof for this design: ``mesh_size_mm``, at most
    PROOF_MESH_THICK_WALL for a wall b above THICK_WALL_MM."""
    return min(mesh_size_mm, PROOF_MESH_THICK_WALL) if design.b > THICK_WALL_MM else mesh_size_mm


def check_proof_size(task: Task, mesh_size_mm: float) -> None:
    """Refuse (MeshTooLarge) a proof mesh too large for this machine's memory whatever the design:
    bounded on the task's thinnest, shortest tube (a, b, l0 at their lower bounds where free) and
    the finest mesh the proof may try, before the optimiser runs, not after it."""
    from softhand.fem.hand.finger_options import UNKNOWNS_PER_TET, check_unknowns, gmsh_least_tets

    low = {key: lo for key, lo, _ in task.free}
    a, b, l0 = (low.get(key, default) for key, default in
                (("a_mm", task.base.a), ("b_mm", task.base.b), ("l0_mm", task.base.l0)))
    h = min(mesh_size_mm, PROOF_MESH_FINEST)
    check_unknowns(int(UNKNOWNS_PER_TET * gmsh_least_tets(a, b, l0, b, h)), f"gmsh mesh_size={h:g} (the proof's)")

"""The finger FEM's discretisation and modelling options, the tie bands and the mesh they give
(and whether the FEM takes it)."""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from softhand.fem.mapping import folded_elements
from softhand.meshes.finger import FingerTube, finger_tube_mesh, layered_tets, layered_tube_mesh
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError, MeshRejected, MeshTooLarge

TIES = ("ring", "full")
MESHERS = ("layered", "gmsh")


@dataclass(frozen=True)
class FingerOptions:
    """Discretisation and modelling choices of the finger FEM."""

    #: the default mesh is layered (meshes.finger.layered_tube_mesh): 4 sectors over the half
    #: circumference, 5 wall layers from 0.2 mm at the cavity, axial slices of at most 2.5 mm
    #: (38k unknowns); theta(0.8 MPa) 0.3 % below the extrapolated value (docs/finger.md: mesh
    #: convergence). "gmsh": an unstructured mesh of size mesh_size (the CI mesh: 6 mm, uniform,
    #: unrefined; 3.6 % below)
    mesher: str = "layered"    #: "layered" (structured, no gmsh) or "gmsh"
    n_phi: int = 4             #: layered: sectors over the half circumference (180 deg)
    layer_first: float = 0.2   #: layered: thickness of the wall layer at the cavity [mm]
    layer_ratio: float = 2.0   #: layered: growth of the layer thickness towards the outside
    axial_size: float = 2.5   #: layered: largest slice length along the finger [mm]
    mesh_size: float = 6.0     #: gmsh: target element size, before mesh_refine [mm]
    edge_ratio: float = 1.0    #: gmsh: element size at the ring edges and cap corner / mesh_size (1: uniform)
    edge_reach: float = 3.0    #: gmsh: distance over which the size grows back to mesh_size [mm]
    mesh_refine: int = 0       #: split every element / halve every spacing this many times (nested meshes)
    tie: str = "ring"          #: which outer surface the links hold: "ring" or "full"
    tie_width: float | None = None  #: width of each link's tied ring [mm]; None: the design's tie_width_mm
    hinge_gap: float = 4.0     #: untied tube length around each hinge, tie = "full" [mm]
    cap: float | None = None   #: end-cap thickness at the tip [mm]; None: the wall b
    kappa_ratio: float = 1000.0  #: bulk over shear modulus of the rubber
    fiber_ratio: float = 1000.0  #: fiber stiffness over mu (Kevlar >> rubber)
    fiber_toe: float = 0.0     #: fiber strain over which the windings' stiffness sets in (0: a jump)
    fiber_intorder: int = 5    #: degree of the quadrature rule of the windings' energy (2: the rubber's)

    def __post_init__(self):
        if self.mesher not in MESHERS:
            raise InputError("mesher", self.mesher, f"must be one of {', '.join(MESHERS)}")
        if not (isinstance(self.n_phi, int) and self.n_phi >= 2):
            raise InputError("n_phi", self.n_phi, "must be an integer >= 2")
        if not self.layer_ratio >= 1:
            raise InputError("layer_ratio", self.layer_ratio, "must be >= 1")
        if self.tie not in TIES:
            raise InputError("tie", self.tie, f"must be one of {', '.join(TIES)}")
        if not get_quadrature(RefTet, self.fiber_intorder)[1].min() > 0:
            raise InputError("fiber_intorder", self.fiber_intorder,
                             "must name a tetrahedral rule with positive weights (e.g. 2, 5, 6)")
        if not 0 < self.edge_ratio <= 1:
            raise InputError("edge_ratio", self.edge_ratio, "must be in (0, 1]")
        if self.mesh_refine not in range(0, 4):
            raise InputError("mesh_refine", self.mesh_refine, "must be 0, 1, 2 or 3")
        for name in ("layer_first", "axial_size", "mesh_size", "edge_reach", "tie_width", "hinge_gap", "kappa_ratio", "fiber_ratio"):
            if getattr(self, name) is not None and not getattr(self, name) > 0:
                raise InputError(name, getattr(self, name), "must be a positive number")


def mesh_options(mesh_size: float | None = None, axial_size: float | None = None) -> FingerOptions:
    """The options of a mesh asked by its size: the layered mesh with slices of at most
    ``axial_size`` [mm], else a uniform gmsh mesh of ``mesh_size`` [mm], else the default."""
    if axial_size is not None:
        return FingerOptions(axial_size=float(axial_size))
    if mesh_size is not None:
        return FingerOptions(mesher="gmsh", mesh_size=float(mesh_size))
    return FingerOptions()


def ring_width(design: HandDesign, options: FingerOptions) -> float:
    """Width of each link's tied ring [mm]: the options' if given, else the design's tie_width."""
    return design.tie_width if options.tie_width is None else options.tie_width


def tie_bands(design: HandDesign, options: FingerOptions) -> tuple[tuple[float, float], ...]:
    """(x_start, x_end) of the tube band each link holds [mm] (see :class:`~softhand.fem.hand.finger_options.FingerOptions`)."""
    s = np.array((0.0, *design.hinge_s, design.l0))
    if options.tie == "ring":
        width = ring_width(design, options)
        mid, half = 0.5 * (s[:-1] + s[1:]), 0.5 * width
        if width >= np.diff(s).min():
            raise InputError("tie_width_mm", width, "must be shorter than every link")
        return tuple((float(m - half), float(m + half)) for m in mid)
    gap = 0.5 * options.hinge_gap
    if options.hinge_gap >= np.diff(s).min():
        raise InputError("hinge_gap", options.hinge_gap, "must be shorter than every link")
    start, end = s[:-1] + gap, s[1:] - gap
    start[0], end[-1] = 0.0, design.l0
    return tuple((float(a), float(b)) for a, b in zip(start, end))



#: the finger FEM's peak memory, measured: 14.9 GB at 553 820 unknowns (gmsh level 2,
#: docs/finger.md); a sparse factor's fill in 3D grows about as unknowns^(4/3)
MEASURED_UNKNOWNS, MEASURED_PEAK_BYTES, FILL_EXPONENT = 553_820, 14.9e9, 4 / 3
#: unknowns per tetrahedron, at least (P2, after the links' reduction: 4.2-4.7 measured on
#: layered and gmsh meshes of 2 000-130 000 tetrahedra)
UNKNOWNS_PER_TET = 4
#: a gmsh tetrahedron of size h is at most this times h^3 in volume on average (1.15 mm^3 at
#: h = 2 mm, 0.14-0.22 h^3 measured; thin walls make them smaller)
TET_VOLUME_PER_H3 = 0.2


def least_unknowns(tube: FingerTube, options: FingerOptions) -> int:
    """A lower bound of the finger FEM's unknowns on this mesh, without meshing: the layered
    mesh's tetrahedra counted exactly; gmsh's from the half tube's volume over the largest
    average tetrahedron of its size (grading only adds elements)."""
    if options.mesher == "layered":
        tets = layered_tets(tube, n_phi=options.n_phi, layer_first=options.layer_first,
                            layer_ratio=options.layer_ratio, axial_size=options.axial_size,
                            refine=options.mesh_refine)
    else:
        tets = gmsh_least_tets(tube.a, tube.b, tube.length, tube.cap, options.mesh_size, options.mesh_refine)
    return int(UNKNOWNS_PER_TET * tets)


def gmsh_least_tets(a: float, b: float, length: float, cap: float, size: float, refine: int = 0) -> float:
    """At least the tetrahedra of gmsh's half tube of element size ``size`` [mm], refined
    ``refine`` times: its volume over the largest average tetrahedron of that size."""
    volume = 0.5 * np.pi * ((a + b) ** 2 * length - a ** 2 * (length - cap))
    return 8 ** refine * volume / (TET_VOLUME_PER_H3 * size ** 3)


#: a container's memory limit (cgroup v2, v1), where it is lower than the machine's
CGROUP_LIMITS = ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes")


def memory_bytes() -> float | None:
    """The memory this process may use [bytes]: the machine's, or its container's limit where
    lower; None where the system does not say."""
    try:
        memory = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None
    for path in CGROUP_LIMITS:
        try:
            with open(path) as f:
                memory = min(memory, float(f.read().split()[0]))  # "max": no limit
        except (OSError, ValueError, IndexError):
            pass
    return memory


def most_unknowns(memory: float) -> int:
    """About the most unknowns whose finger FEM fits in ``memory`` bytes (see MEASURED_*)."""
    return int(MEASURED_UNKNOWNS * (memory / MEASURED_PEAK_BYTES) ** (1 / FILL_EXPONENT))


def check_size(tube: FingerTube, options: FingerOptions, memory: float | None = None) -> None:
    """Refuse (MeshTooLarge), before meshing, a mesh whose FEM cannot fit in this machine's
    memory (a mesh size of 0.5 mm would mesh for minutes, then fill the memory and be killed)."""
    check_unknowns(least_unknowns(tube, options), describe_mesh(options), memory)


def check_unknowns(least: int, mesh: str, memory: float | None = None) -> None:
    """MeshTooLarge if ``least`` unknowns (a lower bound) exceed what ``memory`` (default: this
    machine's) holds; ``mesh`` names the mesh in the message."""
    memory = memory_bytes() if memory is None else memory
    if memory is None:
        return
    most = most_unknowns(memory)
    if least > most:
        raise MeshTooLarge(mesh, f"has at least {least:,} unknowns; {memory / 2 ** 30:.0f} GiB of memory hold "
                                 f"the finger FEM of about {most:,} (measured: {MEASURED_PEAK_BYTES / 1e9:g} GB "
                                 f"at {MEASURED_UNKNOWNS:,}); choose a coarser mesh")


def build_mesh(tube: FingerTube, options: FingerOptions):
    if options.mesher == "layered":
        return layered_tube_mesh(tube, n_phi=options.n_phi, layer_first=options.layer_first,
                                 layer_ratio=options.layer_ratio, axial_size=options.axial_size,
                                 refine=options.mesh_refine)
    return finger_tube_mesh(tube, size=options.mesh_size, refine=options.mesh_refine)


def describe_mesh(options: FingerOptions) -> str:
    if options.mesher == "layered":
        return (f"layered n_phi={options.n_phi} layer_first={options.layer_first} "
                f"layer_ratio={options.layer_ratio} axial_size={options.axial_size} refine={options.mesh_refine}")
    return (f"gmsh mesh_size={options.mesh_size} edge_ratio={options.edge_ratio} "
            f"refine={options.mesh_refine}")


def finger_tube(design: HandDesign, options: FingerOptions) -> FingerTube:
    """The half tube the finger FEM meshes: the design's radii and length, the options' end cap
    (default: the wall b) and tie bands."""
    cap = options.cap if options.cap is not None else design.b
    return FingerTube(design.a, design.b, design.l0, cap, tie_bands(design, options),
                      options.edge_ratio, options.edge_reach)


def refuse_folds(mesh, options: FingerOptions) -> None:
    """MeshRejected if curved elements of ``mesh`` fold over themselves (positive at the
    quadrature points, folded between them: the FEM stops or balloons the tube)."""
    folded = folded_elements(mesh)
    if folded.size:
        raise MeshRejected(describe_mesh(options),
                           f"has {folded.size} curved elements that fold over themselves (its FEM "
                           f"stops or balloons the tube); try a finer mesh size, edge_ratio 1 "
                           f"(uniform) or the layered mesher")


def check_finger_mesh(design: HandDesign, options: FingerOptions) -> None:
    """The finger mesh of ``design`` is one the FEM takes (size, folds), without the FEM: a
    study checks each case's mesh before any case runs. A gmsh mesh goes through the cache,
    which keeps it only if it is taken (a refused run leaves nothing behind)."""
    tube = finger_tube(design, options)
    check_size(tube, options)
    if options.mesher == "layered":
        refuse_folds(build_mesh(tube, options), options)
        return
    from softhand.meshes.cache import cache_dir, discard, mesh_key, valid_entry
    from softhand.meshes.finger import finger_geometry

    key = mesh_key(finger_geometry, tube, size=options.mesh_size, order=2, refine=options.mesh_refine)
    path = cache_dir() / f"{finger_geometry.__name__}-{key}.msh"
    cached, made = valid_entry(path), [d for d in (path.parent, path.parent.parent) if not d.exists()]
    try:
        refuse_folds(build_mesh(tube, options), options)
    except MeshRejected:
        if not cached:
            discard(path, made)
        raise

r"""The finger FEM: a fiber-reinforced rubber tube held by a hinged rigid shell, under pressure.

Model (the paper's section II-B, with the choices the paper leaves open made explicit):

* the NBR tube of :mod:`meshes.finger` (inner radius a, wall b, length l0 with an end cap
  of thickness ``cap`` at the tip), half model on the bending plane z = 0;
* nearly incompressible Neo-Hookean rubber (mu_sf, kappa = ``kappa_ratio`` mu) in the
  mean-dilatation P2-P0 formulation of :mod:`fem.solid`, plus a tension-only fiber family
  (the Kevlar windings) along the hoop direction e_phi = (0, -z, y)/r, stiffness
  ``fiber_ratio`` mu, everywhere in the wall (the cap too). The windings' energy is
  integrated with its own rule (:class:`Windings`, degree ``fiber_intorder``, default the
  14-point degree-5 rule whose points include the edge midpoints): the 4-point rule of the
  rubber samples the tension-only switch only inside the elements and misses the taut
  layer at the cavity wall, which made theta converge from above, non-monotonically, with
  the number of elements through the wall (docs/finger.md, mesh convergence);
* oil pressure P on the cavity: the closed-cavity load P dV/du with its symmetric load
  stiffness P d2V/du2, V the cavity volume of :class:`fem.loads.CavityVolume` (closed by
  the symmetry plane z = 0 and the fixed inlet plane x = 0);
* the shell: a :class:`fem.constraints.PlanarChain` with hinges at (``hinge_s``, d) in the
  finger frame (the hinge plate at y = +d), link 0 fixed; the tube's base face is clamped
  to link 0 and the outer-surface band ``tie<k>`` moves rigidly with link k
  (:class:`fem.constraints.ChainConstraint`);
* unknowns y = (free displacements, hinge angles q); theta = sum(q); the hand's base
  inclination theta0_hat only rotates the result (:func:`to_hand_frame`).

Which part of the outer surface the shell holds is a modelling choice
(:class:`FingerOptions` ``tie``): ``"ring"`` ties a band of width ``tie_width`` in the
middle of each link (the shell clamps the tube at rings and lets it bend between
them), ``"full"`` ties each link's whole length except ``hinge_gap`` around each hinge
(a closed shell that lets the tube deform only at the hinges). docs/finger.md compares
them.

Generalised forces on the links (contact with an object, its weight) are passed to
:meth:`FingerModel.residual_tangent` as ``link_load(q) -> (Q, dQ/dq)``; see
:meth:`fem.constraints.PlanarChain.point_load`.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from skfem import Basis, ElementTetP2, ElementVector
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from softhand.fem import kinematics as kin
from softhand.fem.constraints import ChainConstraint, PlanarChain
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import CavityVolume
from softhand.fem.hyperelastic import rubber_law
from softhand.fem.materials import Fibers
from softhand.fem.newton import NewtonOptions, NotConverged, PathOptions, solve_path
from softhand.fem.solid import Solid
from softhand.meshes.finger import FingerTube, finger_tube_mesh, layered_tube_mesh
from softhand.reduced.design import HandDesign
from softhand.reduced.errors import InputError

TIES = ("ring", "full")
MESHERS = ("layered", "gmsh")


@dataclass(frozen=True, eq=False)
class WindingFibers(Fibers):
    r"""The tension-only winding fibers with a smooth onset ("toe") of width ``toe``.

    .. math:: \psi = k\,G(\lambda_f - 1),\quad
        G(e) = \begin{cases} 0 & e \le 0\\ e^3/(6\delta) & 0 < e < \delta\\
        e^2/2 - \delta e/2 + \delta^2/6 & e \ge \delta \end{cases}

    so the fiber stiffness k G'' rises linearly from 0 to k over 0 < e < delta (the slack of
    wound threads) instead of jumping at lambda_f = 1. ``toe = 0`` is
    :class:`fem.materials.Fibers` (stiff already at lambda_f = 1). The jump makes Newton
    chatter where the hoop stretch is near 1, i.e. in much of the bent tube; docs/finger.md
    shows the effect of delta on theta.
    """

    toe: float = 0.0  #: width delta of the onset in fiber strain

    def take(self, elements):
        return self if self.a0.ndim == 1 else WindingFibers(self.k, self.a0[:, elements], self.toe)

    def _g(self, e):
        """(G, G', G'') of the fiber strain e (see the class docstring)."""
        d = self.toe
        if d == 0:
            on = e >= 0
            return (np.where(on, 0.5 * e * e, 0.0), np.where(on, e, 0.0), on * 1.0)
        ramp = np.clip(e, 0.0, d)
        G = np.where(e < d, ramp ** 3 / (6 * d), 0.5 * e * e - 0.5 * d * e + d * d / 6)
        G1 = np.where(e < d, ramp ** 2 / (2 * d), e - 0.5 * d)
        return G, G1, ramp / d

    def energy(self, F):
        return self.k * self._g(self.stretch(F) - 1.0)[0]

    def stress(self, F):
        a0, f, lam, _ = self._kinematics(F)
        return self.k * self._g(lam - 1.0)[1] / lam * np.einsum("a...,K...->aK...", f, a0)

    def tangent(self, F):
        a0, f, lam, _ = self._kinematics(F)
        _, G1, G2 = self._g(lam - 1.0)
        fa = np.einsum("a...,K...->aK...", f, a0)
        aa = np.einsum("ab,K...,L...->aKbL...", np.eye(3), a0, a0)
        return self.k * ((G2 / lam ** 2 - G1 / lam ** 3) * kin.outer(fa, fa) + G1 / lam * aa)


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


def ring_width(design: HandDesign, options: FingerOptions) -> float:
    """Width of each link's tied ring [mm]: the options' if given, else the design's tie_width."""
    return design.tie_width if options.tie_width is None else options.tie_width


def tie_bands(design: HandDesign, options: FingerOptions) -> tuple[tuple[float, float], ...]:
    """(x_start, x_end) of the tube band each link holds [mm] (see :class:`FingerOptions`)."""
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


def hoop_directions(X: np.ndarray) -> np.ndarray:
    """Fiber directions e_phi = (0, -z, y)/r around the tube axis (the x axis), X (3, ...).

    On the axis itself (points of the end cap, r = 0) the hoop is undefined; e_z is used.
    """
    r = np.hypot(X[1], X[2])
    on_axis = r < 1e-12
    a0 = np.stack([np.zeros_like(X[0]), np.where(on_axis, 1.0, -X[2]), X[1]])
    return a0 / np.where(on_axis, 1.0, r)


class Windings:
    r"""The windings' energy :math:`\int k G(\lambda_f - 1)\,dV` (:class:`WindingFibers`),
    residual and tangent, integrated with their own quadrature rule of degree ``intorder``.

    Why a rule of its own: the fiber energy is a kinked function of the hoop strain, and
    the taut fibers sit in a thin layer at the cavity wall (bending contracts the hoop,
    the pressure expands it; at the optimum the hoop strain is largest at the inner
    radius). The rubber's 4-point rule samples it only at points inside each element, so
    the hoop strain at the cavity wall can go positive unseen, the more so the fewer
    elements the wall has; the 14-point degree-5 rule includes the edge midpoints.

    With f = F a0 = a0 + sum_n u_n g_n (g_n = grad N_n . a0) and c1 = k (G''/lam^2 -
    G'/lam^3), c2 = k G'/lam: r_na = sum_q w k G'/lam f_a g_n and
    K_(na)(mb) = sum_q w (c1 f_a g_n f_b g_m + c2 delta_ab g_n g_m): two batched products,
    far cheaper than the general anisotropic tangent of :mod:`fem.solid`, written in the
    block layout K[e, n, a, b, m] of :func:`fem.solid.element_matrices` into a whole-mesh
    buffer and scattered like the rubber's (:meth:`fem.assembly.ElementScatter.block_matrix_data`).
    """

    def __init__(self, mesh, fibers_k: float, toe: float, intorder: int, scatter, chunk=2048):
        basis = Basis(mesh, ElementTetP2(), intorder=intorder)
        self.law = WindingFibers(fibers_k, hoop_directions(np.asarray(basis.global_coordinates().value)), toe)
        a0 = self.law.a0                                                    # (3, nel, nq)
        grads = np.stack([basis.basis[i][0].grad for i in range(basis.Nbfun)])  # (nloc, 3, nel, nq)
        self.g = np.einsum("nkeq,keq->eqn", grads, a0)                      # (nel, nq, nloc)
        self.W = np.asarray(basis.dx)                                       # (nel, nq)
        self.scatter = scatter
        nel = self.W.shape[0]
        self.chunks = [slice(i, min(i + chunk, nel)) for i in range(0, nel, chunk)]
        self._ke = None  # element matrices of the whole mesh, block layout; allocated at first use

    def stretch(self, u: np.ndarray, elements=slice(None)):
        """(f = F a0 (3, ne, nq), fiber stretch lam (ne, nq)) at the rule's points."""
        ue = u[self.scatter.vector_dofs(elements)].reshape(*self.g[elements].shape[::2], 3)
        f = self.law.a0[:, elements] + np.einsum("ena,eqn->aeq", ue, self.g[elements], optimize=True)
        return f, np.sqrt(np.einsum("aeq,aeq->eq", f, f))

    def energy(self, u: np.ndarray) -> float:
        """Stored energy of the windings [N mm]."""
        lam = self.stretch(u)[1]
        return float(np.sum(self.W * self.law.k * self.law._g(lam - 1.0)[0]))

    def _chunk(self, u, c):
        """(f (3, ne, nq), lam, G', G'', v (ne, nq, (n a)) = f_a g_n) of chunk c."""
        f, lam = self.stretch(u, c)
        _, G1, G2 = self.law._g(lam - 1.0)
        v = np.einsum("aeq,eqn->eqna", f, self.g[c]).reshape(*lam.shape, -1)
        return f, lam, G1, G2, v

    def add_residual(self, u: np.ndarray, R: np.ndarray) -> None:
        """R += the windings' internal force."""
        for c in self.chunks:
            _, lam, G1, _, v = self._chunk(u, c)
            self.scatter.add_vector(R, np.einsum("eq,eqi->ei", self.W[c] * self.law.k * G1 / lam, v), c)

    def add_residual_tangent(self, u: np.ndarray, R: np.ndarray, data: np.ndarray) -> None:
        """R += the windings' internal force; data (the CSR data of ``scatter``) += tangent."""
        k = self.law.k
        nel, nq, nloc = self.g.shape
        if self._ke is None:
            self._ke = np.empty((nel, nloc, 3, 3, nloc))
        for c in self.chunks:
            f, lam, G1, G2, v = self._chunk(u, c)
            g, W = self.g[c], self.W[c]
            self.scatter.add_vector(R, np.einsum("eq,eqi->ei", W * k * G1 / lam, v), c)
            c1, c2 = W * k * (G2 / lam ** 2 - G1 / lam ** 3), W * k * G1 / lam
            vt = np.einsum("aeq,eqn->eqan", f, g).reshape(*W.shape, -1)     # (ne, nq, (b m))
            Ke = self._ke[c]
            np.matmul(v.transpose(0, 2, 1) * c1[:, None, :], vt, out=Ke.reshape(len(W), 3 * nloc, 3 * nloc))
            S = np.matmul(g.transpose(0, 2, 1) * c2[:, None, :], g)         # (ne, nloc, nloc)
            for a in range(3):  # + delta_ab S_nm
                Ke[:, :, a, a, :] += S
        data += self.scatter.block_matrix_data(self._ke)


def to_hand_frame(points: np.ndarray, design: HandDesign) -> np.ndarray:
    """Finger-frame (x, y) points (..., 2) -> the hand frame of :mod:`reduced.kinematics`.

    The hinge plate's base point (0, d) goes to (base_offset, 0); the finger axis x to
    the base link's direction, inclined theta0_hat outward from the downward vertical;
    the finger frame's +y (towards the plate, the finger's closing side) points inward.
    """
    c, s = math.cos(design.theta0), math.sin(design.theta0)
    M = np.array([[s, -c], [c, s]])
    rel = np.asarray(points, dtype=float) - np.array([0.0, design.d])
    return np.array([design.base_offset, 0.0]) + rel @ M.T


@dataclass
class FingerState:
    """One converged state of the finger (finger frame, mm, MPa, rad)."""

    P: float                       #: cavity pressure [MPa]
    q: np.ndarray                  #: hinge angles theta_hat_i [rad]
    dQ: float                      #: cavity volume change of the whole finger [mm^3]
    radial_stretch_max: float      #: max hoop (fiber) stretch in the wall, cap excluded; the paper's lambda_2
    radial_stretch_q99: float      #: hoop stretch exceeded in 1 % of the wall's volume
    max_principal_stretch: float   #: max principal stretch over the quadrature points
    max_von_mises: float           #: max Cauchy von Mises stress [MPa]
    max_fiber_stress: float        #: max fiber stress k (lambda_f - 1) [MPa]
    iterations: int                #: Newton iterations of this pressure step
    y: np.ndarray = field(repr=False, default=None)  #: reduced unknowns (free u, q)

    @property
    def theta(self) -> float:
        """Total bend angle theta = sum theta_hat_i (3) [rad]."""
        return float(np.sum(self.q))


class FingerModel:
    """The built finger FEM: mesh, solid, shell constraint and pressure load."""

    def __init__(self, design: HandDesign, options: FingerOptions = FingerOptions()):
        self.design, self.options = design, options
        cap = options.cap if options.cap is not None else design.b
        self.tube = FingerTube(design.a, design.b, design.l0, cap, tie_bands(design, options),
                               options.edge_ratio, options.edge_reach)
        self.mesh = _mesh(self.tube, options)
        mu = design.mu_sf
        rubber = rubber_law(design.finger_rubber, options.kappa_ratio * mu)
        self.solid = Solid(self.mesh, rubber)
        if not np.all(self.solid.W > 0):
            raise InputError("mesh", _describe_mesh(options),
                             "has curved elements turned inside out (negative Jacobian); "
                             "try another mesh size, edge_ratio 1 (uniform) or the layered mesher")
        self.windings = Windings(self.mesh, options.fiber_ratio * mu, options.fiber_toe,
                                 options.fiber_intorder, self.solid.scatter)
        X_q = self.solid.sbasis.global_coordinates().value
        #: the windings at the rubber's quadrature points (stress outputs, VTK)
        self.fibers = WindingFibers(options.fiber_ratio * mu, hoop_directions(np.asarray(X_q)),
                                    options.fiber_toe)
        self.law = rubber + self.fibers
        self.cavity = _cavity(self.solid, self.mesh, options)
        #: elements of the tube wall (not the end cap): where the windings are
        self.wall = self.mesh.p[0, self.mesh.t[:4]].mean(axis=0) < design.l0 - cap
        self.chain = PlanarChain(np.c_[design.hinge_s, np.full(design.n_s, design.d)])
        self.constraint = self._tie()
        self.V0 = self.cavity.volume(np.zeros(self.solid.ndofs))

    def _tie(self) -> ChainConstraint:
        """Every node follows the link over its x position; the tie bands' nodes are tied."""
        basis = self.solid.sbasis
        X = basis.doflocs
        links = np.searchsorted(self.design.hinge_s, X[0], side="right")
        tied = np.zeros(basis.N, dtype=bool)
        for k in range(self.design.n_s + 1):
            band = basis.get_dofs(f"tie{k}").all()
            tied[band] = True
            links[band] = k
        fixed = np.concatenate((self.solid.dofs("base"), self.solid.dofs("symmetry", (2,))))
        nodes = 3 * np.arange(basis.N)[:, None] + np.arange(3)
        return ChainConstraint(self.chain, self.solid.ndofs, nodes, links, X[:2].T, tied, fixed)

    def energy(self, y) -> float:
        """Stored energy of the half model (rubber + windings) [N mm]."""
        u = self.constraint.expand(y)
        return self.solid.energy(u) + self.windings.energy(u)

    @property
    def ndofs(self) -> int:
        """Unknowns of the reduced system (free displacements + hinge angles)."""
        return self.constraint.n_reduced

    def displacement(self, y) -> np.ndarray:
        """The full displacement vector u = T(y)."""
        return self.constraint.expand(y)

    def residual_tangent(self, y, P: float, link_load=None):
        """Reduced residual and tangent at pressure P [MPa].

        ``link_load(q) -> (Q, dQdq)``: generalised external forces on the hinge angles
        [N mm] and their derivative (e.g. from :meth:`PlanarChain.point_load`).
        """
        u = self.constraint.expand(y)
        R, data = self.solid.residual_tangent_data(u)
        self.windings.add_residual_tangent(u, R, data)
        R = R - P * self.cavity.gradient(u)
        K = self.solid.scatter.csr(data - P * self.cavity.hessian_data(u))
        Q, dQ = (None, None) if link_load is None else link_load(self.constraint.q(y))
        r, Kr = self.constraint.reduce(y, R, K, None if dQ is None else -np.asarray(dQ))
        if Q is not None:
            r[len(self.constraint.free):] -= Q
        return r, Kr

    def residual(self, y, P: float, link_load=None) -> np.ndarray:
        """The reduced residual of :meth:`residual_tangent` alone (a line search's trial points)."""
        u = self.constraint.expand(y)
        R = self.solid.residual(u)
        self.windings.add_residual(u, R)
        r = self.constraint.reduce(y, R - P * self.cavity.gradient(u))
        if link_load is not None:
            r[len(self.constraint.free):] -= link_load(self.constraint.q(y))[0]
        return r

    def state(self, y, P: float, iterations: int = 0) -> FingerState:
        """Outputs of the converged reduced state y at pressure P."""
        u = self.constraint.expand(y)
        F = self.solid.F(u)
        eig = np.linalg.eigvalsh(np.moveaxis(kin.right_cauchy_green(F), (0, 1), (-2, -1)))
        P1 = self.solid.first_piola(u) + self.fibers.stress(F)
        sigma = np.einsum("aK...,bK...->ab...", P1, F) / kin.det(F)
        dev = sigma - np.einsum("aa...->...", sigma) / 3.0 * kin.identity(sigma.shape[2:])
        lam_f = self.windings.stretch(u)[1][self.wall]  # the cap's "hoop" near the axis is no winding
        order = np.argsort(lam_f, axis=None)
        share = np.cumsum(self.windings.W[self.wall].ravel()[order])
        return FingerState(
            P=float(P), q=np.array(self.constraint.q(y)),
            dQ=2.0 * (self.cavity.volume(u) - self.V0),
            radial_stretch_max=float(lam_f.max()),
            radial_stretch_q99=float(lam_f.ravel()[order][np.searchsorted(share, 0.99 * share[-1])]),
            max_principal_stretch=float(np.sqrt(eig.max())),
            max_von_mises=float(np.sqrt(1.5 * np.einsum("ab...,ab...->...", dev, dev)).max()),
            max_fiber_stress=float(self.fibers.k * np.clip(lam_f - 1.0, 0.0, None).max()),
            iterations=int(iterations), y=np.array(y))

    def link_poses(self, y) -> tuple[np.ndarray, np.ndarray]:
        """Link poses in the finger frame: origins c_k (n_s+1, 2) [mm], angles phi_k [rad]."""
        return self.chain.link_poses(self.constraint.q(y))

    def vector_basis(self) -> Basis:
        """The vector P2 basis of the displacement (for VTK output)."""
        return Basis(self.mesh, ElementVector(ElementTetP2()), intorder=2)

    def element_dilatation(self, y) -> np.ndarray:
        """Mean dilatation J_bar per element (for the VTK stress of :mod:`fem.io`)."""
        u = self.constraint.expand(y)
        W = self.solid.W
        return (W * kin.det(self.solid.F(u))).sum(axis=1) / W.sum(axis=1)


def _mesh(tube: FingerTube, options: FingerOptions):
    if options.mesher == "layered":
        return layered_tube_mesh(tube, n_phi=options.n_phi, layer_first=options.layer_first,
                                 layer_ratio=options.layer_ratio, axial_size=options.axial_size,
                                 refine=options.mesh_refine)
    return finger_tube_mesh(tube, size=options.mesh_size, refine=options.mesh_refine)


def _describe_mesh(options: FingerOptions) -> str:
    if options.mesher == "layered":
        return (f"layered n_phi={options.n_phi} layer_first={options.layer_first} "
                f"layer_ratio={options.layer_ratio} axial_size={options.axial_size} refine={options.mesh_refine}")
    return (f"gmsh mesh_size={options.mesh_size} edge_ratio={options.edge_ratio} "
            f"refine={options.mesh_refine}")


def _cavity(solid, mesh, options: FingerOptions) -> CavityVolume:
    """The cavity volume load; a curved facet whose element map cannot be inverted (a badly
    distorted element that still has a positive Jacobian at the quadrature points) becomes
    one clear line instead of a traceback."""
    try:
        return CavityVolume(solid, mesh.boundaries["cavity"], symmetry_normal=0)
    except RuntimeError as err:  # fem.mapping.RobustIsoparametric.invF
        if "inverse isoparametric map" not in str(err):
            raise
        raise InputError("mesh", _describe_mesh(options),
                         "has a curved element too distorted to map; try another mesh size, "
                         "edge_ratio 1 (uniform) or the layered mesher") from None


@dataclass(frozen=True)
class SweepStats:
    """Cost of a pressure sweep."""

    wall_seconds: float
    assembly_seconds: float
    solve_seconds: float
    newton_iterations: int
    cutbacks: int
    solver: str
    factorizations: int = 0  #: tangents factorised (fewer than iterations with refactor="adaptive")


def solve_pressures(model: FingerModel, pressures, *, link_load=None, y0=None, callback=None,
                    newton_options: NewtonOptions = NewtonOptions(rtol=1e-9)):
    """Follow increasing pressures [MPa] from the state y0 (default: unloaded, P = 0).

    Each pressure is one load step of :func:`fem.newton.solve_path` from the last converged
    state, cut back (halved) when Newton fails. Returns
    ([FingerState], SweepStats); raises :class:`fem.newton.NotConverged` with the last
    converged state when even the cut-back fails.
    """
    # double precision: single-precision PARDISO plus refinement gains only ~0.06-0.16 per
    # refinement step on the finger (fibers 1000 mu stiffer than the rubber), so "mixed" always
    # fell back after one wasted factorisation (fem.linsolve)
    solver = make_solver(symmetric=True, precision="double")
    t0 = time.perf_counter()
    history = [(0.0, model.constraint.zero() if y0 is None else np.array(y0, dtype=float))]
    states, totals = [], np.zeros(5)  # assembly s, solve s, iterations, cutbacks, factorisations
    scale = model.design.mu_sf * model.design.a ** 2 * model.design.l0  # [N] residual scale
    for P in (float(p) for p in pressures):
        y, its = _solve_one(model, P, history, link_load, solver, newton_options, scale, totals)
        if P != history[-1][0]:
            history.append((P, y))
        states.append(model.state(y, P, its))
        if callback is not None:
            callback(states[-1])
    stats = SweepStats(time.perf_counter() - t0, totals[0], totals[1], int(totals[2]),
                       int(totals[3]), solver.describe(), int(totals[4]))
    return states, stats


def _solve_one(model, P, history, link_load, solver, options, scale, totals):
    """The state at P from the last converged (P_i, y_i); updates totals in place.

    One load step from the last state with the tangent predictor of
    :func:`fem.newton.solve_path` (a secant predictor from the last two states made the
    chattering tension-only fibers fail more often than it saved iterations).
    """
    P1, y1 = history[-1]
    try:
        path = solve_path(lambda y, t: model.residual_tangent(y, P1 + t * (P - P1), link_load), y1,
                          PathOptions(steps=1, newton=options), solver=solver, scale_t=lambda t: scale,
                          residual_t=lambda y, t: model.residual(y, P1 + t * (P - P1), link_load))
    except NotConverged as exc:  # named by the pressures, not the step's load fraction
        t, y = exc.last_converged if exc.last_converged is not None else (0.0, y1)
        reached = P1 + t * (P - P1)
        error = NotConverged(f"Newton did not converge above P = {reached:.6g} MPa on the way to "
                             f"{P:.6g} MPa", exc.history, exc.x, last_converged=(reached, y))
        error.pressure = reached  #: the last converged pressure [MPa]
        raise error from None
    totals += (path.assembly_seconds, path.solve_seconds, path.total_iterations, path.cutbacks,
               path.factorizations)
    return path.x[-1], path.total_iterations

r"""The finger FEM: a fiber-reinforced rubber tube held by a hinged rigid shell, under pressure.

Model (the paper's section II-B, with the choices the paper leaves open made explicit):

* the NBR tube of :mod:`softhand.meshes.finger` (inner radius a, wall b, length l0 with an end cap
  of thickness ``cap`` at the tip), half model on the bending plane z = 0;
* nearly incompressible Neo-Hookean rubber (mu_sf, kappa = ``kappa_ratio`` mu) in the
  mean-dilatation P2-P0 formulation of :mod:`softhand.fem.solid`, plus a tension-only fiber family
  (the Kevlar windings) along the hoop direction e_phi = (0, -z, y)/r, stiffness
  ``fiber_ratio`` mu, everywhere in the wall (the cap too). The windings' energy is
  integrated with its own rule (:class:`~softhand.fem.hand.windings.Windings`, degree ``fiber_intorder``, default the
  14-point degree-5 rule whose points include the edge midpoints): the 4-point rule of the
  rubber samples the tension-only switch only inside the elements and misses the taut
  layer at the cavity wall, which made theta converge from above, non-monotonically, with
  the number of elements through the wall (docs/finger.md, mesh convergence);
* oil pressure P on the cavity: the closed-cavity load P dV/du with its symmetric load
  stiffness P d2V/du2, V the cavity volume of :class:`softhand.fem.loads.CavityVolume` (closed by
  the symmetry plane z = 0 and the fixed inlet plane x = 0);
* the shell: a :class:`softhand.fem.constraints.PlanarChain` with hinges at (``hinge_s``, d) in the
  finger frame (the hinge plate at y = +d), link 0 fixed; the tube's base face is clamped
  to link 0 and the outer-surface band ``tie<k>`` moves rigidly with link k
  (:class:`softhand.fem.constraints.ChainConstraint`);
* unknowns y = (free displacements, hinge angles q); theta = sum(q); the hand's base
  inclination theta0_hat only rotates the result (:func:`~softhand.fem.hand.frame.to_hand_frame`).

Which part of the outer surface the shell holds is a modelling choice
(:class:`~softhand.fem.hand.finger_options.FingerOptions` ``tie``): ``"ring"`` ties a band of width ``tie_width`` in the
middle of each link (the shell clamps the tube at rings and lets it bend between
them), ``"full"`` ties each link's whole length except ``hinge_gap`` around each hinge
(a closed shell that lets the tube deform only at the hinges). docs/finger.md compares
them.

Generalised forces on the links (contact with an object, its weight) are passed to
:meth:`FingerModel.residual_tangent` as ``link_load(q) -> (Q, dQ/dq)``; see
:meth:`softhand.fem.constraints.PlanarChain.point_load`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from skfem import Basis, ElementTetP2, ElementVector

from softhand.fem import kinematics as kin
from softhand.fem.compiled import rubber as compiled_kernels
from softhand.fem.constraints import ChainConstraint, PlanarChain
from softhand.fem.hand.finger_options import (FingerOptions, build_mesh, check_size, describe_mesh, finger_tube,
                                              refuse_folds, ring_width, tie_bands)
from softhand.fem.hand.finger_sweep import SweepStats, solve_pressures
from softhand.fem.hand.frame import to_hand_frame
from softhand.fem.hand.windings import Windings, WindingFibers, hoop_directions
from softhand.fem.hyperelastic import rubber_law
from softhand.fem.loads import CavityVolume
from softhand.fem.rubber_stretch import Averager, peaks_at_radii
from softhand.fem.solid import Solid
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import MeshRejected

__all__ = ["FingerModel", "FingerOptions", "FingerState", "SweepStats", "WindingFibers",
           "ring_width", "solve_pressures", "tie_bands", "to_hand_frame"]


@dataclass
class FingerState:
    """One converged state of the finger (finger frame, mm, MPa, rad)."""

    P: float                       #: cavity pressure [MPa]
    q: np.ndarray                  #: hinge angles theta_hat_i [rad]
    dQ: float                      #: cavity volume change of the whole finger [mm^3]
    radial_stretch_max: float      #: max hoop (fiber) stretch in the wall, cap excluded; the paper's lambda_2
    radial_stretch_q99: float      #: hoop stretch exceeded in 1 % of the wall's volume
    #: the windings' hoop stretch averaged over the wall as rubber_stretch (fem.rubber_stretch)
    radial_stretch: float
    #: max principal stretch over the quadrature points: the bonded rings' corner peak,
    #: mesh-dependent (it grows without limit as the mesh is refined)
    max_principal_stretch: float
    #: the converged rubber stretch: the principal stretch averaged over a ball of radius
    #: fem.rubber_stretch.RADIUS_MM, at its worst place (fem.rubber_stretch)
    rubber_stretch: float
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
        self.tube = finger_tube(design, options)
        check_size(self.tube, options)
        self.mesh = build_mesh(self.tube, options)
        mu = design.mu_sf
        rubber = rubber_law(design.finger_rubber, options.kappa_ratio * mu)
        self.solid = Solid(self.mesh, rubber)
        if not np.all(self.solid.W > 0):
            raise MeshRejected(describe_mesh(options),
                               "has curved elements turned inside out (negative Jacobian); "
                               "try another mesh size, edge_ratio 1 (uniform) or the layered mesher")
        refuse_folds(self.mesh, options)
        self.windings = Windings(self.mesh, options.fiber_ratio * mu, options.fiber_toe,
                                 options.fiber_intorder, self.solid.scatter)
        X_q = self.solid.sbasis.global_coordinates().value
        #: the windings at the rubber's quadrature points (stress outputs, VTK)
        self.fibers = WindingFibers(options.fiber_ratio * mu, hoop_directions(np.asarray(X_q)),
                                    options.fiber_toe)
        self.law = rubber + self.fibers
        self._X_q = np.asarray(X_q)
        self.cavity = _cavity(self.solid, self.mesh, options)
        #: elements of the tube wall (not the end cap): where the windings are
        self.wall = self.mesh.p[0, self.mesh.t[:4]].mean(axis=0) < design.l0 - self.tube.cap
        self.chain = PlanarChain(np.c_[design.hinge_s, np.full(design.n_s, design.d)])
        self.constraint = self._tie()
        self.V0 = self.cavity.volume(np.zeros(self.solid.ndofs))
        #: the rubber and windings by the compiled kernel, or None: the NumPy kernels (fem.compiled)
        self.kernels = compiled_kernels.for_finger(self.solid, self.windings)

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
        [N mm] and their derivative (e.g. from :meth:`~softhand.fem.constraints.PlanarChain.point_load`).
        """
        u = self.constraint.expand(y)
        if self.kernels is not None:  # rubber + windings: one compiled pass, scattered as it goes
            R, data = self.kernels.residual_tangent_data(u, self.solid)
        else:  # rubber + windings: one kernel pass, one product, one scatter
            R, Ke = self.solid.residual_element_matrices(u, extra=lambda c: self.windings.terms(u, c))
            data = self.solid.scatter.block_matrix_data(Ke)
        R = R - P * self.cavity.gradient(u, data, -P)  # and the cavity's load stiffness into data
        K = self.solid.scatter.csr(data)
        Q, dQ = (None, None) if link_load is None else link_load(self.constraint.q(y))
        r, Kr = self.constraint.reduce(y, R, K, None if dQ is None else -np.asarray(dQ), symmetric=True)
        if Q is not None:
            r[len(self.constraint.free):] -= Q
        return r, Kr

    def residual(self, y, P: float, link_load=None) -> np.ndarray:
        """The reduced residual of :meth:`residual_tangent` alone (a line search's trial points)."""
        u = self.constraint.expand(y)
        if self.kernels is not None:
            R = self.kernels.residual(u, self.solid)
        else:
            R = self.solid.residual(u)
            self.windings.add_residual(u, R)
        r = self.constraint.reduce(y, R - P * self.cavity.gradient(u))
        if link_load is not None:
            r[len(self.constraint.free):] -= link_load(self.constraint.q(y))[0]
        return r

    def dQ(self, y) -> float:
        """Cavity volume change of the whole finger [mm^3] at the reduced state y."""
        return self._dQ(self.constraint.expand(y))

    def _dQ(self, u) -> float:
        return 2.0 * (self.cavity.volume(u) - self.V0)  # the half model's cavity, twice

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
            dQ=self._dQ(u),
            radial_stretch_max=float(lam_f.max()),
            radial_stretch_q99=float(lam_f.ravel()[order][np.searchsorted(share, 0.99 * share[-1])]),
            radial_stretch=self.wall_averager.peak(self.fibers.take(self.wall).stretch(F[:, :, self.wall]))[0],
            max_principal_stretch=float(np.sqrt(eig.max())),
            rubber_stretch=self.averager.peak(np.sqrt(eig[..., -1]))[0],
            max_von_mises=float(np.sqrt(1.5 * np.einsum("ab...,ab...->...", dev, dev)).max()),
            max_fiber_stress=float(self.fibers.k * np.clip(lam_f - 1.0, 0.0, None).max()),
            iterations=int(iterations), y=np.array(y))

    def link_poses(self, y) -> tuple[np.ndarray, np.ndarray]:
        """Link poses in the finger frame: origins c_k (n_s+1, 2) [mm], angles phi_k [rad]."""
        return self.chain.link_poses(self.constraint.q(y))

    @cached_property
    def averager(self) -> Averager:
        """Ball averages over the rubber's quadrature points, both halves (fem.rubber_stretch)."""
        return Averager(self._X_q.reshape(3, -1).T, self.solid.W, mirror=2)

    @cached_property
    def wall_averager(self) -> Averager:
        """Ball averages over the rubber's quadrature points of the wall (the windings), both halves."""
        return self.averager.subset(np.repeat(self.wall, self.solid.W.shape[1]))

    def principal_stretch(self, y) -> np.ndarray:
        """The largest principal stretch at the rubber's quadrature points (nel, nq) [-]."""
        C = kin.right_cauchy_green(self.solid.F(self.constraint.expand(y)))
        return np.sqrt(np.linalg.eigvalsh(np.moveaxis(C, (0, 1), (-2, -1)))[..., -1])

    def rubber_stretches(self, ys, radii) -> np.ndarray:
        """The converged rubber stretch of each state ``ys`` with the averaging ball's radius each
        of ``radii`` [mm], (len(ys), len(radii)): the calibration's record of how the measure
        depends on the finger's size (the radius is the rubber's, so a/rho is a group)."""
        return peaks_at_radii(self._X_q.reshape(3, -1).T, self.solid.W,
                              [self.principal_stretch(y) for y in ys], radii, mirror=2)

    def rubber_stretch_field(self, y) -> np.ndarray:
        """The ball-averaged principal stretch at every quadrature point (nel, nq) [-]."""
        lam = self.principal_stretch(y)
        return self.averager.at(lam.ravel()).reshape(lam.shape)

    def vector_basis(self) -> Basis:
        """The vector P2 basis of the displacement (for VTK output)."""
        return Basis(self.mesh, ElementVector(ElementTetP2()), intorder=2)

    def element_dilatation(self, y) -> np.ndarray:
        """Mean dilatation J_bar per element (for the VTK stress of :mod:`softhand.fem.io`)."""
        u = self.constraint.expand(y)
        W = self.solid.W
        return (W * kin.det(self.solid.F(u))).sum(axis=1) / W.sum(axis=1)



def _cavity(solid, mesh, options: FingerOptions) -> CavityVolume:
    """The cavity volume load; a curved facet whose element map cannot be inverted (a badly
    distorted element that still has a positive Jacobian at the quadrature points) becomes
    one clear line instead of a traceback."""
    try:
        return CavityVolume(solid, mesh.boundaries["cavity"], symmetry_normal=0)
    except RuntimeError as err:  # fem.mapping.RobustIsoparametric.invF
        if "inverse isoparametric map" not in str(err):
            raise
        raise MeshRejected(describe_mesh(options),
                           "has a curved element too distorted to map; try another mesh size, "
                           "edge_ratio 1 (uniform) or the layered mesher") from None


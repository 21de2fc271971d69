r"""The reservoir sheet FEM: a clamped circular NBR sheet inflated by a prescribed oil volume.

Model (axisymmetric, :mod:`softhand.fem.axisym`): the sheet 0 <= r <= R, 0 <= z <= t, nearly
incompressible Neo-Hookean (μ = μ_sr, κ = 1000 μ by default), clamped over its rim face
r = R (u = 0), u_r = 0 on the axis. Oil fills the space between the clamp plane z = 0 and
the wet underside; its volume V (measured from the clamp plane, :class:`~softhand.fem.axisym.RevolvedVolume`)
is prescribed and the oil pressure p is the Lagrange multiplier (:mod:`softhand.fem.volume_path`).

Starting from flat. A *membrane* has no stiffness against a transverse load when flat,
so a membrane solver must start from a pre-deflection. This model is a solid: the flat
sheet has its plate bending stiffness (D = μ t³/3 for an incompressible sheet), and the
bordered volume-control matrix is regular at u = 0. The path therefore starts at u = 0,
V = 0 with a small first volume step (default 1 mm³, a plate deflection of about 0.005 t),
passes through the plate regime (p ∝ V) into the membrane regime, and the step grows
geometrically up to ``max_step``. Decreasing volumes (oil leaving for the fingers) are the
same elastic states, so one increasing sweep covers the range down to the smallest volume.

Outputs per volume: pressure, apex height (of the wet surface, on the axis), the deformed
wet-surface profile z(r), the mid-surface stretches (meridional, hoop, thickness), the
strain energy W(V); along the whole path p(V), W(V) and the pressure maximum if the path
passes one.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from softhand.fem.axisym import AxisymSolid, RevolvedVolume
from softhand.fem.hyperelastic import rubber_law
from softhand.fem.rubber_stretch import RADIUS_MM, Averager, peaks_at_radii
from softhand.reduced.materials.rubber import NeoHookean
from softhand.reduced.materials.rubber_base import Rubber
from softhand.fem.volume_path import PathOptions, follow_volume, volume_path_options
from softhand.meshes.reservoir import sheet_mesh

__all__ = ["SheetModel", "SheetState", "ReservoirResult", "inflate", "rubber_stretches", "pressure_maximum", "sheet_vtk"]


@dataclass(frozen=True)
class SheetModel:
    """The clamped sheet and its discretisation."""

    R: float = 24.0  #: sheet radius, clamp to axis [mm]
    t: float = 1.0  #: sheet thickness [mm]
    mu: float = 1.15  #: initial shear modulus μ_sr [MPa]
    kappa_ratio: float = 1000.0  #: bulk modulus / μ [-]
    n_radial: int = 40  #: Q2 elements along the radius
    n_thick: int = 2  #: Q2 elements through the thickness
    clamp_ratio: float = 3.0  #: radial element size at the axis / at the clamp
    #: the rubber's strain energy (:mod:`softhand.reduced.materials.rubber`; scaled to mu); None: Neo-Hookean
    material: Rubber | None = None

    @classmethod
    def from_design(cls, design, **mesh) -> "SheetModel":
        """Geometry and material of a :class:`softhand.reduced.vocabulary.design.HandDesign`; mesh keywords as given."""
        material = None if design.reservoir_is_neo_hookean else design.reservoir_rubber
        return cls(R=design.R, t=design.t, mu=design.mu_sr, material=material, **mesh)

    @property
    def rubber(self) -> Rubber:
        """The sheet's strain energy with initial shear modulus mu."""
        m = self.material
        return NeoHookean(self.mu) if m is None else m.scaled(self.mu / m.mu0)

    def build(self):
        """(solid, volume functional, fixed DOFs)."""
        mesh = sheet_mesh(self.R, self.t, n_radial=self.n_radial, n_thick=self.n_thick,
                          clamp_ratio=self.clamp_ratio)
        solid = AxisymSolid(mesh, rubber_law(self.rubber, self.kappa_ratio * self.mu))
        volume = RevolvedVolume(solid, mesh.boundaries["wet"])
        b = solid.basis
        fixed = np.concatenate([b.get_dofs("clamp").all(), b.get_dofs("axis").all("u^1")])
        return solid, volume, fixed


@dataclass(frozen=True)
class SheetState:
    """The deformed sheet at one volume."""

    volume: float  #: oil volume from the clamp plane [mm^3]
    pressure: float  #: oil gauge pressure [MPa]
    energy: float  #: strain energy W [N mm]
    apex: float  #: height of the wet surface on the axis [mm]
    r: np.ndarray = field(repr=False)  #: deformed wet-surface radii, axis to clamp [mm]
    z: np.ndarray = field(repr=False)  #: deformed wet-surface heights [mm]
    r0_mid: np.ndarray = field(repr=False)  #: reference radii of the mid-surface nodes [mm]
    lambda_meridian: np.ndarray = field(repr=False)  #: mid-surface meridional stretch [-]
    lambda_hoop: np.ndarray = field(repr=False)  #: mid-surface hoop stretch [-]
    u: np.ndarray = field(repr=False)  #: displacement vector [mm]
    #: largest principal stretch at any quadrature point: at the clamp's corner, mesh-dependent
    max_principal_stretch: float = float("nan")
    #: the converged rubber stretch: the principal stretch averaged over a ring of radius
    #: fem.rubber_stretch.RADIUS_MM around its worst place (fem.rubber_stretch)
    rubber_stretch: float = float("nan")

    @property
    def lambda_thickness(self):
        """Thickness stretch 1 / (λ_m λ_θ) of the (incompressible) mid-surface [-]."""
        return 1.0 / (self.lambda_meridian * self.lambda_hoop)

    @property
    def mean_stretch(self) -> float:
        """Meridian arc of the mid-surface / R: the FEM's counterpart of eq. (16) [-]."""
        dr0 = np.diff(self.r0_mid)
        return float(np.sum(0.5 * (self.lambda_meridian[1:] + self.lambda_meridian[:-1]) * dr0)
                     / self.r0_mid[-1])

    def profile_at(self, r):
        """Wet-surface height z [mm] at radii r [mm] (profile interpolated, a graph z(r))."""
        return np.interp(r, self.r, self.z)


@dataclass(frozen=True)
class ReservoirResult:
    """States at the requested volumes, the whole path, and run statistics."""

    model: SheetModel
    states: tuple  #: SheetState per requested volume
    path_volume: np.ndarray = field(repr=False)  #: every converged V [mm^3], from 0
    path_pressure: np.ndarray = field(repr=False)  #: p along the path [MPa]
    path_energy: np.ndarray = field(repr=False)  #: W along the path [N mm]
    pressure_max: tuple | None  #: (V [mm^3], p [MPa]) at the pressure maximum, or None
    ndofs: int
    newton_iterations: int
    wall_time: float  #: [s]


def surface_nodes(solid, u, z0):
    """(r0, r, z) [mm] of the nodes of the reference surface z = z0, sorted by r0: reference
    radius, current radius and current height."""
    b = solid.basis
    rdofs, zdofs = np.arange(0, b.N, 2), np.arange(1, b.N, 2)
    X = b.doflocs
    on = np.flatnonzero(np.isclose(X[1, rdofs], z0, atol=1e-9 * solid.mesh.p.max()))
    on = on[np.argsort(X[0, rdofs[on]])]
    r0 = X[0, rdofs[on]]
    return r0, r0 + u[rdofs[on]], X[1, zdofs[on]] + u[zdofs[on]]


def sheet_state(model: SheetModel, solid, s, averager=None) -> SheetState:
    """The sheet at the path state ``s`` (volume, pressure, energy, u): its profile and stretches."""
    _, r, z = surface_nodes(solid, s.u, 0.0)
    r0m, rm, zm = surface_nodes(solid, s.u, model.t / 2)
    arc = np.hypot(np.gradient(rm, r0m), np.gradient(zm, r0m))
    hoop = np.where(r0m > 0, rm / np.where(r0m > 0, r0m, 1.0), arc)
    hoop[0] = arc[0]  # on the axis the hoop stretch equals the meridional one
    lam = principal_stretch(solid, s.u)
    averager = sheet_averager(solid) if averager is None else averager
    return SheetState(s.volume, s.pressure, s.energy, float(z[0]), r, z, r0m, arc, hoop, s.u,
                      float(lam.max()), averager.peak(lam)[0])


def principal_stretch(solid, u) -> np.ndarray:
    """The largest principal stretch at the quadrature points (nel, nqp) [-]."""
    return np.maximum(*solid.stretches(u)[::2])


def sheet_averager(solid, radius: float = RADIUS_MM) -> Averager:
    """Averages over the sheet's r-z quadrature points weighted by their ring volumes (a ball's
    average of an axisymmetric field becomes one over a ring of the same radius), mirrored in the axis."""
    return Averager(_quadrature_points(solid), solid.wdV, radius, mirror=0)


def _quadrature_points(solid) -> np.ndarray:
    """The sheet's r-z quadrature points (N, 2) [mm]."""
    return np.asarray(solid.basis.mapping.F(solid.basis.X)).reshape(2, -1).T


def rubber_stretches(model: SheetModel, states, radii) -> np.ndarray:
    """The converged rubber stretch of each of the sheet's ``states`` with the averaging ball's
    radius each of ``radii`` [mm], (len(states), len(radii)): the calibration's record of how the
    measure depends on the sheet's size (the radius is the rubber's, so R/rho is a group)."""
    solid = model.build()[0]
    return peaks_at_radii(_quadrature_points(solid), solid.wdV, [principal_stretch(solid, s.u) for s in states],
                          radii, mirror=0)


def pressure_maximum(V, p):
    """(V, p) at an interior maximum of the sampled p(V) (parabola through 3 points), or None."""
    k = int(np.argmax(p))
    if k == 0 or k == len(p) - 1:
        return None
    c = np.polyfit(V[k - 1:k + 2], p[k - 1:k + 2], 2)
    vm = -c[1] / (2 * c[0])
    return float(vm), float(np.polyval(c, vm))


def inflate(model: SheetModel, volumes, *, options: PathOptions | None = None,
            progress=None) -> ReservoirResult:
    """Inflate the sheet from flat through the oil volumes ``volumes`` [mm^3] (any order, > 0)."""
    start = time.perf_counter()
    volumes = np.asarray(volumes, dtype=float)
    order = np.argsort(volumes)
    targets, inverse = np.unique(volumes[order], return_inverse=True)
    solid, volume, fixed = model.build()
    # round-off floor of the internal forces: the volumetric stresses are O(κ) and cancel
    atol = 1e-12 * model.kappa_ratio * model.mu * model.R * model.t
    options = options or volume_path_options(max_step=0.5 * model.R**2 * model.t, atol=atol)
    hits, path = follow_volume(solid, volume, fixed, targets, options=options,
                               volume_scale=model.R**2 * model.t, progress=progress)
    averager = sheet_averager(solid)
    states = [sheet_state(model, solid, s, averager) for s in hits]
    by_request = np.empty(volumes.size, dtype=object)
    by_request[order] = [states[i] for i in inverse]
    V = np.array([s.volume for s in path])
    p = np.array([s.pressure for s in path])
    return ReservoirResult(
        model=model, states=tuple(by_request), path_volume=V, path_pressure=p,
        path_energy=np.array([s.energy for s in path]), pressure_max=pressure_maximum(V, p),
        ndofs=solid.ndofs, newton_iterations=sum(s.iterations for s in path),
        wall_time=time.perf_counter() - start)


def sheet_vtk(solid, state: SheetState):
    """The r–z section of a deformed sheet (points, cells, point_data) on its Q2 mesh
    (``quad9``): reference points (r, z, 0) with the ``displacement_mm`` (u_r, u_z, 0) and
    the ``hoop_stretch`` (Warp By Vector shows it). The sheet revolved in 3D is
    :func:`softhand.fem.hand.scene.sheet_block`."""
    from skfem import Basis, ElementQuad2

    scalar = Basis(solid.mesh, ElementQuad2())
    X = scalar.doflocs
    u = state.u.reshape(-1, 2).T  # interleaved (u_r, u_z) per scalar DOF
    hoop = np.where(X[0] > 0, (X[0] + u[0]) / np.where(X[0] > 0, X[0], 1.0), np.nan)
    hoop[np.isnan(hoop)] = state.lambda_hoop[0]
    return (np.c_[X.T, np.zeros(X.shape[1])], {"quad9": scalar.element_dofs.T},
            {"displacement_mm": np.c_[u.T, np.zeros(X.shape[1])], "hoop_stretch": hoop})

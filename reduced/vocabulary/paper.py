"""The paper's data, in one place: Table I (the design), the weight vectors w (section III-C),
Fig. 7's reservoir offset, the Fig. 8 grasps and Table II.

Everything a study compares with the paper is read from here; numbers are exactly as
printed (the 180 mm weight vector sums to 1.40, violating eq. (23); see
:func:`softhand.reduced.equations.grasp.check_weights`).
"""
from __future__ import annotations

from typing import NamedTuple

from softhand.reduced.vocabulary.design import PAPER_DESIGN_FILE, HandDesign

#: Table I is stored once, as :class:`~softhand.reduced.vocabulary.design.HandDesign`'s defaults (each field says
#: where the paper is silent); this TOML file spells the same design out for users, and a test
#: keeps the two equal
TABLE_I_FILE = PAPER_DESIGN_FILE

#: the paper's weight vectors w by object diameter [mm], exactly as printed
WEIGHTS = {
    180.0: (-0.13, 0.0, 0.67, 0.33, 0.53),
    240.0: (-0.2, 0.0, 0.1, 0.3, 0.8),
}

#: Fig. 7: "bent at 0.1 MPa lower pressure" with the reservoir [MPa]
RESERVOIR_OFFSET_MPA = 0.1

#: Table II: state -> (P [MPa], theta [deg], F_v [kgf])
TABLE_II = {
    "a_no_push": (0.89, 50.0, 0.61),
    "b_push_pressure_control": (0.89, 45.0, 0.82),
    "c_push_angle_control": (0.79, 45.0, 0.53),
}


class Grasp(NamedTuple):
    """One object of Fig. 8: what the paper grasped, at which pump pressures, and how well
    its model estimated the measured force."""

    diameter_mm: float               #: object diameter [mm]
    mass_kg: float                   #: object mass [kg]
    pressures_mpa: tuple[float, ...]  #: the pump pressures of Fig. 8 [MPa]
    weights_at_mpa: float            #: a pressure inside that range, where a FEM w is taken [MPa]
    error_kgf: float                 #: the paper's F_v estimation error against its measurement [kgf]


#: the two objects of Fig. 8
FIG8 = (Grasp(180.0, 2.0, (0.6, 0.7, 0.8, 0.9), 0.8, 0.22),
        Grasp(240.0, 6.0, (1.1, 1.2, 1.3, 1.4), 1.2, 0.39))


def table_i() -> HandDesign:
    """The paper's hand (Table I, with documented defaults where the paper is silent)."""
    return HandDesign()

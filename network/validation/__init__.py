"""Validation: reference permeabilities and the cases that run the one pipeline against them."""

from ._drag_laws import DRAG_LAWS, beetstra_drag, drag_ratio, hill_koch_ladd_drag
from ._inertial_cases import (FINNEY_PATH, InertialCase, bed_inertial_case, finney_inertial_case,
                              lattice_inertial_case, periodic_inertial_case, random_inertial_case,
                              solve_sample_curve)
from ._cases import ESTIMATORS, lattice_sample_permeability, random_sample_permeability
from ._periodic import periodic_permeability
from ._references import (STOKES_CELL_BCC, STOKES_CELL_FCC, ZICK_HOMSY_SC, beetstra_permeability,
                          beetstra_stokes_drag, computed_lattice_permeability,
                          drag_to_permeability, ergun_viscous_permeability,
                          kozeny_carman_permeability, lattice_permeability,
                          sangani_acrivos_sc_drag, zick_homsy_sc_drag)

__all__ = ["DRAG_LAWS", "ESTIMATORS", "FINNEY_PATH", "InertialCase",
           "STOKES_CELL_BCC", "STOKES_CELL_FCC", "ZICK_HOMSY_SC", "beetstra_drag",
           "beetstra_permeability", "beetstra_stokes_drag", "computed_lattice_permeability",
           "drag_ratio", "drag_to_permeability", "ergun_viscous_permeability",
           "bed_inertial_case", "finney_inertial_case",
           "hill_koch_ladd_drag", "kozeny_carman_permeability", "lattice_inertial_case",
           "lattice_permeability", "lattice_sample_permeability", "periodic_inertial_case",
           "periodic_permeability",
           "random_inertial_case", "random_sample_permeability",
           "sangani_acrivos_sc_drag", "solve_sample_curve", "zick_homsy_sc_drag"]

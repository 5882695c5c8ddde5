"""Validation: reference permeabilities and the cases that run the one pipeline against them."""

from ._cases import ESTIMATORS, lattice_sample_permeability, random_sample_permeability
from ._references import (STOKES_CELL_BCC, STOKES_CELL_FCC, ZICK_HOMSY_SC, beetstra_permeability,
                          beetstra_stokes_drag, computed_lattice_permeability,
                          drag_to_permeability, ergun_viscous_permeability,
                          kozeny_carman_permeability, lattice_permeability,
                          sangani_acrivos_sc_drag, zick_homsy_sc_drag)

__all__ = ["ESTIMATORS", "STOKES_CELL_BCC", "STOKES_CELL_FCC", "ZICK_HOMSY_SC",
           "beetstra_permeability", "beetstra_stokes_drag", "computed_lattice_permeability",
           "drag_to_permeability", "ergun_viscous_permeability", "kozeny_carman_permeability",
           "lattice_permeability", "lattice_sample_permeability", "random_sample_permeability",
           "sangani_acrivos_sc_drag", "zick_homsy_sc_drag"]

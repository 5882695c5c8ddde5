"""``network.bin``: steady Darcy-Forchheimer airflow through a grain bin, solved with scikit-fem.

The bin (:mod:`._geometry`: round, flat / peaked / inverted-cone top, full floor or floor
ducts; r-z or 3-D gmsh mesh), the bulk's law (:mod:`._law`: tensor Darcy-Forchheimer or D272's
Shedd form, inverted in closed form), its material from the network's porosity band
(:mod:`._material`), the Newton solve and its fluxes (:mod:`._solve`), the system curve and fan
(:mod:`._system`) and what an engineer reads (:mod:`._outputs`). The command is
``python -m network.bin`` (docs/bin.md). gmsh and scikit-fem are imported inside the functions
that use them.
"""

from ._geometry import BinGeometry, Duct, Mesh, mesh_bin, mesh_rz_polygon
from ._law import ForchheimerLaw, SheddLaw, closed_form_radial_airflow
from ._material import Material, PorosityProfile, d272_material, network_material
from ._solve import BinProblem, NewtonFailure, Solution

__all__ = ["BinGeometry", "Duct", "Mesh", "mesh_bin", "mesh_rz_polygon", "ForchheimerLaw",
           "SheddLaw", "closed_form_radial_airflow", "Material", "PorosityProfile",
           "network_material", "d272_material", "BinProblem", "NewtonFailure", "Solution"]

"""grainflow.network: Delaunay pore network of a sphere packing, solved with pyamg.

From a packing to permeability (thesis 3.5.2, 4.2.3): read → tessellate → sample → Q* and
conductances → prune → assemble, condense, solve (pyamg SA-PCG), verify → Darcy k, pressure drop,
and the empirical equations beside them.

Public functions
----------------
read_packing(path) -> Packing
    CSV ``x,y,z,r``, ``.npz`` (centers, radii) or LAMMPS/LIGGGHTS ``dump custom``.
tessellate(packing) -> Tessellation
    Pores = Delaunay tetrahedra, throats = their faces (each once, -1 on the hull).
tie_groups(tessellation)
    Exactly co-spherical tetrahedra and slivers joined into pore bodies.
default_region, select_sample, prune_disconnected, Region, SampleNetwork
    The interior sample box/cylinder, inlet/outlet pores, connectivity pruning.
thesis_conductance, throat_qstar, throat_conductance
    g = Q* r̄⁴/(μ L), L = 2r̄ (Eq. 3.41); Q* by policy from ``cache`` / ``throats``.
assemble_laplacian, apply_pressure_bc, solve_pressure, solve_fixed_pressure, verify_solution
    Assemble → constrain → solve, and the mass-balance check.
solve_network(packing, ...) -> FlowResult
    The whole pipeline (what ``python -m network.solve`` runs).
ergun_gradient, kozeny_carman_gradient, asabe_d272_gradient, darcy_permeability
region_porosity, random_packing, write_network_vtu

From the conduit-model and paths issues: lattice_packing, lattice_radius (regular arrays),
lattice_permeability, beetstra_permeability, kozeny_carman_permeability (references),
trace_paths, AirflowPath, branched_pressure_drop (airflow paths, branched-path model).

Command-line tools: ``python -m network.solve`` (permeability, pressure drop; the bundled
soybean scene when no packing is given), ``python -m network.throats`` (throat table for
``cache.precompute``), ``python -m network.paths``, ``python -m network.bench``.
"""

from ._branched import BranchedResult, branched_pressure_drop
from ._conductance import (MODELS, MU_AIR_PA_S, POLICIES, QstarResult, thesis_conductance,
                           throat_conductance, throat_qstar)
from ._empirical import (asabe_d272_gradient, darcy_permeability, ergun_gradient,
                         kozeny_carman_gradient)
from ._flow import (SolveInfo, apply_pressure_bc, assemble_laplacian, solve_fixed_pressure,
                    solve_pressure, verify_solution)
from ._generate import random_packing, sample_throats
from ._io import Packing, default_packing_path, read_container, read_packing, write_packing_csv
from ._lattices import lattice_packing, lattice_radius
from ._paths import AirflowPath, trace_paths
from ._pipeline import FlowResult, solve_network
from ._porosity import region_porosity
from ._references import beetstra_permeability, kozeny_carman_permeability, lattice_permeability
from ._sample import Region, SampleNetwork, default_region, prune_disconnected, select_sample
from ._tessellation import QHULL_OPTIONS, Tessellation, tessellate, tie_groups
from ._vtk import write_network_vtu

__all__ = [
    "Packing", "read_packing", "write_packing_csv", "default_packing_path", "read_container",
    "Tessellation", "tessellate", "tie_groups", "QHULL_OPTIONS",
    "Region", "SampleNetwork", "default_region", "select_sample", "prune_disconnected",
    "MU_AIR_PA_S", "POLICIES", "MODELS", "QstarResult", "thesis_conductance", "throat_qstar",
    "throat_conductance",
    "SolveInfo", "assemble_laplacian", "apply_pressure_bc", "solve_pressure",
    "solve_fixed_pressure", "verify_solution",
    "FlowResult", "solve_network",
    "ergun_gradient", "kozeny_carman_gradient", "asabe_d272_gradient", "darcy_permeability",
    "region_porosity", "random_packing", "sample_throats", "write_network_vtu",
    "lattice_packing", "lattice_radius",
    "lattice_permeability", "beetstra_permeability", "kozeny_carman_permeability",
    "AirflowPath", "trace_paths", "BranchedResult", "branched_pressure_drop",
]

"""grainflow.network: from a sphere packing to airflow resistance, in layers.

Each layer imports only the layers above it in this list (``tests/test_layers.py``):

``_air``, ``packing``  air properties; Packing, readers/writers, random and lattice packings
``pores``              Delaunay tessellation, merged pore bodies, sample region, porosity
``conductance``        Q* by policy (the only importer of ``cache``), thesis and conduit models
``flow``               assemble → constrain → solve → verify; :func:`solve_network`, the one
                       pipeline, and :class:`FlowResult`; Darcy/core k; Ergun, K-C, ASABE D272
``paths``              airflow paths, tortuosity, the branched-path model, plots
``validation``         reference permeabilities and validation cases through the one pipeline
CLIs                   ``python -m network.solve`` (permeability and pressure drop; the bundled
                       soybean scene by default), ``network.throats``, ``network.paths``,
                       ``network.curve`` (the resistance curve with inertia), ``network.bench``:
                       parse, call the pipeline, print

The names below (``__all__``) are the public API; the subpackages export more.
"""

import sys as _sys

if _sys.argv[:1] == ["-m"]:     # python -m network.<command>: a command process (network._lean)
    from ._lean import lean_imports as _lean_imports
    _lean_imports()

from ._air import MU_AIR_PA_S, RHO_AIR_KG_M3
from .conductance import (MODELS, POLICIES, ConductanceResult, QstarResult, thesis_conductance,
                          throat_conductance, throat_qstar)
from .flow import (AMGSolver, FlowResult, InertialPoint, SolveInfo, apply_pressure_bc,
                   asabe_d272_gradient, fit_curve, solve_inertial,
                   assemble_laplacian, darcy_permeability, ergun_gradient, kozeny_carman_gradient,
                   solve_fixed_pressure, solve_network, solve_pressure, verify_solution,
                   write_network_vtu)
from .packing import (Packing, default_packing_path, lattice_packing, lattice_radius,
                      random_packing, read_container, read_packing, write_packing_csv)
from .paths import AirflowPath, BranchedResult, branched_pressure_drop, trace_paths
from .pores import (QHULL_OPTIONS, Region, SampleNetwork, Tessellation, default_region,
                    prune_disconnected, region_porosity, sample_throats, select_sample,
                    tessellate, tie_groups)
from .validation import beetstra_permeability, kozeny_carman_permeability, lattice_permeability

from ._lean import imports_done as _imports_done

_imports_done()                 # a command process's collector back on (no-op otherwise)

__all__ = [
    "Packing", "read_packing", "write_packing_csv", "default_packing_path", "read_container",
    "Tessellation", "tessellate", "tie_groups", "QHULL_OPTIONS",
    "Region", "SampleNetwork", "default_region", "select_sample", "prune_disconnected",
    "MU_AIR_PA_S", "RHO_AIR_KG_M3", "POLICIES", "MODELS", "QstarResult", "ConductanceResult",
    "thesis_conductance", "throat_qstar",
    "throat_conductance",
    "SolveInfo", "assemble_laplacian", "apply_pressure_bc", "solve_pressure",
    "solve_fixed_pressure", "verify_solution",
    "FlowResult", "solve_network", "AMGSolver", "InertialPoint", "solve_inertial", "fit_curve",
    "ergun_gradient", "kozeny_carman_gradient", "asabe_d272_gradient", "darcy_permeability",
    "region_porosity", "random_packing", "sample_throats", "write_network_vtu",
    "lattice_packing", "lattice_radius",
    "lattice_permeability", "beetstra_permeability", "kozeny_carman_permeability",
    "AirflowPath", "trace_paths", "BranchedResult", "branched_pressure_drop",
]

"""Flow: the linear system, the one pipeline from a packing to permeability, and its results.

assemble → boundary conditions → solve (pyamg SA-PCG) → verify (:mod:`._linear`);
:func:`solve_network` runs the whole pipeline and returns a :class:`FlowResult`; Darcy and core
permeability; the empirical laws (Ergun, Kozeny-Carman, ASABE D272) set beside it; VTK output.
"""

from ._amg import AMGSolver
from ._darcy import core_permeability, darcy_permeability
from ._empirical import (ASABE_SOYBEAN_A, ASABE_SOYBEAN_B, asabe_d272_gradient, ergun_gradient,
                         kozeny_carman_gradient)
from ._fits import GRAINS, fit_curve
from ._conduit_flow import conduit_flow
from ._inertial import InertialPoint, solve_inertial
from ._linear import (SolveInfo, apply_pressure_bc, assemble_laplacian, boundary_flows,
                      solve_fixed_pressure, solve_pressure, verify_solution)
from ._options import (DEFAULT_DEPTH_M, DEFAULT_VELOCITY_M_S, ConductanceOptions, FlowOptions,
                       SampleOptions)
from ._pipeline import (CORE_MARGIN_DIAMETERS, CORE_MIN_DIAMETERS, INERTIAL_LAW, inset_window,
                        solve_axes, solve_network)
from ._result import FlowResult, combined_summary
from ._vtk import read_vtu_arrays, write_network_vtu

__all__ = ["AMGSolver", "ASABE_SOYBEAN_A", "ASABE_SOYBEAN_B", "CORE_MARGIN_DIAMETERS",
           "CORE_MIN_DIAMETERS", "ConductanceOptions", "DEFAULT_DEPTH_M", "DEFAULT_VELOCITY_M_S",
           "FlowOptions", "FlowResult", "SampleOptions",
           "GRAINS", "INERTIAL_LAW", "InertialPoint", "SolveInfo", "apply_pressure_bc",
           "asabe_d272_gradient", "assemble_laplacian", "boundary_flows", "combined_summary",
           "conduit_flow", "core_permeability", "darcy_permeability", "ergun_gradient",
           "fit_curve", "inset_window", "kozeny_carman_gradient", "read_vtu_arrays", "solve_axes",
           "solve_fixed_pressure", "solve_inertial", "solve_network", "solve_pressure",
           "verify_solution", "write_network_vtu"]

"""grainflow.network: from a sphere packing to airflow resistance, in layers.

Each layer imports only the layers above it in this list (``tests/test_layers.py``):

``_air``, ``core``,    air properties; Packing, its file format and the command-line base
``packing``            (``core``, shared with ``dem``); random and lattice packings
``pores``              Delaunay tessellation, merged pore bodies, sample region, porosity
``conductance``        Q* by policy (the only importer of ``cache``), thesis and conduit models
``flow``               assemble → constrain → solve → verify; :func:`solve_network`, the one
                       pipeline, and :class:`FlowResult`; Darcy/core k; Ergun, K-C, ASABE D272
``paths``              airflow paths, tortuosity, the branched-path model, plots
``validation``         reference permeabilities and validation cases through the one pipeline
CLIs                   ``python -m network.solve`` (permeability and pressure drop; the bundled
                       soybean scene by default), ``network.throatlist``, ``network.paths``,
                       ``network.curve`` (the resistance curve with inertia), ``network.bench``:
                       parse, call the pipeline, print

The names below (``__all__``) are the public API, each imported from its subpackage on first
use; the subpackages export more.
"""

import importlib as _importlib
import importlib.util as _importlib_util
import sys as _sys


def _network_command() -> bool:
    """Whether this process is a network command: started as ``python -m network.<command>``
    (``sys.argv[0]`` is ``'-m'`` while the package is imported; where the interpreter keeps no
    ``orig_argv``, any ``-m``). The commands of the other packages import :mod:`network.core`
    alone (dem, cache, throats) or the public API (the benchmarks), lazily."""
    if _sys.argv[:1] != ["-m"]:
        return False
    orig = list(getattr(_sys, "orig_argv", ()))
    for k, arg in enumerate(orig[1:], 1):
        if arg.startswith("-m"):
            module = arg[2:] or (orig[k + 1] if k + 1 < len(orig) else "")
            return module.split(".")[0] == "network"
    return True


if _network_command():          # a command process (network._lean): the pipeline imported now
    from ._lean import lean_imports as _lean_imports
    _lean_imports()
    from . import conductance, flow, packing, paths, pores, validation  # noqa: F401

#: public name -> the subpackage that defines it; imported on first use (PEP 562), so that
#: ``import network.core`` (what ``dem`` imports) loads the core alone
_HOME = {}
for _module, _names in {
    "._air": ("MU_AIR_PA_S", "RHO_AIR_KG_M3"),
    ".paths": ("AirflowPath", "BranchedResult", "branched_pressure_drop", "trace_paths"),
    ".conductance": ("MODELS", "POLICIES", "ConductanceResult", "QstarResult",
                     "thesis_conductance", "throat_conductance", "throat_qstar"),
    ".flow": ("AMGSolver", "FlowResult", "InertialPoint", "SolveInfo", "apply_pressure_bc",
              "asabe_d272_gradient", "fit_curve", "solve_inertial", "assemble_laplacian",
              "darcy_permeability", "ergun_gradient", "kozeny_carman_gradient",
              "solve_fixed_pressure", "solve_network", "solve_pressure", "verify_solution",
              "write_network_vtu", "SampleOptions", "ConductanceOptions", "FlowOptions"),
    ".packing": ("Packing", "default_packing_path", "lattice_packing", "lattice_radius",
                 "random_packing", "read_container", "read_packing", "write_packing_csv"),
    ".pores": ("QHULL_OPTIONS", "Region", "SampleNetwork", "Tessellation", "default_region",
               "prune_disconnected", "region_porosity", "sample_throats", "select_sample",
               "tessellate", "tie_groups"),
    ".validation": ("beetstra_permeability", "kozeny_carman_permeability",
                    "lattice_permeability"),
}.items():
    _HOME.update(dict.fromkeys(_names, _module))
del _module, _names


def __getattr__(name: str):
    """A public name (or a subpackage) of the package, imported on first use."""
    if name in _HOME:
        value = getattr(_importlib.import_module(_HOME[name], __name__), name)
    elif not name.startswith("__") and _importlib_util.find_spec(f"{__name__}.{name}"):
        value = _importlib.import_module(f"{__name__}.{name}")
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "Packing", "read_packing", "write_packing_csv", "default_packing_path", "read_container",
    "Tessellation", "tessellate", "tie_groups", "QHULL_OPTIONS",
    "Region", "SampleNetwork", "default_region", "select_sample", "prune_disconnected",
    "MU_AIR_PA_S", "RHO_AIR_KG_M3", "POLICIES", "MODELS", "QstarResult", "ConductanceResult",
    "thesis_conductance", "throat_qstar",
    "throat_conductance",
    "SolveInfo", "assemble_laplacian", "apply_pressure_bc", "solve_pressure",
    "solve_fixed_pressure", "verify_solution",
    "FlowResult", "solve_network", "SampleOptions", "ConductanceOptions", "FlowOptions",
    "AMGSolver", "InertialPoint", "solve_inertial", "fit_curve",
    "ergun_gradient", "kozeny_carman_gradient", "asabe_d272_gradient", "darcy_permeability",
    "region_porosity", "random_packing", "sample_throats", "write_network_vtu",
    "lattice_packing", "lattice_radius",
    "lattice_permeability", "beetstra_permeability", "kozeny_carman_permeability",
    "AirflowPath", "trace_paths", "BranchedResult", "branched_pressure_drop",
]

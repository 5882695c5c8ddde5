"""grainflow.network: Delaunay pore network of a sphere packing, solved with pyamg.

Public functions
----------------
read_packing(path) -> Packing
    CSV ``x,y,z,r``, ``.npz`` (centers, radii) or LAMMPS/LIGGGHTS ``dump custom``.
tessellate(packing) -> Tessellation
    Pores = Delaunay tetrahedra, throats = their faces (each once, -1 on the hull).

Command-line tools: ``python -m network.solve`` (permeability, pressure drop),
``python -m network.throats`` (throat table for ``cache.precompute``), ``python -m network.bench``.

"""

from ._io import Packing, default_packing_path, read_packing, write_packing_csv
from ._tessellation import QHULL_OPTIONS, Tessellation, tessellate, tie_groups

__all__ = [
    "Packing",
    "read_packing",
    "write_packing_csv",
    "default_packing_path",
    "Tessellation",
    "tessellate",
    "QHULL_OPTIONS",
    "tie_groups",
]

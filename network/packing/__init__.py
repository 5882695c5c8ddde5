"""Packings: the :class:`Packing` table, its readers and writers (both from :mod:`network.core`,
the light module ``dem`` shares), and generated packings.

Readers take CSV ``x,y,z,r`` (m), ``.npz`` and LAMMPS/LIGGGHTS dumps; :func:`random_packing` is the
project's one random sphere packer (grow and push, no gravity); :func:`lattice_packing` builds
the regular arrays whose exact permeability is known.
"""

from ._generate import SOYBEAN_DEFAULT, periodic_copies, random_packing, soybean_default_scene
from ..core import (FORMATS, MIN_SPHERES, PLAUSIBLE_DIAMETER_M, UNITS, DegeneratePackingError,
                    Packing, check_grains, check_three_dimensional, default_packing_path,
                    grain_volumes, read_container, read_packing, scale_warning,
                    validate_spheres, write_packing_csv)
from ._lattices import (LATTICES, SPHERES_PER_CELL, TOUCHING_FRACTION, lattice_basis,
                        lattice_packing, lattice_radius)

__all__ = ["FORMATS", "LATTICES", "MIN_SPHERES", "PLAUSIBLE_DIAMETER_M", "SOYBEAN_DEFAULT",
           "SPHERES_PER_CELL", "TOUCHING_FRACTION", "UNITS", "DegeneratePackingError", "Packing",
           "check_grains", "check_three_dimensional", "grain_volumes",
           "default_packing_path", "lattice_basis", "lattice_packing", "lattice_radius",
           "periodic_copies", "random_packing", "read_container", "read_packing",
           "scale_warning", "soybean_default_scene", "validate_spheres", "write_packing_csv"]

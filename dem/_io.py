"""Packing files for the DEM: the project's one packing format (:mod:`network.core`), read and
written as centre and radius arrays with the JSON summary beside them.

The DEM moves single spheres, so a ``grain_id`` on several spheres (a multi-sphere grain) is
refused on reading; fewer than five spheres are taken (a tessellation needs five, the DEM
none).
"""

from __future__ import annotations

import numpy as np

from network.core import Packing, read_summary, summary_path, write_summary
from network.core import read_packing as _read_core
from network.core import write_packing_csv

__all__ = ["write_packing", "write_summary", "read_packing", "summary_path"]

#: Why the DEM refuses a grain of several spheres (the message's end).
ONE_SPHERE_GRAINS = ("multi-sphere grains cannot be moved by the sphere engine (dem.vibrate "
                     "vibrates sphere packings)")


def write_packing(path, centers, radii, summary=None) -> None:
    """Write ``x,y,z,r`` rows (m, 10 significant digits) and, if given, the JSON summary.

    Files are written to a temporary name first and renamed, so a crash never leaves a
    half-written packing (:func:`network.core.write_packing_csv`).
    """
    centers = np.asarray(centers, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if centers.ndim != 2 or centers.shape[1] != 3 or radii.shape != (len(centers),):
        raise ValueError(f"need centers (N, 3) and radii (N,), got {centers.shape}, {radii.shape}")
    if not (np.all(np.isfinite(centers)) and np.all(radii > 0)):
        raise ValueError("refusing to write a packing with non-finite centres or non-positive radii")
    write_packing_csv(Packing(centers, radii), path, digits=10, notation="e", summary=summary)


def read_packing(path):
    """Read a sphere packing (m) and its JSON summary, validated at the door.

    The formats and checks of :func:`network.core.read_packing` (delimited text, ``.npz``,
    LAMMPS/LIGGGHTS dumps; the row named in every refusal), with any number of spheres and no
    grain of several spheres (:data:`ONE_SPHERE_GRAINS`).

    Returns
    -------
    centers : (N, 3) array, m
    radii : (N,) array, m
    summary : dict or None
        The companion JSON if present.

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        Malformed content, NaN/inf, a radius <= 0, two spheres with one centre, a
        ``grain_id`` shared by several spheres, or a companion JSON that is not JSON; the
        message names the file and the row.
    """
    pk = _read_core(path, min_spheres=1, one_sphere_grains=ONE_SPHERE_GRAINS)
    return np.array(pk.centers), np.array(pk.radii), read_summary(path)

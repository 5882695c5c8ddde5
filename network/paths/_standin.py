"""The stand-in packing of ``python -m network.paths --standin``: a geometric random packing
in a given box, soybean diameters at the thesis's bin porosity, for a bed without a packing file.

It holds the stand-in's diameters and porosity, the limits on its box (most spheres, shortest
side) and the two functions the command uses: :func:`standin_size` (spheres in a box, checked
against the limits) and :func:`standin_packing` (the packing, by
``network.packing.random_packing``).
"""

from __future__ import annotations

import numpy as np

from ..packing import random_packing

__all__ = ["STANDIN_DIAMETERS_M", "STANDIN_MAX_SPHERES", "STANDIN_MIN_SIDE_M",
           "STANDIN_POROSITY", "standin_packing", "standin_size"]


#: Stand-in packing (``--standin``): soybean diameters (thesis Table 3.1) and the thesis's bin
#: porosity.
STANDIN_DIAMETERS_M = (5.5e-3, 7.5e-3)
STANDIN_POROSITY = 0.408
#: Most spheres a stand-in may have (about a 0.29 m cube; the thesis's bin holds 18 000).
STANDIN_MAX_SPHERES = 100_000
#: Shortest stand-in side, m: 6 mean diameters, the default sample's 1.5-diameter margins on
#: both sides and its 2-diameter interior (``network.pores.default_region``) with room to spare.
STANDIN_MIN_SIDE_M = 0.04


def standin_packing(box_m, *, rng=None):
    """Geometric stand-in packing of about the box ``box_m`` (m): (centers, radii).

    As many spheres (diameters uniform in :data:`STANDIN_DIAMETERS_M`) as give porosity
    :data:`STANDIN_POROSITY` in the box, packed by ``network.packing.random_packing`` with the
    box's aspect ratio; its box has the volume of the drawn spheres at that porosity, so it
    differs from ``box_m`` by the sampling error of the mean sphere volume.
    """
    n = standin_size(box_m)
    pk = random_packing(n, diameter_range_m=STANDIN_DIAMETERS_M,
                        solid_fraction=1.0 - STANDIN_POROSITY,
                        aspect=np.asarray(box_m, dtype=float), rng=rng)
    return np.asarray(pk.centers), np.asarray(pk.radii)


def standin_size(box_m) -> int:
    """Spheres of the stand-in in the box ``box_m`` (3,) m; ValueError naming ``--standin``
    and the box when a side is not > 0 or the count is over :data:`STANDIN_MAX_SPHERES`."""
    box = np.asarray(box_m, dtype=float)
    if box.shape != (3,) or not np.all(np.isfinite(box) & (box > 0)):
        raise ValueError(f"--standin needs three box sides > 0 (m), got {box_m}")
    d0, d1 = STANDIN_DIAMETERS_M
    mean_vol = np.pi / 6.0 * (d1**4 - d0**4) / (4.0 * (d1 - d0))  # E[pi d^3 / 6], d uniform
    n = (1.0 - STANDIN_POROSITY) * float(box.prod()) / mean_vol
    if n > STANDIN_MAX_SPHERES:
        side = (STANDIN_MAX_SPHERES * mean_vol / (1.0 - STANDIN_POROSITY)) ** (1 / 3)
        raise ValueError(f"--standin {' '.join(f'{v:g}' for v in box)}: the box holds about "
                         f"{n:.3g} spheres, more than the {STANDIN_MAX_SPHERES} a stand-in may "
                         f"have (a cube of {side:.2g} m); give a smaller box")
    return int(round(n))

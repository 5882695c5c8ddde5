"""Where a throat's two conduits end: the heights of its pore bodies' centres above its face.

The conduit model (:mod:`._conduit`) integrates each side of a throat from the face (h = 0) to
the height :math:`h_P` of that side's pore-body centre along the face normal; this module holds
that geometry, apart from the resistance integral and the blocks of throats that use it.
"""

from __future__ import annotations

import numpy as np

from ..pores import column_norm, cross_components

__all__ = ["conduit_heights"]


def conduit_heights(tessellation, idx, pm):
    """Conduit heights (M, 2), m: the normal distance from each throat's face plane to the
    centres of its two pore bodies (``pm``, :class:`network.pores.PoreMerge`), and the side
    (M, 2) of the plane each lies on, +1 / -1 along n = (x2 - x1) x (x3 - x1) / |...|
    (+1 where the height is 0). A hull face's one side counts twice."""
    t = tessellation
    tp = t.throat_pores[idx]
    # (component-major: each component a contiguous row, the gathers and products run over it)
    x = np.ascontiguousarray(t.packing.centers.T)[:, t.throat_vertices[idx].T]   # (3, 3, M)
    nrm = np.stack(cross_components(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]))  # face normal
    nrm /= np.maximum(column_norm(nrm), 1e-300)
    centre = np.ascontiguousarray(pm.center.T)
    h = np.zeros((idx.size, 2))
    sign = np.ones((idx.size, 2))
    for side in (0, 1):
        pore = tp[:, side]
        ok = pore >= 0
        d = centre[:, pm.labels[pore[ok]]] - x[:, 0][:, ok]
        n = nrm[:, ok]
        dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2]
        h[ok, side] = np.abs(dn)
        sign[ok, side] = np.where(dn < 0, -1.0, 1.0)
    hull = tp[:, 1] < 0
    h[hull, 1] = h[hull, 0]
    sign[hull, 1] = sign[hull, 0]
    return h, sign

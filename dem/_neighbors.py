r"""Verlet neighbour list with a skin, built from ``scipy.spatial.cKDTree``.

Candidate pairs are all (i, j), i < j, with centre distance below
r_i + r_j + skin. The list stays valid until some particle has moved more than
skin/2 since the last build (then no pair outside the list can touch).
Tangential contact history is carried across rebuilds by matching sorted pair keys
``i * N + j`` with :func:`numpy.searchsorted`.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["VerletList", "build_pairs", "remap_history"]

log = logging.getLogger(__name__)


def build_pairs(centers, radii, skin):
    """Candidate contact pairs, (Np, 2) int64 array sorted by key i*N+j, i < j.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    skin : float, m
        Extra distance beyond touching.
    """
    n = len(radii)
    if n < 2:
        return np.empty((0, 2), dtype=np.int64)
    tree = cKDTree(centers)
    pairs = tree.query_pairs(2.0 * float(radii.max()) + skin, output_type="ndarray")
    if len(pairs) == 0:
        return np.empty((0, 2), dtype=np.int64)
    pairs = pairs.astype(np.int64, copy=False)
    i, j = pairs[:, 0], pairs[:, 1]
    d = centers[j] - centers[i]
    keep = np.einsum("ij,ij->i", d, d) < (radii[i] + radii[j] + skin) ** 2
    pairs = np.sort(pairs[keep], axis=1)
    keys = pairs[:, 0] * n + pairs[:, 1]
    return pairs[np.argsort(keys, kind="stable")]


def remap_history(old_keys, old_values, new_keys):
    """Carry per-pair values (e.g. shear springs) from an old sorted key list to a new one.

    Pairs absent from the old list get zeros.

    Parameters
    ----------
    old_keys : (M,) int64, sorted
    old_values : (M, k) array
    new_keys : (P,) int64

    Returns
    -------
    (P, k) array
    """
    out = np.zeros((len(new_keys),) + old_values.shape[1:], dtype=old_values.dtype)
    if len(old_keys) == 0 or len(new_keys) == 0:
        return out
    pos = np.searchsorted(old_keys, new_keys)
    pos_c = np.minimum(pos, len(old_keys) - 1)
    found = old_keys[pos_c] == new_keys
    out[found] = old_values[pos_c[found]]
    return out


class VerletList:
    """Pair list plus the state needed to know when it must be rebuilt.

    Attributes
    ----------
    pairs : (Np, 2) int64
    keys : (Np,) int64, sorted
    n_builds : int
    """

    def __init__(self, skin):
        if not skin > 0:
            raise ValueError(f"skin must be positive, got {skin}")
        self.skin = float(skin)
        self.pairs = np.empty((0, 2), dtype=np.int64)
        self.keys = np.empty(0, dtype=np.int64)
        self._ref = None
        self._ref_radii = None
        self.n_builds = 0

    def needs_rebuild(self, centers, radii):
        """True when a particle moved more than skin/2 (or grew) since the last build."""
        if self._ref is None or len(self._ref) != len(centers):
            return True
        d = centers - self._ref
        moved = float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d))))
        grown = float(np.max(radii - self._ref_radii))
        return 2.0 * moved + 2.0 * grown > self.skin

    def build(self, centers, radii):
        """Rebuild; returns the old keys so callers can remap pair history."""
        old = self.keys
        self.pairs = build_pairs(centers, radii, self.skin)
        n = len(radii)
        self.keys = self.pairs[:, 0] * n + self.pairs[:, 1]
        self._ref = centers.copy()
        self._ref_radii = radii.copy()
        self.n_builds += 1
        return old

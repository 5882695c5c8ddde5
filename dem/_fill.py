r"""Filling a container: the thesis's sphere count and random sequential addition.

* :func:`thesis_particle_count`: N from the target porosity (thesis Eq. 3.10).
* :func:`check_fill`: refuses porosities no sphere packing reaches and bins smaller than a grain.
* :func:`check_sphere_count`: refuses a bed of more than :data:`MAX_SPHERES` spheres.
* :func:`generate_spheres`: N non-overlapping spheres at random (PFC3D ``generate``).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ._material import SOYBEAN

__all__ = ["KEPLER_POROSITY", "MAX_SPHERES", "thesis_particle_count", "check_fill",
           "check_sphere_count", "generate_spheres"]

#: Densest packing of equal spheres (Kepler), porosity 1 − π/√18.
KEPLER_POROSITY = 1.0 - np.pi / np.sqrt(18.0)


#: Most spheres in one bed: the thesis's cyl-bin holds 18 188; a million spheres already need
#: ~10^11 particle-steps to settle (hours to days at the ~10^7 particle-steps/s of one core) and
#: GBs of neighbour lists, and a request far beyond (a 1 m bin: 4 million; 100 m: 8e12, 60 TiB
#: for its radii alone) only fails late.
MAX_SPHERES = 1_000_000


def check_sphere_count(n, what="spheres"):
    """ValueError when a bed of ``n`` spheres exceeds :data:`MAX_SPHERES` (the message names
    both and what they count)."""
    if n > MAX_SPHERES:
        raise ValueError(f"the container needs {n:,} {what}, more than the limit of "
                         f"{MAX_SPHERES:,} spheres per bed: make it smaller")


def thesis_particle_count(container, porosity, material=SOYBEAN):
    r"""Sphere count of thesis Eq. 3.10 with r̄ = (r_lo + r_hi)/2:
    :math:`N = \lfloor (1-φ)V / (\tfrac43 π r̄^3) \rfloor` (rect-bin: 5146; cyl-bin: 18188)."""
    rbar = 0.5 * (material.radius_min_m + material.radius_max_m)
    return int((1.0 - porosity) * container.volume_m3 / (4.0 / 3.0 * np.pi * rbar**3))


def check_fill(container, porosity, material):
    """Raise ValueError when ``porosity`` cannot be packed or the container is smaller than a grain."""
    if not 0.0 < porosity < 1.0:
        raise ValueError(f"porosity must be in (0, 1), got {porosity}")
    if porosity <= KEPLER_POROSITY:
        raise ValueError(
            f"porosity {porosity} is unreachable: no sphere packing is denser than "
            f"{KEPLER_POROSITY:.4f} (face-centred cubic)"
        )
    if porosity < 0.35:
        raise ValueError(
            f"porosity {porosity} is unreachable by a random packing of near-equal spheres "
            "(random close packing is about 0.36)"
        )
    d = 2 * material.radius_max_m
    if container.min_dimension_m < d:
        raise ValueError(
            f"container ({container.size_m}, height {container.fill_height_m}) m is smaller than a "
            f"grain of diameter {d} m"
        )


def generate_spheres(container, n, r_lo, r_hi, rng, *, tries=200000):
    """N non-overlapping spheres, radii uniform in [r_lo, r_hi], random sequential addition.

    Candidates are drawn in batches and rejected against the accepted spheres (KD-tree)
    and against each other; raises ValueError after ``tries`` rejected candidates
    (PFC3D ``generate ... tries``).
    """
    radii_all = np.empty(0)
    centers_all = np.empty((0, 3))
    rejected = 0
    while len(radii_all) < n:
        need = n - len(radii_all)
        m = max(2 * need, 64)
        r = rng.uniform(r_lo, r_hi, m)
        x = container.sample_centers(r, rng)
        ok = np.ones(m, dtype=bool)
        if len(radii_all):
            tree = cKDTree(centers_all)
            k = min(16, len(radii_all))
            dist, idx = tree.query(x, k=k, distance_upper_bound=r_hi + r.max())
            dist = dist.reshape(m, k)
            idx = idx.reshape(m, k)
            valid = idx < len(radii_all)
            rr = np.where(valid, radii_all[np.minimum(idx, len(radii_all) - 1)], 0.0)
            ok &= ~np.any(valid & (dist < r[:, None] + rr), axis=1)
        pairs = cKDTree(x).query_pairs(2 * r_hi, output_type="ndarray")
        if len(pairs):
            i, j = pairs[:, 0], pairs[:, 1]
            clash = np.linalg.norm(x[i] - x[j], axis=1) < r[i] + r[j]
            ok[np.maximum(i, j)[clash]] = False
        acc = np.flatnonzero(ok)[:need]
        rejected += m - len(acc)
        radii_all = np.concatenate([radii_all, r[acc]])
        centers_all = np.concatenate([centers_all, x[acc]])
        if rejected > tries and len(radii_all) < n:
            raise ValueError(
                f"could only place {len(radii_all)} of {n} spheres after {rejected} tries: "
                "container too small or porosity too low for the initial radii"
            )
    return centers_all, radii_all

"""Sample regions: the flow axis, a box or cylinder inside the bed, the default interior region.

A sample keeps ``margin`` (default 1.5 mean diameters) from the walls or from the outer sphere
surfaces, where the packing is looser than the bulk (thesis 4.2.3, Appendix G).
"""

from __future__ import annotations

import logging

import numpy as np

from ..core import AXES, Region, axis_index
from ..packing import MIN_SPHERES

__all__ = ["AXES", "MIN_INTERIOR_DIAMETERS", "NoInteriorError", "OUTSIDE_BED_DIAMETERS", "Region",
           "axis_index", "bed_members", "check_inside_bed", "default_region", "sample_region"]

#: A tetrahedron whose empty sphere is wider than this many mean diameters is outside the bed.
OUTSIDE_BED_DIAMETERS = 2.0

#: Thinnest interior (in mean diameters) that :func:`default_region` accepts on any axis.
MIN_INTERIOR_DIAMETERS = 2.0

log = logging.getLogger(__name__)


class NoInteriorError(ValueError):
    """The packing leaves no default interior sample: ``reason`` says why, ``advice`` (the
    CLIs' options) what to give instead; the message is both. An input fault (``bad_input``:
    exit 2 in every command, also where it is found while computing)."""

    bad_input = True

    def __init__(self, reason: str, advice: str, sep: str = "; "):
        super().__init__(f"{reason}{sep}{advice}")
        self.reason, self.advice = reason, advice


def bed_members(packing) -> np.ndarray:
    """Spheres of the bed (bool, (N,)): along every axis the sorted sphere surfaces of a packed
    bed leave no empty band wider than :data:`OUTSIDE_BED_DIAMETERS` mean diameters; spheres
    beyond such a band from the largest contiguous run (a DEM's escaped particles, a stray row)
    are not. O(N log N), no neighbour search."""
    c, r = packing.centers, packing.radii
    gap = OUTSIDE_BED_DIAMETERS * packing.grain_diameter
    keep = np.ones(c.shape[0], dtype=bool)
    for k in range(3):
        order = np.argsort(c[:, k], kind="stable")
        top = np.maximum.accumulate(c[order, k] + r[order])     # highest surface so far
        breaks = np.flatnonzero(c[order[1:], k] - r[order[1:]] - top[:-1] > gap) + 1
        if breaks.size:
            edges = np.concatenate([[0], breaks, [order.size]])
            run = int(np.argmax(np.diff(edges)))
            out = np.ones(order.size, dtype=bool)
            out[edges[run]:edges[run + 1]] = False
            keep[order[out]] = False
    return keep


def default_region(packing, *, margin: float | None = None, cylinder: bool = False,
                   container: dict | None = None, axis="z") -> Region:
    r"""Interior box (or cylinder) of a packing, ``margin`` inside its container or its spheres.

    Parameters
    ----------
    packing : Packing
    margin : float, optional, m
        Distance kept from the walls (or from the outer sphere surfaces) on every side.
        Default: 1.5 mean diameters, the thickness over which wall ordering raises the local
        porosity of random sphere packings. (The thesis's box, |x|, |y| < 0.051 m in a 0.15 m
        cylinder, stayed 3.7 d from the wall at mid-faces but came within 0.5 d of it at the
        corners; pass ``--sample`` to reproduce it.)
    cylinder : bool
        Return the largest cylinder (axis = flow axis) inside the interior box.
    container : dict, optional
        From :func:`network.read_container`. A vertical ``'cylinder'`` (``size_m = [D]``,
        axis z, centre ``center_xy`` or the middle of the packing) gives a cylinder of radius
        D/2 − margin for flow along z, and the square inscribed in it for flow along x or y:
        the bounding box of a cylindrical bed would reach past the wall, where the convex
        hull's large outer tetrahedra make a spurious high-conductance channel.
    axis : {'x', 'y', 'z'}
        Flow axis (matters for a cylindrical container only).
    """
    bed = bed_members(packing)
    if bed.sum() < MIN_SPHERES:
        gap = OUTSIDE_BED_DIAMETERS * packing.grain_diameter
        raise NoInteriorError(
            f"no bed to take a sample from: the spheres lie apart (no two near contact?), "
            f"{int(bed.sum())} of the {packing.n} without an empty band wider than "
            f"{OUTSIDE_BED_DIAMETERS:g} mean diameters ({gap:.3g} m) between them, fewer than "
            f"{MIN_SPHERES} (radii too small for their spacing?)", "give an explicit --sample box")
    lo, hi = packing.extent(None if bed.all() else bed)
    if not bed.all():
        apart = np.flatnonzero(~bed)
        log.warning("%d sphere(s) lie apart from the bed, beyond an empty band of %g mean "
                    "diameters (sphere %s): the default sample leaves them out", apart.size,
                    OUTSIDE_BED_DIAMETERS, ", ".join(f"#{i + 1}" for i in apart[:5])
                    + (", ..." if apart.size > 5 else ""))
    m = 1.5 * packing.grain_diameter if margin is None else float(margin)
    if m < 0:
        raise ValueError(f"margin must be >= 0, got {m}")
    if np.any(hi - lo <= 2 * m):
        raise NoInteriorError(f"margin {m:g} leaves no interior in a packing of extent "
                              f"{hi - lo}", "give a smaller --margin or an explicit --sample box")
    d = packing.grain_diameter
    thin = np.flatnonzero(hi - lo - 2 * m < MIN_INTERIOR_DIAMETERS * d)
    if thin.size:
        k = int(thin[0])
        w = float(hi[k] - lo[k] - 2 * m)
        raise NoInteriorError(
            f"a margin of {m:.4g} (kept from the walls on every side) leaves an interior only "
            f"{w:.3g} ({w / d:.2f} mean diameters) thick along {'xyz'[k]}, where the packing is "
            f"{hi[k] - lo[k]:.4g} thick: too thin for a sample away from the walls (the "
            f"tessellation has no walls)", "Give a smaller --margin (the wall layer then enters "
            "the sample) or an explicit --sample box", sep=". ")
    lo, hi = lo + m, hi - m
    if container is not None and container.get("kind") == "cylinder":
        c = np.asarray(container.get("center_xy", 0.5 * (lo[:2] + hi[:2])), dtype=float)
        r_in = 0.5 * float(container["size_m"][0]) - m
        if r_in <= 0:
            raise ValueError(f"margin {m:g} leaves no interior in a cylinder of diameter "
                             f"{container['size_m'][0]:g}")
        if axis_index(axis) == 2:
            return Region([c[0] - r_in, c[1] - r_in, lo[2]], [c[0] + r_in, c[1] + r_in, hi[2]],
                          r_in)
        h = r_in / np.sqrt(2.0)
        return Region([c[0] - h, c[1] - h, lo[2]], [c[0] + h, c[1] + h, hi[2]])
    radius = None
    if cylinder:
        radius = 0.5 * float(np.min(np.delete(hi - lo, axis_index(axis))))
    return Region(lo, hi, radius)


def sample_region(packing, *, box=None, margin: float | None = None, cylinder: bool = False,
                  container: dict | None = None, axis="z") -> Region:
    """The flow sample of a packing: an explicit box, or the default interior region.

    Parameters
    ----------
    packing : Packing
    box : 6 floats, optional, m
        ``(xmin, xmax, ymin, ymax, zmin, zmax)`` (the CLIs' ``--sample``); None: the
        interior region of :func:`default_region` with ``margin`` and ``container``.
    cylinder : bool
        The cylinder inscribed in the box, its axis the flow axis.
    axis : {'x', 'y', 'z'} or int

    Examples
    --------
    >>> r = sample_region(None, box=(0, 2, 0, 1, 0, 3), cylinder=True, axis="z")
    >>> r.radius, r.cross_section(2) == 0.25 * 3.141592653589793
    (0.5, True)
    """
    ax = axis_index(axis)
    if box is None:
        reg = default_region(packing, margin=margin, cylinder=cylinder, container=container,
                             axis=ax)
    else:
        b = np.asarray(box, dtype=float)
        if b.shape != (6,):
            raise ValueError(f"a sample box is 6 numbers (xmin xmax ymin ymax zmin zmax), got "
                             f"{box!r}")
        reg = Region(b[0::2], b[1::2])
        if cylinder:
            reg = Region(reg.lo, reg.hi, 0.5 * float(np.min(np.delete(reg.hi - reg.lo, ax))))
    if packing is not None:
        check_inside_bed(packing, reg)
    return reg


def check_inside_bed(packing, region: Region, *, tolerance: float = 1e-9) -> None:
    r"""ValueError, naming the bed's extent, when ``region`` reaches outside the packed bed.

    The bed is the bounding box of the spheres, :math:`[\min(x - r), \max(x + r)]` per axis.
    Outside it there are no grains: a sample reaching there takes in the hull's empty
    tetrahedra (measured: porosity 0.945 and a pressure drop 12 times too high on the bundled
    scene), so it is refused rather than solved.
    """
    lo, hi = packing.extent()
    tol = tolerance * float(np.max(hi - lo))
    out = np.flatnonzero((region.lo < lo - tol) | (region.hi > hi + tol))
    if out.size:
        k = int(out[0])
        raise ValueError(
            f"the sample {'xyz'[k]} {region.lo[k]:.6g}..{region.hi[k]:.6g} reaches outside the "
            f"packed bed, which spans x {lo[0]:.6g}..{hi[0]:.6g}, y {lo[1]:.6g}..{hi[1]:.6g}, "
            f"z {lo[2]:.6g}..{hi[2]:.6g} (m): give a sample inside it")

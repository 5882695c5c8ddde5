r"""Multi-sphere grain templates: a rigid body of overlapping spheres in its body frame.

:func:`template_from_axes` builds a template from three measured kernel axes L >= W >= T
(semi-axes a >= b >= c of the ellipsoid): spheres on stations along the long axis x whose radius
is the ellipsoid's half-thickness there, c(x) = c sqrt(1 - x^2/a^2); where W > T each station
holds a row of q spheres across y at offsets up to b(x) - c(x), so the row spans the ellipsoid's
width. The end stations hold one sphere of radius r* = 2ac^2/(a^2+c^2) at x* = a(a^2-c^2)/(a^2+c^2),
the sphere of the local thickness that just reaches the tip, and a station at x = 0 gives T and W
exactly. So all three axes are exact by construction; the spacing exponent of the inner stations
is chosen to bring the union's volume nearest the ellipsoid's (4/3 pi a b c), then one uniform
scale makes the volume exact, which moves each axis by a third of the remaining volume error.
Derivation, the sphere counts and the measured errors of the bundled grains: ``docs/dem-clumps.md``.

Volumes, centres and inertias are those of the union of the spheres (:mod:`dem._rigid`, QMC
with a stated standard error), never a sum over spheres. Every template is stored in its
principal frame: centroid at the origin, x the long axis (smallest moment of inertia).

:data:`TEMPLATE_GRAINS` are the bundled library grains (axes and sources in :mod:`dem.grains`); a user
template is a CSV ``x,y,z,r`` in the body frame (:func:`read_template`, units mm or m).
A sphere is the one-sphere template (:func:`sphere_template`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from network.core import read_table

from ._rigid import union_mass_properties
from .grains import grain

__all__ = ["Template", "template_from_axes", "sphere_template", "library_template", "read_template",
           "check_template", "resolve_template", "TEMPLATE_GRAINS", "ROW_SPACING", "LIBRARY_MAX_SPHERES"]

#: largest centre spacing of the spheres of one row, in units of their radius (overlap 0.8 r)
ROW_SPACING = 1.2
#: the library grains with bundled templates (axes and sources in dem.grains)
TEMPLATE_GRAINS = ("soybean", "wheat", "shelled_corn", "barley", "canola")


@dataclass(frozen=True)
class Template:
    """A grain: n spheres (body frame, principal axes, centroid at 0) and its union's properties.

    ``inertia_unit`` are the principal moments per unit density (m^5), x the smallest;
    ``extent_m`` the template's length, width, thickness along x, y, z.
    """

    name: str
    positions: np.ndarray
    radii: np.ndarray
    volume_m3: float
    volume_error_m3: float
    inertia_unit: np.ndarray
    source: str = ""
    info: dict = field(default_factory=dict)

    @property
    def n(self):
        return len(self.radii)

    @property
    def extent_m(self):
        return 2 * (np.abs(self.positions) + self.radii[:, None]).max(axis=0)

    @property
    def bounding_radius_m(self):
        return float(np.max(np.linalg.norm(self.positions, axis=1) + self.radii))

    @property
    def equivalent_radius_m(self):
        """Radius of the sphere of the same volume, m."""
        return (3 * self.volume_m3 / (4 * np.pi)) ** (1 / 3)

    def scaled(self, s):
        """The same grain scaled by s (radii, positions; volume s^3, inertia s^5)."""
        return Template(self.name, self.positions * s, self.radii * s, self.volume_m3 * s**3,
                        self.volume_error_m3 * s**3, self.inertia_unit * s**5, self.source, dict(self.info))


def _principal(name, positions, radii, source, info, *, symmetric=False):
    """Template of the spheres moved to their union's principal frame (``symmetric``: the layout is
    mirror-symmetric in x, y and z, so the frame is exact and only the moments are measured)."""
    mp = union_mass_properties(positions, radii)
    if symmetric:
        moments, axes, mp["centroid"] = np.diag(mp["inertia"]).copy(), np.eye(3), np.zeros(3)
    else:
        moments, axes = np.linalg.eigh(mp["inertia"])  # ascending: x = long axis
        if np.linalg.det(axes) < 0:
            axes[:, 2] *= -1
    x = (np.asarray(positions, float) - mp["centroid"]) @ axes
    x[np.abs(x) < 1e-15] = 0.0
    info = dict(info, inertia_error=mp["inertia_error"])
    return Template(name, x, np.asarray(radii, float).copy(), mp["volume"], mp["volume_error"], moments, source, info)


def sphere_template(radius_m=1.0):
    """The one-sphere template (exact volume and inertia)."""
    r = float(radius_m)
    v = 4.0 / 3.0 * np.pi * r**3
    return Template("sphere", np.zeros((1, 3)), np.array([r]), v, 0.0, np.full(3, 0.4 * v * r * r), "")


def _layout(a, b, c, stations, q, q_tip, q_in, gamma, tau, kappa):
    """Sphere centres and radii of the station layout (module notes).

    ``gamma``: spacing exponent of the inner stations; ``tau``: tip radius over r*; ``kappa``:
    inner radius profile c sqrt(1 - x^2/(a^2 - kappa c^2)) (0: the local half-thickness, 1: the
    inscribed sphere of a spheroid), floored at c/4. Rows: ``q`` spheres in the middle, ``q_in`` on
    the inner stations (one sphere there has the row's cross-section area, radius sqrt(b/c) rho <= c),
    ``q_tip`` at the tips.
    """
    r_tip = tau * 2 * a * c * c / (a * a + c * c)
    x_tip = a - r_tip
    half = (stations - 1) // 2
    t = (np.arange(1, half) / half) ** gamma if half > 1 else np.zeros(0)
    big = a * a - kappa * c * c
    rows = [(0.0, c, q)]
    for tk in t:
        rho = c * math.sqrt(max(1 - (x_tip * tk) ** 2 / big, 1 / 16))
        if q_in == 1 and q > 1:
            rho = min(rho * math.sqrt(b / c), c)
        rows += [(-x_tip * tk, rho, q_in), (x_tip * tk, rho, q_in)]
    rows += [(-x_tip, r_tip, q_tip), (x_tip, r_tip, q_tip)]
    pos, rad = [], []
    for x, rho, qk in rows:
        half_w = max(rho * b / c, rho)  # the row spans the width profile b(x)/c(x) = b/c
        for y in (np.linspace(half_w - rho, rho - half_w, qk) if qk > 1 else [0.0]):
            pos.append([x, float(y), 0.0])
            rad.append(rho)
    return np.array(pos), np.array(rad)


def _connected(pos, rad):
    try:
        check_template(pos, rad)
    except ValueError:
        return False
    return True


def template_from_axes(axes_m, *, max_spheres=9, min_spheres=5, name="grain", source="", tolerance=0.02):
    """Template of at most ``max_spheres`` spheres matching measured axes and ellipsoid volume.

    Parameters
    ----------
    axes_m : (3,) length, width, thickness, m (any order; sorted descending)
    max_spheres, min_spheres : int
        Sphere counts allowed (a layout needs at least 2 + q: two tips and the middle row of q).
    tolerance : float
        Largest relative error of any axis or of the volume; ValueError if not reached.

    Returns
    -------
    Template, with ``info`` holding the target axes and volume, the layout and the errors.
    """
    axes = np.sort(np.asarray(axes_m, dtype=float).ravel())[::-1]
    if axes.shape != (3,) or not np.all(np.isfinite(axes)) or not np.all(axes > 0):
        raise ValueError(f"axes must be three positive lengths, got {axes_m}")
    a, b, c = axes / 2
    q = 1 if b / c < 1.02 else 1 + math.ceil(2 * (b / c - 1) / ROW_SPACING)
    layouts = [(m, qt, qi) for m in range(3, 2 * max_spheres, 2) for qt in sorted({1, q}) for qi in sorted({1, q})
               if min_spheres <= 2 * qt + q + (m - 3) * qi <= max_spheres and (qi == q or m > 3)]
    if not layouts:
        raise ValueError(f"axes {axes_m} need rows of {q} spheres: at least {2 + q} spheres, max_spheres is "
                         f"{max_spheres}")
    v_target = 4.0 / 3.0 * np.pi * a * b * c
    best = None
    for m, qt, qi in layouts:
        for gamma in (np.linspace(0.5, 2.5, 9) if m > 3 else [1.0]):
            for tau in np.linspace(0.5, 1.0, 6):
                for kappa in (0.0, 0.5, 1.0):
                    pos, rad = _layout(a, b, c, m, q, qt, qi, gamma, tau, kappa)
                    if not _connected(pos, rad):
                        continue
                    v = union_mass_properties(pos, rad, log2_points=10, replicates=2)["volume"]
                    if best is None or abs(v / v_target - 1) < best[0]:
                        best = (abs(v / v_target - 1), (m, qt, qi, float(gamma), float(tau), kappa), pos, rad)
    if best is None:
        raise ValueError(f"axes {axes_m}: no layout of at most {max_spheres} spheres is one body")
    _, params, pos, rad = best
    raw = union_mass_properties(pos, rad)["volume"]
    s = (v_target / raw) ** (1 / 3)
    info = {"target_axes_m": axes.tolist(), "target_volume_m3": v_target,
            "layout": dict(zip(("stations", "tip_row", "inner_row", "spacing_exponent", "tip_factor", "profile"), params)),
            "row": q, "raw_volume_error": raw / v_target - 1, "scale": s}
    t = _principal(name, pos * s, rad * s, source, info, symmetric=True)
    ax_err = t.extent_m / axes - 1
    t.info.update(axes_error=ax_err.tolist(), volume_error=t.volume_m3 / v_target - 1)
    worst = max(np.abs(ax_err).max(), abs(t.volume_m3 / v_target - 1))
    if worst > tolerance:
        raise ValueError(f"template {name!r}: {t.n} spheres miss the axes or volume by {worst:.1%} "
                         f"> {tolerance:.0%}; allow more spheres (max_spheres)")
    return t


#: sphere counts tried, in order, for a library grain: the default range first (5-9), more only
#: when 9 spheres miss the 2 % (shelled corn: 11, barley: 12; rough rice: none up to 15)
LIBRARY_MAX_SPHERES = (9, 11, 13, 15)


@lru_cache(maxsize=None)
def library_template(name):
    """Template of a library grain from its measured axes (:mod:`dem.grains`, with the source).

    The fewest spheres of :data:`LIBRARY_MAX_SPHERES` that meet the 2 % tolerance.
    """
    g = grain(name)
    if g.axes_mm.value is None:
        raise ValueError(f"grain {g.name!r} has no measured axes in the library ({g.axes_mm.note})")
    src = f"axes {g.axes_mm.value} mm: {g.axes_mm.source}"
    err = None
    for max_spheres in LIBRARY_MAX_SPHERES:
        try:
            return template_from_axes(np.array(g.axes_mm.value) * 1e-3, max_spheres=max_spheres, name=g.name,
                                      source=src)
        except ValueError as e:
            err = e
    raise ValueError(f"grain {g.name!r}: no template of up to {LIBRARY_MAX_SPHERES[-1]} spheres ({err})")


def check_template(positions, radii, *, where="template", first_row=1):
    """ValueError naming the row when radii are not positive/finite, a sphere lies inside another
    (coincident or contained) or the spheres are not one body.

    Rows are numbered from ``first_row`` (2 for a CSV with a header, as a spreadsheet does).
    """
    x = np.asarray(positions, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).ravel()
    if len(r) == 0:
        raise ValueError(f"{where}: no spheres")
    bad = ~(np.all(np.isfinite(x), axis=1) & np.isfinite(r))
    if bad.any():
        raise ValueError(f"{where} row {first_row + int(np.flatnonzero(bad)[0])}: not a finite number")
    bad = ~(r > 0)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{where} row {first_row + k}: radius {r[k]:g} must be positive")
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    inside = (d + r[None] <= r[:, None] * (1 + 1e-12)) & ~np.eye(len(r), dtype=bool)
    if inside.any():            # row j within row i: a coincident or contained sphere
        big, small = np.argwhere(inside)[0]
        if r[small] == r[big] and small < big:
            big, small = small, big
        raise ValueError(f"{where} row {first_row + int(small)}: the sphere lies inside the sphere "
                         f"of row {first_row + int(big)} (coincident or contained spheres add "
                         "nothing to the grain): remove it")
    i, j = np.nonzero(d < r[:, None] + r[None])
    _, label = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(len(r), len(r))), directed=False)
    apart = np.flatnonzero(label != label[0])
    if len(apart):
        raise ValueError(f"{where} row {first_row + int(apart[0])}: sphere does not overlap into one body with "
                         f"row {first_row} (spheres of a grain must overlap)")


#: Smallest grain (largest extent, m) a template read in mm may describe: below it the file is
#: taken to be in metres (a 2 mm kernel written in metres and read in mm is 0.002 mm across)
MIN_TEMPLATE_EXTENT_M = 50e-6


def read_template(path, *, units="mm", name=None, option="--grain"):
    """A user template: CSV with columns ``x,y,z,r`` in the body frame, ``units`` 'mm' or 'm'.

    Read as spreadsheets write it (:func:`network.core.read_table`: BOM, CRLF, quoted header,
    spaces after separators; columns in any order, extra ones ignored). Errors name ``option``,
    the file and the row (header = row 1); a grain under :data:`MIN_TEMPLATE_EXTENT_M` across
    read in mm is refused with the unit it is probably in. The template is moved to its
    principal frame.
    """
    scale = {"mm": 1e-3, "m": 1.0}.get(units)
    if scale is None:
        raise ValueError(f"template units must be 'mm' or 'm', got {units!r}")
    path = Path(path)
    where = f"{option} {path}"
    try:
        header, table = read_table(path, option, what="a grain template")
    except ValueError as e:
        if "empty file" not in str(e):
            raise
        header, table = [], []
    names = [h.lower() for h in header]
    if not all(c in names for c in "xyzr"):
        got = ",".join(header) if header else "an empty file"
        raise ValueError(f"{where} row 1: expected the header 'x,y,z,r', got {got!r}")
    cols = [names.index(c) for c in "xyzr"]
    rows = []
    for k, fields in table:
        try:
            vals = [float(fields[c]) for c in cols] if len(fields) == len(names) else []
        except ValueError:
            vals = []
        if len(vals) != 4:
            raise ValueError(f"{where} row {k}: expected four numbers x,y,z,r, got "
                             f"{','.join(fields)!r}")
        rows.append((k, vals))
    if not rows:
        raise ValueError(f"{where}: no spheres (empty template)")
    data = np.array([v for _, v in rows])
    row_no = [k for k, _ in rows]
    try:  # checked in the file's units, so the message quotes the file's numbers
        check_template(data[:, :3], data[:, 3], where=where, first_row=0)
    except ValueError as e:  # renumber the rows as the file's
        msg = str(e)
        for idx in sorted({int(t.split(":")[0].split(" ")[0]) for t in msg.split(" row ")[1:]},
                          reverse=True):
            msg = msg.replace(f" row {idx}:", f" row {row_no[idx]}:").replace(
                f"of row {idx} ", f"of row {row_no[idx]} ").replace(
                f"with row {idx} ", f"with row {row_no[idx]} ")
        raise ValueError(msg) from None
    extent = float(np.max(np.ptp(data[:, :3], axis=0) + 2 * data[:, 3].max())) * scale
    if units == "mm" and extent < MIN_TEMPLATE_EXTENT_M:
        raise ValueError(f"{where}: the grain is {extent * 1e3:.3g} mm across read in mm "
                         f"(--template-units mm): a template written in metres? give "
                         f"--template-units m")
    data = data * scale
    return _principal(name or path.stem, data[:, :3], data[:, 3], f"user file {path} ({units})", {})


def resolve_template(spec, *, units="mm"):
    """``spec``: a library grain name, ``'sphere'``, or a path to a template CSV."""
    if str(spec) == "sphere":
        return sphere_template(1.0)
    if Path(str(spec)).suffix.lower() == ".csv" or Path(str(spec)).exists():
        return read_template(spec, units=units)
    return library_template(grain(str(spec)).name)

r"""The bin's geometry and its gmsh mesh: axisymmetric (r-z triangles) or 3-D (tetrahedra).

A round bin of diameter B (radius R) and eave depth D (grain depth at the wall). The grain
surface z_s(r) is

- ``flat``: z_s = D;
- ``peaked``: a cone at the angle θ, z_s = D + (R - r) tan θ (centre filling at the angle of
  repose);
- ``inverted``: an inverted cone, z_s = D - (R - r) tan θ (after unloading from the centre).

The floor is fully perforated (``full``: the whole floor is the plenum) or solid with ducts
(``duct``): straight perforated ducts lying on the floor along x, each of diameter d, length L
from the wall where the fan feeds it, axis at y = offset; ``round`` (a full cylinder; its axis
sits at 0.45 d, so the duct meets the floor at an angle, not in the zero-angle cusp of a
tangent cylinder, which no mesh resolves) or ``half-round`` (axis on the floor: a half cylinder).
The duct's inner end is a closed cap. A bin without ducts is axisymmetric (r-z); with ducts 3-D.

Boundary nodes are classified from the CAD entities gmsh meshes: plenum (the full floor or a
duct's perforated surface, fan static pressure), surface (the grain surface, atmospheric),
everything else closed (wall, solid floor, duct caps, the axis r = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Duct", "BinGeometry", "Mesh", "mesh_bin", "mesh_rz_polygon", "ROUND_DUCT_AXIS"]

#: growth of the element size with the distance from a duct (m per m): h = h_duct + 0.15 dist
DUCT_GRADING = 0.15
#: the end cap's edge: the duct size divided by this
CAP_REFINE = 8.0
#: height of a round duct's axis above the floor, in duct diameters (0.5 would be tangent)
ROUND_DUCT_AXIS = 0.45
TOPS = ("flat", "peaked", "inverted")
FLOORS = ("full", "duct")
DUCT_SHAPES = ("round", "half-round")


@dataclass(frozen=True)
class Duct:
    """A perforated floor duct along x: diameter and length (m), axis offset y (m), shape."""

    diameter_m: float
    length_m: float
    offset_m: float = 0.0
    shape: str = "half-round"

    def axis_height_m(self) -> float:
        """Height of the duct's axis above the floor, m."""
        return ROUND_DUCT_AXIS * self.diameter_m if self.shape == "round" else 0.0


@dataclass(frozen=True)
class BinGeometry:
    """Round bin: diameter, eave depth (m), top shape and angle (degrees), floor and ducts.

    ``__post_init__`` checks every value (ValueError naming it).
    """

    diameter_m: float
    depth_m: float
    top: str = "flat"
    peak_angle_deg: float = 0.0
    floor: str = "full"
    ducts: tuple = field(default_factory=tuple)

    def __post_init__(self):
        for name in ("diameter_m", "depth_m"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                opt = "--diameter" if name == "diameter_m" else "--depth"
                raise ValueError(f"{opt} must be finite and > 0, got {v!r}")
        if self.top not in TOPS:
            raise ValueError(f"--top {self.top!r}: use one of {', '.join(TOPS)}")
        if self.floor not in FLOORS:
            raise ValueError(f"--floor {self.floor!r}: use one of {', '.join(FLOORS)}")
        if self.top != "flat":
            a = self.peak_angle_deg
            if not (np.isfinite(a) and 0 < a < 90):
                raise ValueError(f"--peak-angle must be in (0, 90) degrees, got {a!r}")
            drop = self.radius_m * math.tan(math.radians(a))
            if self.top == "inverted" and drop >= 0.95 * self.depth_m:
                raise ValueError(
                    f"--top inverted at {a:g} degrees drops {drop:.3g} m at the centre, not less "
                    f"than 95 % of --depth {self.depth_m:g} m: the cone would reach the floor")
        if self.floor == "duct" and not self.ducts:
            raise ValueError("--floor duct needs at least one --duct DIAMETER LENGTH OFFSET")
        if self.floor == "full" and self.ducts:
            raise ValueError("--duct given with --floor full: give --floor duct")
        for i, d in enumerate(self.ducts):
            self._check_duct(i, d)

    def _check_duct(self, i, d: Duct):
        tag = f"--duct {i + 1} ({d.diameter_m:g} {d.length_m:g} {d.offset_m:g})"
        if d.shape not in DUCT_SHAPES:
            raise ValueError(f"--duct-shape {d.shape!r}: use one of {', '.join(DUCT_SHAPES)}")
        for what, v in (("diameter", d.diameter_m), ("length", d.length_m)):
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{tag}: {what} must be finite and > 0, got {v!r}")
        if not np.isfinite(d.offset_m):
            raise ValueError(f"{tag}: offset must be finite, got {d.offset_m!r}")
        if abs(d.offset_m) + d.diameter_m / 2 >= self.radius_m:
            raise ValueError(f"{tag}: the duct lies outside the floor (|offset| + diameter/2 = "
                             f"{abs(d.offset_m) + d.diameter_m / 2:g} m >= the bin's radius "
                             f"{self.radius_m:g} m)")
        chord = 2 * math.sqrt(self.radius_m**2 - d.offset_m**2)
        if d.length_m > chord * (1 + 1e-9):
            raise ValueError(f"{tag}: length {d.length_m:g} m is longer than the bin along "
                             f"the duct ({chord:.4g} m at offset {d.offset_m:g} m)")
        if d.length_m < 2 * d.diameter_m:
            raise ValueError(f"{tag}: length {d.length_m:g} m is under two diameters")
        top = d.axis_height_m() + d.diameter_m / 2
        if top >= 0.8 * self.lowest_surface_m:
            raise ValueError(f"{tag}: the duct's top {top:g} m is not below 80 % of the grain's "
                             f"lowest surface height {self.lowest_surface_m:.4g} m")
        for j, e in enumerate(self.ducts[:i]):
            if abs(d.offset_m - e.offset_m) < (d.diameter_m + e.diameter_m) / 2:
                raise ValueError(f"{tag} overlaps --duct {j + 1}")

    @property
    def radius_m(self) -> float:
        return 0.5 * self.diameter_m

    @property
    def axisymmetric(self) -> bool:
        """True without ducts: the problem is r-z."""
        return self.floor == "full"

    @property
    def slope(self) -> float:
        """tan θ of the cone (0 flat)."""
        return 0.0 if self.top == "flat" else math.tan(math.radians(self.peak_angle_deg))

    def surface_height(self, r):
        """z_s(r), m: the grain surface's height at radius r (m)."""
        r = np.asarray(r, dtype=float)
        s = {"flat": 0.0, "peaked": 1.0, "inverted": -1.0}[self.top] * self.slope
        return self.depth_m + s * (self.radius_m - r)

    @property
    def lowest_surface_m(self) -> float:
        return float(min(self.surface_height(0.0), self.depth_m))

    @property
    def grain_volume_m3(self) -> float:
        """Volume of the grain, m³ (the ducts' volume not taken out)."""
        r = self.radius_m
        cone = math.pi * r**2 * (r * self.slope) / 3.0
        return math.pi * r**2 * self.depth_m + {"flat": 0.0, "peaked": cone,
                                               "inverted": -cone}[self.top]

    def as_json(self) -> dict:
        return {"diameter_m": self.diameter_m, "depth_m": self.depth_m, "top": self.top,
                "peak_angle_deg": None if self.top == "flat" else self.peak_angle_deg,
                "floor": self.floor, "axisymmetric": self.axisymmetric,
                "ducts": [{"diameter_m": d.diameter_m, "length_m": d.length_m,
                           "offset_m": d.offset_m, "shape": d.shape,
                           "axis_height_m": d.axis_height_m()} for d in self.ducts],
                "grain_volume_m3": self.grain_volume_m3}


@dataclass(frozen=True)
class Mesh:
    """Nodes (dim, N) m, elements (dim + 1, Ne), node indices at the fan's pressure (plenum)
    and at atmospheric pressure (surface); ``axisymmetric``: coordinates are (r, z)."""

    points: np.ndarray
    cells: np.ndarray
    plenum: np.ndarray
    surface: np.ndarray
    axisymmetric: bool
    size_m: float

    @property
    def n_elements(self) -> int:
        return int(self.cells.shape[1])


def _gmsh():
    """gmsh, initialised, with an empty model and every option at gmsh's default (another
    mesher in the process, the throats' second-order triangles, leaves its own options set:
    a bin mesh depends on none of them), quiet and on one thread."""
    import gmsh

    if not gmsh.isInitialized():
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    gmsh.option.restoreDefaults()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.clear()
    return gmsh


def _elements(gmsh, dim):
    tags, coords, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    lookup = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    lookup[tags[order]] = np.arange(tags.size)
    pts = coords.reshape(-1, 3)[order][:, :dim].T.copy()
    etypes, _, enodes = gmsh.model.mesh.getElements(dim)
    nv = dim + 1
    cells = np.concatenate([lookup[n.astype(np.int64)].reshape(-1, nv) for n, t in
                            zip(enodes, etypes)]).T
    return pts, lookup, np.ascontiguousarray(cells)


def _entity_nodes(gmsh, lookup, dim, tags):
    out = [np.empty(0, dtype=np.int64)]
    for t in tags:
        n, _, _ = gmsh.model.mesh.getNodes(dim, t, includeBoundary=True)
        out.append(lookup[n.astype(np.int64)])
    return np.unique(np.concatenate(out))


def mesh_rz_polygon(vertices, edge_kinds, size_m, *, size_field=None):
    """Triangular mesh of a polygon in the r-z half plane.

    Parameters
    ----------
    vertices : (n, 2) array_like, m
        Corners (r, z), counter-clockwise.
    edge_kinds : sequence of str, length n
        ``"plenum"``, ``"surface"`` or ``"closed"`` for the edge from corner i to i + 1.
    size_m : float
        Target element size, m.
    size_field : (float, float, float, float), optional
        (r, z, near size, radius): smaller elements around a point (gmsh threshold field).
    """
    gmsh = _gmsh()
    try:
        geo = gmsh.model.geo
        v = np.asarray(vertices, dtype=float)
        pts = [geo.addPoint(r, z, 0.0, size_m) for r, z in v]
        lines = [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
        loop = geo.addCurveLoop(lines)
        geo.addPlaneSurface([loop])
        geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size_m)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)
        p, lookup, t = _elements(gmsh, 2)
        kinds = list(edge_kinds)
        plenum = _entity_nodes(gmsh, lookup, 1, [ln for ln, k in zip(lines, kinds)
                                                if k == "plenum"])
        surface = _entity_nodes(gmsh, lookup, 1, [ln for ln, k in zip(lines, kinds)
                                                 if k == "surface"])
    finally:
        gmsh.clear()
    surface = np.setdiff1d(surface, plenum)
    return Mesh(p, t, plenum, surface, True, float(size_m))


def _mesh_rz(geom: BinGeometry, size_m: float) -> Mesh:
    r, d = geom.radius_m, geom.depth_m
    zc = float(geom.surface_height(0.0))
    return mesh_rz_polygon([(0.0, 0.0), (r, 0.0), (r, d), (0.0, zc)],
                           ["plenum", "closed", "surface", "closed"], size_m)


def _mesh_3d(geom: BinGeometry, size_m: float, duct_size_m: float) -> Mesh:
    gmsh = _gmsh()
    occ = gmsh.model.occ
    r, d = geom.radius_m, geom.depth_m
    try:
        body = [(3, occ.addCylinder(0, 0, 0, 0, 0, d, r))]
        h = r * geom.slope
        if geom.top == "peaked":
            cone = occ.addCone(0, 0, d, 0, 0, h, r, 0.0)
            body, _ = occ.fuse(body, [(3, cone)])
        elif geom.top == "inverted":
            cone = occ.addCone(0, 0, d, 0, 0, -h, r, 0.0)
            body, _ = occ.cut(body, [(3, cone)])
        tools, cap_x = [], []
        for duct in geom.ducts:
            half = math.sqrt(r**2 - duct.offset_m**2)
            x0 = -half - 0.1 * r
            x1 = -half + duct.length_m
            if duct.length_m >= 2 * half * (1 - 1e-9):
                x1 = half + 0.1 * r
            else:
                cap_x.append(x1)
            tools.append((3, occ.addCylinder(x0, duct.offset_m, duct.axis_height_m(), x1 - x0,
                                             0, 0, duct.diameter_m / 2)))
        if tools:
            body, _ = occ.cut(body, tools)
        occ.synchronize()
        duct_faces = []
        surfaces = gmsh.model.getEntities(2)
        kinds = {}
        for _, tag in surfaces:
            kinds[tag] = _classify(gmsh, geom, tag)
            if kinds[tag] == "plenum":
                duct_faces.append(tag)
        if duct_faces:
            near = min(size_m, duct_size_m)
            f = gmsh.model.mesh.field

            def graded(kind, tags, h0):
                fd = f.add("Distance")
                f.setNumbers(fd, kind, tags)
                ft = f.add("Threshold")
                f.setNumber(ft, "InField", fd)
                f.setNumber(ft, "SizeMin", h0)
                f.setNumber(ft, "SizeMax", size_m)
                f.setNumber(ft, "DistMin", 0.0)
                f.setNumber(ft, "DistMax", max(size_m - h0, 0.0) / DUCT_GRADING + 1e-9)
                return ft

            fields = [graded("SurfacesList", duct_faces, near)]
            # the circle where a duct's closed end cap meets its perforated surface: a
            # Dirichlet-Neumann corner of 270 degrees on the air's side, where the pressure
            # gradient is singular (r^(-2/3)); refined to a third of the duct size
            tol = 1e-6 * geom.diameter_m
            edges = []
            for _, c in gmsh.model.getEntities(1):
                x0, _, _, x1, _, _ = gmsh.model.getBoundingBox(1, c)
                if x1 - x0 < tol and any(abs(x0 - e) < 1e3 * tol for e in cap_x):
                    edges.append(c)
            if edges:
                fields.append(graded("CurvesList", edges, near / CAP_REFINE))
            fmin = f.add("Min")
            f.setNumbers(fmin, "FieldsList", fields)
            f.setAsBackgroundMesh(fmin)
            gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
            gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size_m)
        gmsh.model.mesh.generate(3)
        p, lookup, t = _elements(gmsh, 3)
        plenum = _entity_nodes(gmsh, lookup, 2, [k for k, v in kinds.items() if v == "plenum"])
        surface = _entity_nodes(gmsh, lookup, 2, [k for k, v in kinds.items()
                                                  if v == "surface"])
    finally:
        gmsh.clear()
    used = np.unique(t)
    if used.size != p.shape[1]:         # nodes of no tetrahedron (none expected): renumber
        new = -np.ones(p.shape[1], dtype=np.int64)
        new[used] = np.arange(used.size)
        p, t = p[:, used], new[t]
        plenum, surface = new[plenum], new[surface]
        plenum, surface = plenum[plenum >= 0], surface[surface >= 0]
    surface = np.setdiff1d(surface, plenum)
    return Mesh(p, t, plenum, surface, False, float(size_m))


def _classify(gmsh, geom: BinGeometry, tag: int) -> str:
    """plenum / surface / closed for one CAD surface, from points sampled on it."""
    umin, umax = gmsh.model.getParametrizationBounds(2, tag)
    uu = np.linspace(0.1, 0.9, 4)
    par = np.array([[umin[0] + a * (umax[0] - umin[0]), umin[1] + b * (umax[1] - umin[1])]
                    for a in uu for b in uu]).ravel()
    xyz = np.asarray(gmsh.model.getValue(2, tag, par)).reshape(-1, 3)
    # a trimmed surface's parametric box may hold points outside it: keep those on it
    x, y, z = xyz.T
    rr = np.hypot(x, y)
    tol = 1e-6 * max(geom.diameter_m, geom.depth_m)
    inside = (rr <= geom.radius_m + tol) & (z >= -tol) & (z <= geom.surface_height(
        np.minimum(rr, geom.radius_m)) + tol)
    x, y, z, rr = x[inside], y[inside], z[inside], rr[inside]
    if x.size == 0:
        return "closed"
    if np.all(np.abs(z - geom.surface_height(rr)) < 1e-5 * geom.depth_m) and np.all(z > tol):
        return "surface"
    for du in geom.ducts:
        dist = np.hypot(y - du.offset_m, z - du.axis_height_m())
        if np.all(np.abs(dist - du.diameter_m / 2) < 1e-5 * du.diameter_m):
            return "plenum"
    return "closed"


def default_size(geom: BinGeometry, elements: int) -> float:
    """Element size, m, that gives about ``elements`` elements (triangles in r-z: area / 0.45 h²;
    tetrahedra: 4.6 per h³, measured on gmsh's meshes of a bin)."""
    if geom.axisymmetric:
        area = geom.radius_m * 0.5 * (geom.depth_m + float(geom.surface_height(0.0))) \
            if geom.top != "flat" else geom.radius_m * geom.depth_m
        return math.sqrt(area / (0.45 * elements))
    return (4.6 * geom.grain_volume_m3 / elements) ** (1.0 / 3.0)


def duct_size(geom: BinGeometry, size_m: float) -> float:
    """Element size on the ducts, m: a tenth of the narrowest duct's diameter, at most
    ``size_m``."""
    return min([size_m] + [d.diameter_m / 10 for d in geom.ducts])


def mesh_bin(geom: BinGeometry, size_m: float, *, duct_size_m: float | None = None) -> Mesh:
    """The bin's mesh with its plenum and surface nodes: r-z triangles when axisymmetric,
    else tetrahedra (gmsh, OpenCASCADE booleans for the cone and the ducts), refined to
    ``duct_size_m`` (default :func:`duct_size`) on the ducts."""
    if not (np.isfinite(size_m) and size_m > 0):
        raise ValueError(f"--mesh-size must be finite and > 0, got {size_m!r}")
    if duct_size_m is None:
        duct_size_m = duct_size(geom, size_m)
    mesh = (_mesh_rz(geom, size_m) if geom.axisymmetric
            else _mesh_3d(geom, size_m, duct_size_m))
    if mesh.plenum.size == 0 or mesh.surface.size == 0:
        raise RuntimeError(f"the mesh has {mesh.plenum.size} plenum and {mesh.surface.size} "
                           "surface nodes: the boundary was not recognised")
    return mesh

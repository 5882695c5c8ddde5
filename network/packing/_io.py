"""Reading sphere packings: delimited text ``x,y,z,r``, ``.npz`` and LAMMPS/LIGGGHTS dumps.

A packing is a table of sphere centres (N, 3) and radii (N,), in metres: a file in mm or cm
is read with ``units``. Every reader validates at the door and names the
offending line (1-based, as an editor shows it) in its ``ValueError``.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["Packing", "read_packing", "write_packing_csv", "MIN_SPHERES", "default_packing_path",
           "read_container", "scale_warning", "UNITS", "FORMATS", "PLAUSIBLE_DIAMETER_M"]

log = logging.getLogger(__name__)

def default_packing_path() -> Path:
    """The bundled soybean-like scene, ``network/data/soybean_default.csv`` (see its README)."""
    return Path(__file__).resolve().parents[1] / "data" / "soybean_default.csv"


#: Fewest spheres that make a three-dimensional Delaunay tessellation with an interior.
MIN_SPHERES = 5


@dataclasses.dataclass(frozen=True)
class Packing:
    """A sphere packing.

    Attributes
    ----------
    centers : (N, 3) ndarray of float, m
        Sphere centres.
    radii : (N,) ndarray of float, m
        Sphere radii, all > 0.
    source : str
        Where the packing came from (a path, or a short description); informative only.
    """

    centers: np.ndarray
    radii: np.ndarray
    source: str = ""

    def __post_init__(self):
        try:
            c = np.asarray(self.centers, dtype=float)
            r = np.asarray(self.radii, dtype=float)
        except (TypeError, ValueError) as e:
            raise TypeError(f"centers and radii must be numeric arrays: {e}") from e
        if c.ndim != 2 or c.shape[1] != 3:
            raise ValueError(f"centers must have shape (N, 3), got {c.shape}")
        if r.shape != (c.shape[0],):
            raise ValueError(f"radii must have shape ({c.shape[0]},), got {r.shape}")
        c.setflags(write=False)
        r.setflags(write=False)
        object.__setattr__(self, "centers", c)
        object.__setattr__(self, "radii", r)

    @property
    def n(self) -> int:
        """Number of spheres."""
        return int(self.radii.shape[0])

    @property
    def mean_diameter(self) -> float:
        """Arithmetic mean sphere diameter, m."""
        return float(2.0 * self.radii.mean())

    def bounds(self) -> np.ndarray:
        """(2, 3) array: lowest and highest centre coordinate along x, y, z (m)."""
        return np.stack([self.centers.min(axis=0), self.centers.max(axis=0)])


def _validate(centers, radii, lines, source, *, check_duplicates=True):
    """Check finite values, positive radii, distinct centres and enough spheres.

    ``lines[i]`` is the 1-based file line (or array row) that sphere i came from.
    """
    n = len(radii)
    if n < MIN_SPHERES:
        raise ValueError(f"{source}: too few spheres ({n}); a packing needs at least {MIN_SPHERES}")
    bad = ~np.isfinite(centers).all(axis=1) | ~np.isfinite(radii)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: line {lines[i]}: non-finite value (NaN or inf) "
                         f"in x,y,z,r = {centers[i].tolist() + [float(radii[i])]}")
    bad = radii <= 0
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{source}: line {lines[i]}: radius must be > 0, got {radii[i]!r}")
    if check_duplicates:
        order = np.lexsort(centers.T[::-1])
        s = centers[order]
        dup = np.all(s[1:] == s[:-1], axis=1)
        if dup.any():
            k = int(np.flatnonzero(dup)[0])
            a, b = sorted((int(order[k]), int(order[k + 1])))
            raise ValueError(f"{source}: line {lines[b]}: duplicate centre {centers[b].tolist()} "
                             f"(same as line {lines[a]})")


def _parse_rows(rows, ncols, first_line, source):
    """Parse whitespace/comma split rows into floats, naming the first bad line."""
    out = np.empty((len(rows), ncols))
    for k, fields in enumerate(rows):  # parsing is I/O-bound; the loop runs once per line
        if len(fields) != ncols:
            raise ValueError(f"{source}: line {first_line[k]}: expected {ncols} values, "
                             f"got {len(fields)}: {','.join(fields)!r}")
        try:
            out[k] = [float(f) for f in fields]
        except ValueError as e:
            raise ValueError(f"{source}: line {first_line[k]}: not a number in "
                             f"{','.join(fields)!r}") from e
    return out


#: Header names of the radius column (``diameter`` names are halved).
_RADIUS_NAMES = ("r", "radius", "rad")
_DIAMETER_NAMES = ("d", "diameter", "diam")


def _delimiter(line: str):
    """',' or ';' when the line holds one, else None (any run of spaces or tabs)."""
    for d in (",", ";"):
        if d in line:
            return d
    return None


def _split(line: str, delim):
    return [f.strip() for f in (line.split(delim) if delim else line.split())]


def _read_csv(path: Path) -> Packing:
    """Delimited text: comma, semicolon, or spaces/tabs (YADE's ``export.text``: ``#`` comment
    lines, then ``x y z r`` rows); an optional header names x, y, z and r/radius/diameter."""
    src = str(path)
    text = path.read_text(errors="replace").splitlines()
    lines = [(i + 1, ln.strip()) for i, ln in enumerate(text)]
    lines = [(i, ln) for i, ln in lines if ln and not ln.startswith("#")]
    if not lines:
        raise ValueError(f"{src}: empty file (no data line)")
    head_no, head = lines[0]
    delim = _delimiter(head)
    names = [h.lower() for h in _split(head, delim)]
    scale = 1.0
    if any(not _isfloat(h) for h in names):
        rname = [c for c in _RADIUS_NAMES + _DIAMETER_NAMES if c in names]
        missing = [c for c in ("x", "y", "z") if c not in names] + ([] if rname else ["r"])
        if missing:
            raise ValueError(f"{src}: line {head_no}: header {head!r} lacks column(s) "
                             f"{missing}; expected x, y, z and r (or radius, or diameter)")
        cols = [names.index(c) for c in ("x", "y", "z")] + [names.index(rname[0])]
        scale = 0.5 if rname[0] in _DIAMETER_NAMES else 1.0
        body = lines[1:]
        if not body:
            raise ValueError(f"{src}: no data line after the header")
    else:  # no header: x, y, z, r in that order
        cols = [0, 1, 2, 3]
        body = lines
    ncols = len(names)
    if ncols < 4:
        raise ValueError(f"{src}: line {head_no}: expected at least 4 columns (x y z r), got "
                         f"{ncols}: {head!r}")
    fast = None
    try:
        fast = np.loadtxt([ln for _, ln in body], delimiter=delim, ndmin=2)
    except ValueError:
        fast = None
    if fast is None or fast.shape[1] != ncols:
        fast = _parse_rows([_split(ln, delim) for _, ln in body], ncols,
                           [i for i, _ in body], src)
    data = fast[:, cols]
    lineno = np.array([i for i, _ in body])
    _validate(data[:, :3], data[:, 3] * scale, lineno, src)
    return Packing(data[:, :3], data[:, 3] * scale, source=src)


def _isfloat(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _read_npz(path: Path) -> Packing:
    src = str(path)
    with np.load(path) as z:
        missing = [k for k in ("centers", "radii") if k not in z.files]
        if missing:
            raise ValueError(f"{src}: missing array(s) {missing}; found {z.files}")
        c = np.asarray(z["centers"], dtype=float)
        r = np.asarray(z["radii"], dtype=float).ravel()
    if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] != r.shape[0]:
        raise ValueError(f"{src}: centers {c.shape} and radii {r.shape} must be (N, 3) and (N,)")
    _validate(c, r, np.arange(1, len(r) + 1), f"{src} (row)")
    return Packing(c, r, source=src)


def _read_dump(path: Path) -> Packing:
    """LAMMPS/LIGGGHTS ``dump custom`` text; the last snapshot in the file is read."""
    src = str(path)
    text = path.read_text().splitlines()
    starts = [i for i, ln in enumerate(text) if ln.startswith("ITEM: ATOMS")]
    if not starts:
        raise ValueError(f"{src}: no 'ITEM: ATOMS' line: not a LAMMPS/LIGGGHTS dump custom file")
    s = starts[-1]
    cols = text[s].split()[2:]
    # number of atoms of this snapshot
    n = None
    for j in range(s - 1, -1, -1):
        if text[j].startswith("ITEM: NUMBER OF ATOMS"):
            try:
                n = int(text[j + 1].split()[0])
            except (IndexError, ValueError) as e:
                raise ValueError(f"{src}: line {j + 2}: bad atom count") from e
            break
    xyz = []
    for names in (("x", "xu", "xs"), ("y", "yu", "ys"), ("z", "zu", "zs")):
        hit = [c for c in names if c in cols]
        if not hit:
            raise ValueError(f"{src}: line {s + 1}: ATOMS columns {cols} lack {names[0]}")
        xyz.append(cols.index(hit[0]))
    rname = [c for c in ("radius", "r", "diameter") if c in cols]
    if not rname:
        raise ValueError(f"{src}: line {s + 1}: ATOMS columns {cols} lack 'radius' (or 'diameter')")
    rcol = cols.index(rname[0])
    body = []
    for j in range(s + 1, len(text)):
        if text[j].startswith("ITEM:"):
            break
        if text[j].strip():
            body.append((j + 1, text[j].split()))
    if n is not None and len(body) != n:
        raise ValueError(f"{src}: line {s + 1}: header says {n} atoms, found {len(body)} rows")
    data = _parse_rows([f for _, f in body], len(cols), [i for i, _ in body], src)
    c = data[:, xyz]
    r = data[:, rcol] * (0.5 if rname[0] == "diameter" else 1.0)
    if any(cols[k].endswith("s") for k in xyz):
        raise ValueError(f"{src}: line {s + 1}: scaled coordinates (xs ys zs) are not supported; "
                         "dump x y z or xu yu zu")
    lineno = np.array([i for i, _ in body])
    _validate(c, r, lineno, src)
    return Packing(c, r, source=src)


def read_packing(path: str | os.PathLike, *, units: str = "m") -> Packing:
    """Read a sphere packing from a file, in metres.

    Parameters
    ----------
    path : str or path-like
        Formats (:data:`FORMATS`): delimited text (``*.csv``, ``*.txt``, ...: comma, semicolon,
        or spaces/tabs, as YADE's ``export.text`` writes; an optional header naming x, y, z and
        r, radius or diameter in any order, extra columns ignored; without a header the columns
        are x, y, z, r; ``#`` comments allowed); ``*.npz`` with arrays ``centers`` (N, 3) and
        ``radii`` (N,); LAMMPS/LIGGGHTS ``dump custom`` text (``x y z radius`` columns, the
        last snapshot).
    units : {'m', 'mm', 'cm'}, keyword-only
        Unit of the file's lengths (default metres); the packing is returned in metres.

    Returns
    -------
    Packing
        Centres and radii, m.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    ValueError
        Malformed content, NaN/inf, non-positive radii, duplicate centres or fewer than
        ``MIN_SPHERES`` spheres; the message names the file and line.
    """
    if units not in UNITS:
        raise ValueError(f"unknown length unit {units!r}; choose one of {', '.join(UNITS)}")
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"packing file not found: {p}")
    suffix = p.suffix.lower()
    if suffix == ".npz":
        if not zipfile.is_zipfile(p):
            raise ValueError(f"{p}: not a .npz (zip) archive; formats read: {'; '.join(FORMATS)}")
        try:
            pk = _read_npz(p)
        except (OSError, EOFError, zipfile.BadZipFile) as e:
            raise ValueError(f"{p}: not a readable .npz file ({e}); formats read: "
                             f"{'; '.join(FORMATS)}") from e
    else:
        with open(p, "rb") as f:
            head = f.read(65536)
        if b"\0" in head:
            raise ValueError(f"{p}: a binary file, not a packing; formats read: "
                             f"{'; '.join(FORMATS)}")
        if b"ITEM: ATOMS" in head or b"ITEM: TIMESTEP" in head:
            pk = _read_dump(p)
        else:
            pk = _read_csv(p)
    if units != "m":
        f = UNITS[units]
        pk = Packing(pk.centers * f, pk.radii * f, source=f"{pk.source} ({units})")
    log.info("read %d spheres from %s", pk.n, p)
    return pk


#: Length units a packing file may be written in, with their factor to metres.
UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
#: Formats :func:`read_packing` reads, for error messages.
FORMATS = ("delimited text x,y,z,r (comma, semicolon, spaces or tabs; YADE export.text)",
           ".npz with centers and radii", "LAMMPS/LIGGGHTS dump custom")
#: Mean grain diameters (m) outside which a packing is probably not in metres.
PLAUSIBLE_DIAMETER_M = (0.5e-3, 50e-3)


def scale_warning(packing: Packing) -> str | None:
    """A one-line warning when the mean diameter is outside 0.5-50 mm (not metres?), else None.

    >>> scale_warning(Packing(np.eye(3) * 10, np.full(3, 3.3)))[:40]
    'mean grain diameter 6.6 m is outside 0.5'
    """
    d = packing.mean_diameter
    lo, hi = PLAUSIBLE_DIAMETER_M
    if lo <= d <= hi:
        return None
    return (f"mean grain diameter {d:.3g} m is outside 0.5-50 mm, the range of grains: if the "
            f"file is not in metres, give --units mm or --units cm (a dimensionless packing "
            f"is fine with --viscosity 1)")


def read_container(path: str | os.PathLike) -> dict | None:
    """The container of a packing from its companion JSON (same name, ``.json``), if any.

    The DEM writes ``{"container": {"kind": "cylinder" | "box", "size_m": [...], ...}}`` beside
    its CSV (DESIGN: containers are described in the companion JSON or on the command line).

    Returns
    -------
    dict or None
        ``{"kind": ..., "size_m": [...], "center_xy": [x, y] (if known)}``; None when there is
        no companion JSON or it has no usable ``container`` entry (logged).
    """
    import json

    p = Path(path).with_suffix(".json")
    if not p.is_file():
        return None
    try:
        meta = json.loads(p.read_text())
        cont = dict(meta["container"])
        kind = str(cont["kind"]).lower()
        size = [float(v) for v in np.atleast_1d(cont["size_m"])]
    except (ValueError, KeyError, TypeError) as e:
        log.warning("companion JSON %s has no usable 'container' entry (%s): ignored", p, e)
        return None
    out = {"kind": kind, "size_m": size, "source": str(p)}
    centre = cont.get("center_xy") or (meta.get("interior_region") or {}).get("center_xy")
    if centre is not None:
        out["center_xy"] = [float(v) for v in centre][:2]
    return out


def write_packing_csv(packing: Packing, path: str | os.PathLike, *, digits: int = 7) -> None:
    """Write a packing as CSV ``x,y,z,r`` with ``digits`` significant digits."""
    data = np.column_stack([packing.centers, packing.radii])
    np.savetxt(path, data, delimiter=",", header="x,y,z,r", comments="", fmt=f"%.{digits}g")

"""Packing files: reading delimited text ``x,y,z,r``, ``.npz`` and LAMMPS/LIGGGHTS dumps, writing
CSV and the JSON summary beside it.

A packing is a table of sphere centres (N, 3) and radii (N,), in metres: a file in mm or cm
is read with ``units``. Every reader validates at the door and names the
offending row in its ``ValueError``, counted as a spreadsheet does (the file line, header = row 1;
the 1-based array index of a ``.npz``).
"""

from __future__ import annotations

import io
import json
import logging
import os
import zipfile
from pathlib import Path

import numpy as np

from ._packing import MIN_SPHERES, Packing, check_grains, validate_spheres
from ._text import read_text, split_fields

__all__ = ["read_packing", "write_packing_csv", "default_packing_path", "read_container",
           "read_summary", "summary_path", "write_summary", "UNITS", "FORMATS"]

log = logging.getLogger(__name__)

def default_packing_path() -> Path:
    """The bundled soybean-like scene, ``network/data/soybean_default.csv`` (see its README)."""
    return Path(__file__).resolve().parents[1] / "data" / "soybean_default.csv"


def _parse_rows(rows, ncols, first_line, source):
    """Parse whitespace/comma split rows into floats, naming the first bad line."""
    out = np.empty((len(rows), ncols))
    for k, fields in enumerate(rows):  # parsing is I/O-bound; the loop runs once per line
        if len(fields) != ncols:
            raise ValueError(f"{source}: row {first_line[k]}: expected {ncols} values, "
                             f"got {len(fields)}: {','.join(fields)!r}")
        try:
            out[k] = [float(f) for f in fields]
        except ValueError as e:
            raise ValueError(f"{source}: row {first_line[k]}: not a number in "
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


def _read_csv(path: Path, text: str, rules) -> Packing:
    """Delimited text: comma, semicolon, or spaces/tabs (YADE's ``export.text``: ``#`` comment
    lines, then ``x y z r`` rows); an optional header names x, y, z and r/radius/diameter
    (quoted or not)."""
    src = str(path)
    text = text.splitlines()
    # the first line that is neither blank nor a comment: the header or the first row
    first = next((i for i, ln in enumerate(text)
                  if (t := ln.strip()) and not t.startswith("#")), None)
    if first is None:
        raise ValueError(f"{src}: empty file (no data row)")
    head_no, head = first + 1, text[first].strip()
    delim = _delimiter(head)
    names = [h.lower() for h in split_fields(head, delim)]
    scale = 1.0
    if any(not _isfloat(h) for h in names):
        rname = [c for c in _RADIUS_NAMES + _DIAMETER_NAMES if c in names]
        missing = [c for c in ("x", "y", "z") if c not in names] + ([] if rname else ["r"])
        if missing:
            raise ValueError(f"{src}: row {head_no}: header {head!r} lacks column(s) "
                             f"{missing}; expected x, y, z and r (or radius, or diameter)")
        cols = [names.index(c) for c in ("x", "y", "z")] + [names.index(rname[0])]
        if "grain_id" in names:
            cols.append(names.index("grain_id"))
        scale = 0.5 if rname[0] in _DIAMETER_NAMES else 1.0
        start = first + 1
    else:  # no header: x, y, z, r in that order
        cols = [0, 1, 2, 3]
        start = first
    ncols = len(names)
    if ncols < 4:
        raise ValueError(f"{src}: row {head_no}: expected at least 4 columns (x y z r), got "
                         f"{ncols}: {head!r}")
    if next((i for i in range(len(text) - 1, start - 1, -1)      # the last row, from the end
             if (t := text[i].strip()) and not t.startswith("#")), None) is None:
        raise ValueError(f"{src}: no data row after the header")
    raw = text[start:]
    fast = None
    try:  # NumPy's C parser (it skips blank and '#' lines itself)
        fast = np.loadtxt(io.StringIO("\n".join(raw)), delimiter=delim, ndmin=2, comments="#")
    except ValueError:
        fast = None
    if fast is not None and fast.shape == (len(raw), ncols):
        lineno = np.arange(start + 1, start + 1 + len(raw))   # every line a row
    else:
        body = [(i, t) for i, ln in enumerate(raw, start + 1)
                if (t := ln.strip()) and not t.startswith("#")]
        if fast is None or fast.shape != (len(body), ncols):
            fast = _parse_rows([split_fields(ln, delim) for _, ln in body], ncols,
                               [i for i, _ in body], src)
        lineno = np.array([i for i, _ in body])
    data = fast[:, cols]
    validate_spheres(data[:, :3], data[:, 3] * scale, lineno, src, min_spheres=rules[0])
    grain = None
    if data.shape[1] == 5:
        grain = data[:, 4]
        bad = np.flatnonzero(~np.isfinite(grain) | (np.mod(grain, 1) != 0))
        if bad.size:
            raise ValueError(f"{src}: row {lineno[bad[0]]}: grain_id must be a whole number, "
                             f"got {float(grain[bad[0]])!r}")
        _grains(data[:, :3], data[:, 3] * scale, grain, lineno, src, rules[1])
    return Packing(data[:, :3], data[:, 3] * scale, source=src, grain_id=grain)


def _grains(centers, radii, grain, rows, source, one_sphere: str | None) -> None:
    """The grain check of every reader: each grain one body (:func:`check_grains`), or, with
    ``one_sphere`` (a reason), no grain of several spheres."""
    if one_sphere is None:
        check_grains(centers, radii, grain, rows, source)
        return
    ids, first, counts = np.unique(grain, return_index=True, return_counts=True)
    if np.any(counts > 1):
        k = int(np.argmax(counts > 1))
        raise ValueError(f"{source}: row {rows[first[k]]}: grain_id {ids[k]:g} is on {counts[k]} "
                         f"spheres: {one_sphere}")


def _isfloat(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _read_npz(path: Path, rules) -> Packing:
    src = str(path)
    with np.load(path) as z:
        missing = [k for k in ("centers", "radii") if k not in z.files]
        if missing:
            raise ValueError(f"{src}: missing array(s) {missing}; found {z.files}")
        c = np.asarray(z["centers"], dtype=float)
        r = np.asarray(z["radii"], dtype=float).ravel()
        grain = np.asarray(z["grain_id"]).ravel() if "grain_id" in z.files else None
    if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] != r.shape[0]:
        raise ValueError(f"{src}: centers {c.shape} and radii {r.shape} must be (N, 3) and (N,)")
    rows = np.arange(1, len(r) + 1)
    validate_spheres(c, r, rows, src, min_spheres=rules[0])
    if grain is not None:
        if grain.shape != r.shape:
            raise ValueError(f"{src}: grain_id {grain.shape} must be ({r.size},)")
        _grains(c, r, grain, rows, src, rules[1])
    return Packing(c, r, source=src, grain_id=grain)


def _read_dump(path: Path, text: str, rules) -> Packing:
    """LAMMPS/LIGGGHTS ``dump custom`` text; the last snapshot in the file is read."""
    src = str(path)
    text = text.splitlines()
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
                raise ValueError(f"{src}: row {j + 2}: bad atom count") from e
            break
    xyz = []
    for names in (("x", "xu", "xs"), ("y", "yu", "ys"), ("z", "zu", "zs")):
        hit = [c for c in names if c in cols]
        if not hit:
            raise ValueError(f"{src}: row {s + 1}: ATOMS columns {cols} lack {names[0]}")
        xyz.append(cols.index(hit[0]))
    rname = [c for c in ("radius", "r", "diameter") if c in cols]
    if not rname:
        raise ValueError(f"{src}: row {s + 1}: ATOMS columns {cols} lack 'radius' (or 'diameter')")
    rcol = cols.index(rname[0])
    body = []
    for j in range(s + 1, len(text)):
        if text[j].startswith("ITEM:"):
            break
        if text[j].strip():
            body.append((j + 1, text[j].split()))
    if n is not None and len(body) != n:
        raise ValueError(f"{src}: row {s + 1}: header says {n} atoms, found {len(body)} rows")
    data = _parse_rows([f for _, f in body], len(cols), [i for i, _ in body], src)
    c = data[:, xyz]
    r = data[:, rcol] * (0.5 if rname[0] == "diameter" else 1.0)
    if any(cols[k].endswith("s") for k in xyz):
        raise ValueError(f"{src}: row {s + 1}: scaled coordinates (xs ys zs) are not supported; "
                         "dump x y z or xu yu zu")
    lineno = np.array([i for i, _ in body])
    validate_spheres(c, r, lineno, src, min_spheres=rules[0])
    return Packing(c, r, source=src)


def read_packing(path: str | os.PathLike, *, units: str = "m", min_spheres: int = MIN_SPHERES,
                 one_sphere_grains: str | None = None) -> Packing:
    """Read a sphere packing from a file, in metres.

    Parameters
    ----------
    path : str or path-like
        Formats (:data:`FORMATS`): delimited text (``*.csv``, ``*.txt``, ...: comma, semicolon,
        or spaces/tabs, as YADE's ``export.text`` writes; an optional header naming x, y, z and
        r, radius or diameter in any order, extra columns ignored; without a header the columns
        are x, y, z, r; ``#`` comments allowed); ``*.npz`` with arrays ``centers`` (N, 3) and
        ``radii`` (N,); LAMMPS/LIGGGHTS ``dump custom`` text (``x y z radius`` columns, the
        last snapshot). Text as spreadsheets write it: UTF-8 with or without a byte-order
        mark, UTF-16 with one, CRLF line ends, quoted header fields
        (:func:`~network.core.read_text`).
    units : {'m', 'mm', 'cm'}, keyword-only
        Unit of the file's lengths (default metres); the packing is returned in metres, every
        column (``grain_id``) kept.
    min_spheres : int, keyword-only
        Fewest spheres taken (default :data:`MIN_SPHERES`, what a tessellation needs).
    one_sphere_grains : str, optional, keyword-only
        When given, a ``grain_id`` on several spheres is refused with this reason appended
        (a reader whose engine moves single spheres only).

    Returns
    -------
    Packing
        Centres and radii, m.

    Raises
    ------
    FileNotFoundError
        The file does not exist (``IsADirectoryError``: it is a folder).
    ValueError
        Malformed content, NaN/inf, non-positive radii, duplicate centres or fewer than
        ``MIN_SPHERES`` spheres; the message names the file and line.
    """
    if units not in UNITS:
        raise ValueError(f"unknown length unit {units!r}; choose one of {', '.join(UNITS)}")
    rules = (int(min_spheres), one_sphere_grains)
    p = Path(path)
    if p.is_dir():
        raise IsADirectoryError(f"packing {p} is a folder, not a file: give the packing file")
    if not p.is_file():
        raise FileNotFoundError(f"packing file not found: {p}")
    suffix = p.suffix.lower()
    if suffix == ".npz":
        if not zipfile.is_zipfile(p):
            raise ValueError(f"{p}: not a .npz (zip) archive; formats read: {'; '.join(FORMATS)}")
        try:
            pk = _read_npz(p, rules)
        except (OSError, EOFError, zipfile.BadZipFile) as e:
            raise ValueError(f"{p}: not a readable .npz file ({e}); formats read: "
                             f"{'; '.join(FORMATS)}") from e
    else:
        text = read_text(p, what=f"a packing; formats read: {'; '.join(FORMATS)}")
        head = text[:65536]
        if "ITEM: ATOMS" in head or "ITEM: TIMESTEP" in head:
            pk = _read_dump(p, text, rules)
        else:
            pk = _read_csv(p, text, rules)
    if units != "m":
        pk = pk.scaled(UNITS[units], source=f"{pk.source} ({units})")
    log.info("read %d spheres from %s", pk.n, p)
    return pk


#: Length units a packing file may be written in, with their factor to metres.
UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
#: Container kinds of a companion JSON, with the names of their ``size_m`` values (m).
CONTAINER_KINDS = {"box": ("length_x", "width_y"), "cylinder": ("diameter",)}
#: Formats :func:`read_packing` reads, for error messages.
FORMATS = ("delimited text x,y,z,r (comma, semicolon, spaces or tabs; YADE export.text)",
           ".npz with centers and radii", "LAMMPS/LIGGGHTS dump custom")


def read_container(path: str | os.PathLike) -> dict | None:
    """The container of a packing from its companion JSON (same name, ``.json``), if any.

    The DEM writes ``{"container": {"kind": "cylinder" | "box", "size_m": [...], ...}}`` beside
    its CSV (DESIGN: containers are described in the companion JSON or on the command line).

    Returns
    -------
    dict or None
        ``{"kind": ..., "size_m": [...], "center_xy": [x, y] (if known)}``; None when there is
        no companion JSON, it is not a JSON object, or it has no ``container`` entry (logged:
        a JSON of the same stem may be another tool's output).

    Raises
    ------
    ValueError
        A ``container`` entry whose kind is not one of :data:`CONTAINER_KINDS`, or whose
        ``size_m`` is not the kind's positive, finite sizes (a box: length_x, width_y; a
        cylinder: diameter); the message names the file.
    """
    p = Path(path).with_suffix(".json")
    if not p.is_file():
        return None
    try:
        meta = json.loads(p.read_text())
    except (ValueError, UnicodeDecodeError) as e:
        log.warning("companion JSON %s is not readable JSON (%s): ignored", p, e)
        return None
    if not isinstance(meta, dict) or meta.get("container") is None:
        log.warning("companion JSON %s has no 'container' entry: ignored", p)
        return None
    cont = meta["container"]
    kind = str(cont.get("kind")).lower() if isinstance(cont, dict) else None
    if kind not in CONTAINER_KINDS:
        raise ValueError(f"{p}: container kind {kind!r} is not known; the kinds read are "
                         f"{', '.join(CONTAINER_KINDS)} (or remove the 'container' entry)")
    try:
        size = [float(v) for v in np.atleast_1d(cont["size_m"])]
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{p}: container 'size_m' is missing or not numbers ({e})") from e
    need = CONTAINER_KINDS[kind]
    if len(size) != len(need) or not all(np.isfinite(v) and v > 0 for v in size):
        raise ValueError(f"{p}: a {kind} container needs size_m = [{', '.join(need)}] (m, > 0), "
                         f"got {size}")
    out = {"kind": kind, "size_m": size, "source": str(p)}
    centre = cont.get("center_xy") or (meta.get("interior_region") or {}).get("center_xy")
    if centre is not None:
        out["center_xy"] = [float(v) for v in centre][:2]
    return out


def write_packing_csv(packing: Packing, path: str | os.PathLike, *, digits: int = 7,
                      notation: str = "g", summary: dict | None = None) -> None:
    """Write a packing as CSV ``x,y,z,r`` (``x,y,z,r,grain_id`` when it has grain ids) with
    ``digits`` significant digits (``notation`` 'g' or 'e': ``%.{digits}g`` or
    ``%.{digits - 1}e``) and, when given, ``summary`` as the JSON beside it
    (:func:`write_summary`).

    The file is written under a temporary name in its folder and renamed, so a failure never
    leaves a half-written packing (nor the temporary file); missing folders are made.
    """
    if notation not in ("g", "e"):
        raise ValueError(f"notation must be 'g' or 'e', got {notation!r}")
    data = np.column_stack([packing.centers, packing.radii])
    fmt = [f"%.{digits}g" if notation == "g" else f"%.{digits - 1}e"] * 4
    head = "x,y,z,r"
    if packing.grain_id is not None:
        data = np.column_stack([data, packing.grain_id])
        fmt, head = fmt + ["%d"], head + ",grain_id"
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    try:
        np.savetxt(tmp, data, delimiter=",", header=head, comments="", fmt=fmt)
        os.replace(tmp, path)
    finally:                                   # a failed write leaves no .tmp behind
        tmp.unlink(missing_ok=True)
    if summary is not None:
        write_summary(path, summary)


def summary_path(csv_path) -> Path:
    """The JSON companion of a packing file: the same path with suffix ``.json``."""
    return Path(csv_path).with_suffix(".json")


def write_summary(csv_path, summary: dict) -> None:
    """Write (replace) the JSON summary beside a packing file, atomically (NumPy scalars and
    arrays written as numbers and lists)."""
    jp = summary_path(csv_path)
    tmp = jp.with_name(jp.name + ".tmp")
    try:
        tmp.write_text(json.dumps(summary, indent=1, default=_json_default))
        os.replace(tmp, jp)
    finally:
        tmp.unlink(missing_ok=True)


def read_summary(path) -> dict | None:
    """The JSON summary beside packing file ``path`` (:func:`summary_path`), None when there is
    none; ValueError naming it when it is not readable JSON."""
    jp = summary_path(path)
    if not jp.exists():
        return None
    try:
        return json.loads(jp.read_text(encoding="utf-8-sig"))
    except (ValueError, UnicodeDecodeError) as e:
        raise ValueError(f"{jp}: the packing's JSON summary is not readable JSON ({e})") from e


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")

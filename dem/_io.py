"""Packing files: CSV ``x,y,z,r`` (m) plus a JSON summary beside it (same stem); reading validates
at the door as ``network.read_packing`` does (one contract, tested on the same files)."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["write_packing", "write_summary", "read_packing", "summary_path"]


def summary_path(csv_path):
    """The JSON companion of a packing CSV: same path with suffix ``.json``."""
    return Path(csv_path).with_suffix(".json")


def write_packing(path, centers, radii, summary=None):
    """Write ``x,y,z,r`` rows (m, 9 significant digits) and, if given, the JSON summary.

    Files are written to a temporary name first and renamed, so a crash never leaves a
    half-written packing; the temporary file is removed when writing or renaming fails.
    """
    centers = np.asarray(centers, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if centers.ndim != 2 or centers.shape[1] != 3 or radii.shape != (len(centers),):
        raise ValueError(f"need centers (N, 3) and radii (N,), got {centers.shape}, {radii.shape}")
    if not (np.all(np.isfinite(centers)) and np.all(radii > 0)):
        raise ValueError("refusing to write a packing with non-finite centres or non-positive radii")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    try:
        np.savetxt(tmp, np.column_stack([centers, radii]), delimiter=",", header="x,y,z,r",
                   comments="", fmt="%.9e")
        os.replace(tmp, path)
    finally:                                   # a failed write leaves no .tmp behind
        tmp.unlink(missing_ok=True)
    if summary is not None:
        write_summary(path, summary)


def write_summary(csv_path, summary):
    """Write (replace) the JSON summary beside a packing CSV, atomically."""
    jp = summary_path(csv_path)
    tmpj = jp.with_name(jp.name + ".tmp")
    try:
        tmpj.write_text(json.dumps(summary, indent=1, default=_json_default))
        os.replace(tmpj, jp)
    finally:
        tmpj.unlink(missing_ok=True)


#: Header names of the radius column (``diameter`` names are halved), as network's reader.
_RADIUS_NAMES = ("r", "radius", "rad")
_DIAMETER_NAMES = ("d", "diameter", "diam")
#: What :func:`read_packing` reads, for error messages.
FORMATS = "delimited text x,y,z,r (comma, semicolon, spaces or tabs; YADE export.text); .npz with centers and radii"


def read_packing(path):
    """Read a sphere packing (m) and its JSON summary, validated at the door.

    Formats: delimited text (comma, semicolon, or spaces/tabs as YADE's ``export.text``; ``#``
    comment lines; a header naming x, y, z and r, radius or diameter in any order, extra
    columns ignored, or no header and the columns x, y, z, r) and ``.npz`` with ``centers``
    (N, 3) and ``radii`` (N,). The same files are read, and refused, as by
    ``network.read_packing`` (``tests/test_dem_io.py`` feeds both the same files; dem imports
    no other package, so it keeps its own copy of the contract).

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
        Empty or binary file, a missing column, a value that is not a number, NaN/inf, a
        radius <= 0, two spheres with one centre, or a ``grain_id`` shared by several spheres
        (multi-sphere grains: the sphere engine cannot move them); the message names the file
        and the row, counted as a spreadsheet does (header = row 1; ``.npz``: array index + 1).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"packing file not found: {path}")
    if path.suffix.lower() == ".npz":
        centers, radii, grain, rows = _read_npz(path)
    else:
        centers, radii, grain, rows = _read_text(path)
    _validate(path, centers, radii, grain, rows)
    jp = summary_path(path)
    try:
        summary = json.loads(jp.read_text()) if jp.exists() else None
    except ValueError as e:
        raise ValueError(f"{jp}: the packing's JSON summary is not readable JSON ({e})") from e
    return centers, radii, summary


def _read_npz(path):
    if not zipfile.is_zipfile(path):
        raise ValueError(f"{path}: not a .npz (zip) archive; formats read: {FORMATS}")
    try:
        with np.load(path) as z:
            missing = [k for k in ("centers", "radii") if k not in z.files]
            if missing:
                raise ValueError(f"{path}: missing array(s) {missing}; found {z.files}")
            centers = np.asarray(z["centers"], dtype=float)
            radii = np.asarray(z["radii"], dtype=float).ravel()
            grain = np.asarray(z["grain_id"]).ravel() if "grain_id" in z.files else None
    except (OSError, EOFError, zipfile.BadZipFile) as e:
        raise ValueError(f"{path}: not a readable .npz file ({e}); formats read: {FORMATS}") from e
    if centers.ndim != 2 or centers.shape[1] != 3 or len(centers) != len(radii):
        raise ValueError(f"{path}: centers {centers.shape} and radii {radii.shape} must be (N, 3) and (N,)")
    return centers, radii, grain, np.arange(1, len(radii) + 1)


def _read_text(path):
    raw = path.read_bytes()
    if b"\0" in raw[:65536]:
        raise ValueError(f"{path}: a binary file, not a packing; formats read: {FORMATS}")
    body = [(i + 1, ln.strip()) for i, ln in enumerate(raw.decode(errors="replace").splitlines())]
    body = [(i, ln) for i, ln in body if ln and not ln.startswith("#")]
    if not body:
        raise ValueError(f"{path}: empty file (no data row)")
    head_row, head = body[0]
    delim = next((d for d in (",", ";") if d in head), None)
    split = (lambda ln: [f.strip() for f in ln.split(delim)]) if delim else str.split
    names = [h.lower() for h in split(head)]
    cols, scale = [0, 1, 2, 3], 1.0
    if not all(_isfloat(h) for h in names):
        rname = [c for c in _RADIUS_NAMES + _DIAMETER_NAMES if c in names]
        missing = [c for c in "xyz" if c not in names] + ([] if rname else ["r"])
        if missing:
            raise ValueError(f"{path}: row {head_row}: header {head!r} lacks column(s) {missing}; "
                             "expected x, y, z and r (or radius, or diameter)")
        cols = [names.index(c) for c in "xyz"] + [names.index(rname[0])]
        cols += [names.index("grain_id")] if "grain_id" in names else []
        scale = 0.5 if rname[0] in _DIAMETER_NAMES else 1.0
        body = body[1:]
        if not body:
            raise ValueError(f"{path}: no data row after the header")
    elif len(names) < 4:
        raise ValueError(f"{path}: row {head_row}: expected at least 4 columns (x y z r), got {len(names)}: {head!r}")
    data = np.empty((len(body), len(cols)))
    for k, (row, ln) in enumerate(body):  # once per row: reading is I/O-bound
        fields = split(ln)
        if len(fields) != len(names):
            raise ValueError(f"{path}: row {row}: expected {len(names)} values, got {len(fields)}: {ln!r}")
        try:
            data[k] = [float(fields[c]) for c in cols]
        except ValueError as e:
            raise ValueError(f"{path}: row {row}: not a number in {ln!r}") from e
    grain = data[:, 4] if len(cols) == 5 else None
    return data[:, :3], data[:, 3] * scale, grain, np.array([i for i, _ in body])


def _isfloat(s):
    try:
        float(s)
    except ValueError:
        return False
    return True


def _validate(path, centers, radii, grain, rows):
    """ValueError naming the row of the first non-finite value, radius <= 0, repeated centre,
    or grain id shared by several spheres."""
    bad = np.flatnonzero(~np.isfinite(centers).all(axis=1) | ~np.isfinite(radii))
    if bad.size:
        i = bad[0]
        raise ValueError(f"{path}: row {rows[i]}: non-finite value (NaN or inf) in x,y,z,r = "
                         f"{centers[i].tolist() + [float(radii[i])]}")
    bad = np.flatnonzero(radii <= 0)
    if bad.size:
        raise ValueError(f"{path}: row {rows[bad[0]]}: radius must be > 0, "
                         f"got {float(radii[bad[0]])}")
    order = np.lexsort(centers.T[::-1])
    dup = np.flatnonzero(np.all(centers[order][1:] == centers[order][:-1], axis=1))
    if dup.size:
        a, b = sorted((int(order[dup[0]]), int(order[dup[0] + 1])))
        raise ValueError(f"{path}: row {rows[b]}: duplicate centre {centers[b].tolist()} (same as row {rows[a]})")
    if grain is not None:
        ids, first, counts = np.unique(grain, return_index=True, return_counts=True)
        if np.any(counts > 1):
            k = int(np.argmax(counts > 1))
            raise ValueError(f"{path}: row {rows[first[k]]}: grain_id {ids[k]:g} is on {counts[k]} spheres: "
                             "multi-sphere grains cannot be moved by the sphere engine (dem.vibrate vibrates "
                             "sphere packings)")


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")

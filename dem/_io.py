"""Packing files: CSV ``x,y,z,r`` (m) plus a JSON summary beside it (same stem)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

__all__ = ["write_packing", "write_summary", "read_packing", "summary_path"]


def summary_path(csv_path):
    """The JSON companion of a packing CSV: same path with suffix ``.json``."""
    return Path(csv_path).with_suffix(".json")


def write_packing(path, centers, radii, summary=None):
    """Write ``x,y,z,r`` rows (m, 9 significant digits) and, if given, the JSON summary.

    Files are written to a temporary name first and renamed, so a crash never leaves a
    half-written packing.
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
    np.savetxt(tmp, np.column_stack([centers, radii]), delimiter=",", header="x,y,z,r", comments="", fmt="%.9e")
    os.replace(tmp, path)
    if summary is not None:
        write_summary(path, summary)


def write_summary(csv_path, summary):
    """Write (replace) the JSON summary beside a packing CSV, atomically."""
    jp = summary_path(csv_path)
    tmpj = jp.with_name(jp.name + ".tmp")
    tmpj.write_text(json.dumps(summary, indent=1, default=_json_default))
    os.replace(tmpj, jp)


def read_packing(path):
    """Read a packing CSV (header ``x,y,z,r``) or ``.npz`` (centers, radii).

    Returns
    -------
    centers : (N, 3) array, m
    radii : (N,) array, m
    summary : dict or None
        The companion JSON if present.
    """
    path = Path(path)
    if path.suffix == ".npz":
        with np.load(path) as f:
            centers, radii = np.asarray(f["centers"], float), np.asarray(f["radii"], float)
    else:
        with open(path) as fh:
            header = fh.readline().strip().replace(" ", "")
        if header != "x,y,z,r":
            raise ValueError(f"{path}: expected header 'x,y,z,r', got {header!r}")
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
        centers, radii = data[:, :3], data[:, 3]
    jp = summary_path(path)
    summary = json.loads(jp.read_text()) if jp.exists() else None
    return centers, radii, summary


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")

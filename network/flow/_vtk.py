"""A small writer of VTK XML unstructured grids (.vtu) for pore networks (ParaView).

Pores are the points (at the tetrahedron centroids) with point data such as ``pressure``;
throats are line cells (VTK type 3) joining them, with cell data such as ``flow`` and
``conductance``. Data arrays are written inline as base64-encoded binary (``format="binary"``,
UInt32 byte-count header), which ParaView and meshio read; no dependency is needed.
"""

from __future__ import annotations

import base64
import logging
import os

import numpy as np

__all__ = ["write_network_vtu", "read_vtu_arrays"]

log = logging.getLogger(__name__)

_TYPES = {np.dtype("float64"): "Float64", np.dtype("float32"): "Float32",
          np.dtype("int64"): "Int64", np.dtype("int32"): "Int32", np.dtype("uint8"): "UInt8"}


def _data_array(name, arr, ncomp=1):
    arr = np.ascontiguousarray(arr)
    if arr.dtype not in _TYPES:
        arr = arr.astype(np.float64)
    raw = arr.astype(arr.dtype.newbyteorder("<"), copy=False).tobytes()
    payload = base64.b64encode(np.uint32(len(raw)).tobytes() + raw).decode("ascii")
    return (f'<DataArray type="{_TYPES[arr.dtype]}" Name="{name}" NumberOfComponents="{ncomp}" '
            f'format="binary">{payload}</DataArray>')


def write_network_vtu(path: str | os.PathLike, points, lines, *, point_data=None,
                      cell_data=None) -> None:
    """Write points and line cells with data to a ``.vtu`` file.

    Parameters
    ----------
    path : path-like
        Output file (``.vtu``).
    points : (Np, 3) array_like, m
        Pore positions.
    lines : (Nt, 2) array_like of int
        Point indices of each throat.
    point_data : dict of str -> (Np,) array_like, optional
        E.g. ``{"pressure": p}`` (Pa).
    cell_data : dict of str -> (Nt,) array_like, optional
        E.g. ``{"flow": q, "conductance": g}``.
    """
    pts = np.asarray(points, dtype=np.float64)
    con = np.asarray(lines, dtype=np.int64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (Np, 3), got {pts.shape}")
    if con.ndim != 2 or con.shape[1] != 2:
        raise ValueError(f"lines must have shape (Nt, 2), got {con.shape}")
    if con.size and (con.min() < 0 or con.max() >= pts.shape[0]):
        raise ValueError("line indices out of range of the points")
    point_data = point_data or {}
    cell_data = cell_data or {}
    for name, arr in point_data.items():
        if np.shape(arr) != (pts.shape[0],):
            raise ValueError(f"point data {name!r} must have shape ({pts.shape[0]},)")
    for name, arr in cell_data.items():
        if np.shape(arr) != (con.shape[0],):
            raise ValueError(f"cell data {name!r} must have shape ({con.shape[0]},)")
    nt = con.shape[0]
    parts = [
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt32">',
        "<UnstructuredGrid>",
        f'<Piece NumberOfPoints="{pts.shape[0]}" NumberOfCells="{nt}">',
        "<PointData>", *[_data_array(k, np.asarray(v)) for k, v in point_data.items()],
        "</PointData>",
        "<CellData>", *[_data_array(k, np.asarray(v)) for k, v in cell_data.items()],
        "</CellData>",
        "<Points>", _data_array("Points", pts.ravel(), 3), "</Points>",
        "<Cells>",
        _data_array("connectivity", con.ravel()),
        _data_array("offsets", 2 * np.arange(1, nt + 1, dtype=np.int64)),
        _data_array("types", np.full(nt, 3, dtype=np.uint8)),
        "</Cells>",
        "</Piece>",
        "</UnstructuredGrid>",
        "</VTKFile>",
    ]
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")
    log.info("wrote %s: %d pores, %d throats", path, pts.shape[0], nt)


def read_vtu_arrays(path: str | os.PathLike) -> dict:
    """Read back every DataArray of a file written by :func:`write_network_vtu` (for tests)."""
    import xml.etree.ElementTree as ET

    inv = {v: k for k, v in _TYPES.items()}
    out = {}
    for el in ET.parse(path).getroot().iter("DataArray"):
        raw = base64.b64decode(el.text.strip())
        n = int(np.frombuffer(raw[:4], dtype="<u4")[0])
        arr = np.frombuffer(raw[4:4 + n], dtype=inv[el.get("type")].newbyteorder("<"))
        ncomp = int(el.get("NumberOfComponents", "1"))
        out[el.get("Name")] = arr.reshape(-1, ncomp) if ncomp > 1 else arr
    return out

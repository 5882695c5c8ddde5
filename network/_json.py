"""JSON-ready copies of result dictionaries (numpy scalars and small arrays as Python values)."""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["jsonable"]


def jsonable(d: dict) -> dict:
    """Copy of a stats dict that ``json.dump`` takes: numpy scalars as Python numbers, arrays of
    up to 8 items as lists (longer per-throat arrays are left out), dataclasses as their fields.

    >>> jsonable({"n": np.int64(3), "x": np.float32(0.5), "a": np.arange(2), "b": np.zeros(9)})
    {'n': 3, 'x': 0.5, 'a': [0, 1]}
    """
    out = {}
    for k, v in dict(d).items():
        if isinstance(v, dict):
            out[str(k)] = jsonable(v)
        elif isinstance(v, (np.integer,)):
            out[str(k)] = int(v)
        elif isinstance(v, (np.floating,)):
            out[str(k)] = float(v)
        elif isinstance(v, (str, int, float, bool)) or v is None:
            out[str(k)] = v
        elif isinstance(v, np.ndarray):
            if v.size <= 8:
                out[str(k)] = v.tolist()
            # long per-throat arrays are not summary material: left out
        elif isinstance(v, (list, tuple)):
            out[str(k)] = [x.item() if hasattr(x, "item") else x for x in v]
        elif dataclasses.is_dataclass(v):   # e.g. the conduit's PoreMerge: its scalar fields
            out[str(k)] = jsonable({f.name: getattr(v, f.name) for f in dataclasses.fields(v)})
        else:
            out[str(k)] = str(v)
    return out

"""Derived arrays of a shipped interpolation table, computed once and memory-mapped afterwards.

:class:`cache.GridTable` fills the invalid nodes, takes second differences and finds the served
cells in whole-grid passes (0.1-0.2 s for g1 on this 2-core machine, the largest part of a
first lookup). Their result depends only on the table file and on the code that derives it
(``_interp.py``, ``_grids.py``, ``_cells.py``, ``_orbits.py``, ``_pair.py``), so it is saved
beside the user's Q* table under a name hashed from both and read back as a memory map (a few
ms); a changed table or code gets a new name.
The name holds the table file's path too (a clone's files have their own times), so each
checkout has its copy; :data:`KEEP` copies per table, the most recently used, are kept (x1's
are 121 MB each: without the bound every clone added 0.2 GB for good).
"""

from __future__ import annotations

import hashlib
import logging
import os
from pathlib import Path

import numpy as np

logger = logging.getLogger(__name__)

__all__ = ["KEEP", "ROWS", "derived_path", "load_derived", "save_derived"]

#: derived copies kept per table name (several checkouts), the most recently used
KEEP = 3

#: rows of the saved arrays (one float64 .npy, memory-mapped)
ROWS = ("values", "k0", "k1", "k2", "k3", "k4", "cell_ok", "qstar", "fe_error", "geometric")
#: rows a table may lack: saved as NaN and left out on reading (the node shape factor's geometric
#: part, which only the deep-pair table uses: a whole-grid pass of exact open areas, 0.3 s on p1)
OPTIONAL = ("geometric",)


def derived_path(path, directory):
    """Where the derived arrays of table file ``path`` are kept in ``directory``, named by the
    file's size and time and a hash of the code that derives them (None: unreadable)."""
    try:
        where = hashlib.blake2b(str(Path(path).resolve()).encode(), digest_size=6)
        st = Path(path).stat()
        what = hashlib.blake2b(f"{st.st_size}:{st.st_mtime_ns}".encode(), digest_size=8)
        for mod in ("_interp.py", "_grids.py", "_cells.py", "_orbits.py", "_pair.py"):
            what.update(Path(__file__).with_name(mod).read_bytes())
        return (Path(directory)
                / f"{Path(path).stem}.derived-{where.hexdigest()}-{what.hexdigest()}.npy")
    except OSError:
        return None


def load_derived(saved, shape):
    """The saved derived arrays as row views of one memory map (None: absent or foreign)."""
    if saved is None or not saved.exists():
        return None
    try:
        a = np.load(saved, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as exc:
        logger.info("derived arrays %s not read (%s): recomputed", saved, exc)
        return None
    if a.dtype != np.float64 or a.shape != (len(ROWS), int(np.prod(shape))):
        return None
    out = dict(zip(ROWS, np.asarray(a)))      # plain ndarray views: no memmap wrapping later
    out["cell_ok"] = out["cell_ok"] > 0.5
    for k in OPTIONAL:
        if np.isnan(out[k]).all():
            del out[k]
    try:
        os.utime(saved)                       # its time says when it was last used (KEEP)
    except OSError:
        pass
    return out


def save_derived(saved, arrays):
    """Write the derived arrays (28 MB for g1) atomically and drop older copies; a read-only
    or full disk only costs the next run the 0.1 s of recomputing them."""
    tmp = saved.with_name(f"{saved.name}.{os.getpid()}.tmp")
    try:
        if any(arrays.get(k) is None for k in ROWS if k not in OPTIONAL):
            return                           # a grid without curvature in every direction
        size = np.size(arrays["values"])
        arrays = {k: np.full(size, np.nan) if arrays.get(k) is None else arrays[k] for k in ROWS}
        saved.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as f:
            np.save(f, np.stack([np.ravel(arrays[k]).astype(np.float64)
                                 for k in ROWS]))
        os.replace(tmp, saved)
        for old in saved.parent.glob(saved.name.rsplit("-", 1)[0] + "-*.npy"):
            if old != saved:                 # an older copy for the same table file
                old.unlink(missing_ok=True)
        _keep_recent(saved)
    except OSError as exc:
        logger.info("derived arrays not saved to %s (%s)", saved, exc)
        tmp.unlink(missing_ok=True)


def _keep_recent(saved):
    """Delete the derived copies of ``saved``'s table name beyond the :data:`KEEP` most
    recently used (other checkouts' copies; a process reading one keeps its open map)."""
    stem = saved.name.split(".derived-", 1)[0]
    copies = []
    for f in saved.parent.glob(f"{stem}.derived-*.npy"):
        try:
            copies.append((f == saved, f.stat().st_mtime_ns, f))
        except OSError:
            continue
    copies.sort(reverse=True)                # the new copy first, then by last use
    for _, _, f in copies[KEEP:]:
        f.unlink(missing_ok=True)

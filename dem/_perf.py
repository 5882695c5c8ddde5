"""Process-level tuning for the DEM CLIs (not applied on import of the library).

numpy allocates a fresh temporary for every array expression; the per-contact temporaries
of a 20 000-sphere bed are ~0.3–1 MB, above glibc's default mmap threshold, so each one is
mmap'ed, page-faulted and unmapped again, every step. Raising the mmap and trim thresholds
lets malloc reuse heap memory instead: measured 1.8e6 -> 2.2–2.4e6 particle-steps per
CPU-second at N = 20 000 (``python -m dem.bench``). Only the CLIs call this.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging

__all__ = ["tune_malloc"]

log = logging.getLogger(__name__)

_M_TRIM_THRESHOLD = -1
_M_TOP_PAD = -2
_M_MMAP_THRESHOLD = -3


def tune_malloc(mmap_threshold=32 << 20, trim_threshold=1 << 30, top_pad=64 << 20):
    """Set glibc malloc thresholds for this process; returns False where not glibc."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    ok = all(mallopt(p, min(v, 2**31 - 1)) == 1 for p, v in (
        (_M_MMAP_THRESHOLD, mmap_threshold), (_M_TRIM_THRESHOLD, trim_threshold), (_M_TOP_PAD, top_pad)))
    log.debug("malloc tuning %s", "applied" if ok else "refused")
    return ok

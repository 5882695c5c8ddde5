"""Run a block with single-threaded OpenBLAS (best effort, restored afterwards).

The network's hot paths are sparse; OpenBLAS's spinning worker threads gain nothing there and
slow a pyamg setup + solve 10-30x when the cores are shared (measured on this project's 2-core
machine: 0.2 s vs 2.5-6.7 s for a 64 000-pore grid). :func:`single_threaded_blas` finds the
OpenBLAS libraries loaded in the process (numpy's and scipy's wheels each ship one), sets their
thread count to 1 through ctypes, as threadpoolctl does, and restores it on exit. Without OpenBLAS
(MKL, Accelerate, ...) it does nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging

__all__ = ["single_threaded_blas"]

log = logging.getLogger(__name__)

_PREFIXES = ("openblas", "scipy_openblas")
_SUFFIXES = ("", "64_")
_libs: list | None = None


def _openblas_handles():
    global _libs
    if _libs is not None:
        return _libs
    import scipy.linalg  # noqa: F401  (loads scipy's OpenBLAS so that it is found too)

    _libs = []
    try:
        with open("/proc/self/maps") as f:
            paths = {ln.split()[-1] for ln in f if "openblas" in ln.lower() and ".so" in ln}
    except OSError:
        return _libs
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for pre in _PREFIXES:
            for suf in _SUFFIXES:
                get = getattr(lib, f"{pre}_get_num_threads{suf}", None)
                put = getattr(lib, f"{pre}_set_num_threads{suf}", None)
                if get is not None and put is not None:
                    get.restype = ctypes.c_int
                    put.argtypes = [ctypes.c_int]
                    _libs.append((path, get, put))
                    break
            else:
                continue
            break
    log.debug("OpenBLAS libraries found: %s", [p for p, _, _ in _libs])
    return _libs


@contextlib.contextmanager
def single_threaded_blas():
    """Context manager: OpenBLAS limited to one thread inside the block."""
    saved = []
    for path, get, put in _openblas_handles():
        try:
            saved.append((put, get()))
            put(1)
        except Exception:  # pragma: no cover - foreign builds
            continue
    try:
        yield
    finally:
        for put, n in saved:
            put(n)

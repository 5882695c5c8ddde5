"""What every part of the benchmark records: the machine it ran on, the Q* sources of a run."""

from __future__ import annotations

import os
import platform
import time

__all__ = ["machine", "qstar_sources"]


def machine() -> dict:
    """Platform, Python, CPU count, load average and a UTC timestamp."""
    return {"platform": platform.platform(), "python": platform.python_version(),
            "cpu_count": os.cpu_count(), "loadavg": list(os.getloadavg()),
            "timestamp": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def qstar_sources(stats: dict) -> dict:
    """Q* sources of a run (the conduit model nests the lookup statistics one level down)."""
    return stats.get("sources") or stats.get("qstar_stats", {}).get("sources", {})


"""What the dem command lines share: process setup, exit codes, progress lines, the container.

``python -m dem.pack`` and ``python -m dem.vibrate`` (and the vibration study) run their body
through :func:`run_main`: malloc tuning (:mod:`dem._perf`), argument parsing, and one mapping
of failures to exit codes, the project's convention: 2 for bad input (``ValueError``,
``OSError``), 1 for a computation that failed (a simulation that went unstable,
:class:`~dem._integrate.DemInstabilityError`, an unconverged packing) or was interrupted
(Ctrl-C). No physics here.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

from ._container import SCENES, Container
from ._integrate import DemInstabilityError
from ._perf import tune_malloc

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_UNSTABLE", "run_main", "progress_printer",
           "resolve_container", "check_output", "check_seed", "OneLineParser"]

EXIT_BAD_INPUT = 2
#: A computation that failed: unstable, not converged, interrupted (the same code as network's).
EXIT_FAILED = 1
EXIT_UNSTABLE = EXIT_FAILED


class OneLineParser(argparse.ArgumentParser):
    """``ArgumentParser`` whose usage errors are one ``error:`` line and exit 2."""

    def error(self, message):
        print(f"error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(EXIT_BAD_INPUT)


def run_main(parser, body, argv=None, *, interrupted=None) -> int:
    """Parse ``argv`` with ``parser`` and return ``body(args)``, mapping failures to exit codes.

    A ``ValueError`` or ``OSError`` prints ``error: ...`` and returns 2; a
    ``DemInstabilityError`` prints ``unstable: ...`` and Ctrl-C ``interrupted: ...``, both
    returning 1 (what was written before stays: packings are written whole at the end, the
    vibration study keeps its checkpoints; ``interrupted`` replaces that line's text).
    argparse's own errors exit 2 as usual.
    """
    tune_malloc()
    args = parser.parse_args(argv)
    try:
        return body(args)
    except (ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except DemInstabilityError as e:
        print(f"unstable, not written: {e}", file=sys.stderr)
        return EXIT_UNSTABLE
    except KeyboardInterrupt:
        print("interrupted: " + (interrupted or "nothing more written (a packing is written "
              "whole at the end; a vibration study resumes from its last checkpoint)"),
              file=sys.stderr)
        return EXIT_FAILED


def progress_printer(label="", *, quiet=False, every_steps=2000):
    """Progress callback ``(stage, sim, force)`` printing one line to stderr every ``every_steps``.

    The line gives the stage, step, simulated time, kinetic energy, the unbalanced-force ratio
    (when ``force`` is given) and the particle-steps per second since the printer was made.
    """
    t0 = time.perf_counter()

    def progress(stage, sim, force):
        if quiet or sim.steps % every_steps != 0:
            return
        rate = sim.steps * sim.n / (time.perf_counter() - t0)
        ratio = "" if force is None else f"  ratio = {sim.unbalanced_force_ratio(force):8.2e}"
        print(f"[{label}{stage:7s}] step {sim.steps:7d}  t = {sim.time_s:7.4f} s  KE = {sim.kinetic_energy():9.3e} J"
              f"{ratio}  {rate:9.3e} particle-steps/s", file=sys.stderr, flush=True)

    return progress


def resolve_container(scene, *, size_m=None, height_m=None, summary=None):
    """The container of a command line: a named scene, ``box``/``cylinder`` with size and
    height, or the ``container`` entry of a packing's JSON summary (in that order)."""
    if scene in SCENES:
        return SCENES[scene]
    if scene in ("box", "cylinder"):
        if size_m is None or height_m is None:
            raise ValueError(f"--scene {scene} needs --size and --height")
        for opt, vals in (("--size", list(size_m)), ("--height", [height_m])):
            if not all(math.isfinite(v) and v > 0 for v in vals):
                raise ValueError(f"{opt} {' '.join(f'{v:g}' for v in vals)}: lengths must be "
                                 "finite and > 0 (m)")
        return Container(scene, tuple(size_m), height_m)
    if scene is not None:
        raise ValueError(f"unknown scene {scene!r}; choose from {sorted(SCENES)} or 'box'/'cylinder'")
    if summary and "container" in summary:
        return Container.from_dict(summary["container"])
    raise ValueError("no container: give --scene or keep the packing's JSON summary beside it")


def check_output(path, option="--out") -> None:
    """ValueError naming ``option`` when the file ``path`` cannot be written: it is a folder,
    an existing file not writable, or its folder (the nearest existing one: missing folders
    are created when written) takes no new file, probed by making and removing a temporary
    file there (``os.access`` says yes to root, even on ``/proc``)."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{option} {path}: is a folder, give a file name")
    folder = path.parent
    while not folder.is_dir():
        if folder.exists() or folder == folder.parent:
            raise ValueError(f"{option} {path}: {folder} is not a folder")
        folder = folder.parent
    try:
        tempfile.TemporaryFile(dir=folder, prefix=".grainflow-").close()
    except OSError as exc:
        raise ValueError(f"{option} {path}: folder {folder} is not writable "
                         f"({exc.strerror or exc})") from None
    if path.exists() and not os.access(path, os.W_OK):
        raise ValueError(f"{option} {path}: file exists and is not writable")


def check_seed(seed, option="--seed") -> None:
    """ValueError naming ``option`` unless ``seed`` is a non-negative integer (numpy's rule)."""
    if seed is not None and seed < 0:
        raise ValueError(f"{option} must be a non-negative integer, got {seed}")

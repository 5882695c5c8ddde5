"""What the dem command lines share: process setup, progress lines, the container; the
command-line base (exit codes, one-line parser, run wrapper, output check) is the project's one
(:mod:`network.core`).

``python -m dem.pack``, ``dem.vibrate``, ``dem.study`` and ``dem.bench`` run their body through
:func:`run_main`: malloc tuning (:mod:`dem._perf`), argument parsing, and the project's mapping
of failures to exit codes: 2 for bad input (``ValueError``, ``OSError``), 1 for a computation
that failed (a simulation that went unstable, :class:`~dem._integrate.DemInstabilityError`, an
unconverged packing) or was interrupted (Ctrl-C). No physics here.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

from network.core import (EXIT_BAD_INPUT, EXIT_FAILED, MAX_REPEATS, MAX_SPHERES, MAX_WORKERS,
                          CliError, CliParser, bad_input, check_count, check_output_list, run)

from ._container import SCENES, Container
from ._integrate import DemInstabilityError
from ._perf import tune_malloc

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_UNSTABLE", "run_main", "progress_printer",
           "resolve_container", "check_output", "check_output_list", "check_seed",
           "check_count", "check_counts", "OneLineParser", "MAX_STEPS", "MAX_SPHERES",
           "MAX_WORKERS", "MAX_REPEATS"]

#: Most steps a ``--max-steps``/``--steps``/``--settle-steps`` may ask for (a billion steps
#: of a few thousand particles is days of computing: a larger number is a slip)
MAX_STEPS = 10**9
#: A simulation that went unstable: a failed computation (exit 1).
EXIT_UNSTABLE = EXIT_FAILED
#: What an interrupted dem command says was kept.
INTERRUPTED = ("nothing more written (a packing is written whole at the end; a vibration "
               "study resumes from its last checkpoint)")


class OneLineParser(CliParser):
    """The project's one-line parser (:class:`network.core.CliParser`) with argparse's plain
    help layout."""

    def __init__(self, *a, **kw):
        kw.setdefault("formatter_class", argparse.HelpFormatter)
        super().__init__(*a, **kw)


def run_main(parser, body, argv=None, *, interrupted=None) -> int:
    """Parse ``argv`` with ``parser`` and return ``body(args)``, mapping failures to exit codes.

    A ``ValueError`` or ``OSError`` prints ``error: ...`` and returns 2; a
    ``DemInstabilityError`` prints ``unstable, not written: ...`` and Ctrl-C
    ``interrupted: ...``, both returning 1 (what was written before stays: packings are
    written whole at the end, the vibration study keeps its checkpoints; ``interrupted``
    replaces that line's text). Any other exception is one ``error:`` line and exit 1
    (:func:`network.core.run`).
    """
    tune_malloc()

    def guarded(args):
        try:
            with bad_input():
                return body(args)
        except DemInstabilityError as e:
            raise CliError(str(e), EXIT_UNSTABLE, label="unstable, not written") from e

    return run(guarded, parser, argv, interrupted=interrupted or INTERRUPTED)


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


def check_output(path, option="--out", inputs=()) -> None:
    """ValueError naming ``option`` when the file ``path`` cannot be written, or is one of
    ``inputs`` (``(what, path)`` pairs): :func:`network.core.check_output_list`, missing
    folders made on writing."""
    check_output_list([(option, path)], inputs, make_folders=True)


def check_counts(args) -> None:
    """ValueError naming the option when a count of a dem command is out of its bounds
    (:func:`network.core.check_count`): particles and grains up to ``MAX_SPHERES``, steps up
    to :data:`MAX_STEPS`, threads up to ``MAX_WORKERS``, packings up to 100."""
    for opt, high in (("n_particles", MAX_SPHERES), ("n_grains", MAX_SPHERES),
                      ("max_steps", MAX_STEPS), ("sediment_steps", MAX_STEPS),
                      ("settle_steps", MAX_STEPS), ("threads", MAX_WORKERS),
                      ("max_packings", 100)):
        check_count("--" + opt.replace("_", "-"), getattr(args, opt, None), high)


def check_seed(seed, option="--seed") -> None:
    """ValueError naming ``option`` unless ``seed`` is a non-negative integer (numpy's rule)."""
    if seed is not None and seed < 0:
        raise ValueError(f"{option} must be a non-negative integer, got {seed}")

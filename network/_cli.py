"""Shared pieces of the network command-line tools (``network.solve``, ``.curve``, ``.throats``,
``.paths``, ``.report``): the packing/sample/units/air arguments, the packing's input files and
the model's validity warnings, on top of the command-line base every grainflow command shares
(:mod:`network.core`: exit codes, parser, run wrapper, output check; docs/cli.md).

Lengths that place something in the packing (``--sample``, ``--margin``, ``--entry``) are in
the packing file's unit (``--units``, default m); physical quantities (``--depth``,
``--velocity``, ``--viscosity``, ``--density``) are SI.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
from pathlib import Path

from ._air import MU_AIR_PA_S, P_ATM_PA, RHO_AIR_KG_M3, check_positive
from .core import (EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, MAX_WORKERS, CliError, CliParser,
                   bad_input, check_count,
                   check_output_list, check_outputs, check_writable_folder, computing, finish,
                   progress_log, run, warn)
from .conductance import first_run_note
from .packing import (UNITS, check_three_dimensional, default_packing_path, read_container,
                      read_packing, scale_warning)

log = logging.getLogger(__name__)

__all__ = ["EXIT_OK", "EXIT_FAILED", "EXIT_BAD_INPUT", "CliError", "CliParser", "bad_input",
           "computing", "run", "finish", "progress_log", "add_packing", "add_sample", "add_air",
           "check_outputs", "check_output_list", "check_writable_folder", "check_plot",
           "load_packing", "sample_box_m", "warn"]

#: Smallest ``--viscosity`` taken, Pa s: about a hundredth of hydrogen's (8.8e-6 Pa s at 20 °C),
#: the least viscous gas. Far below it the viscous term is lost beside the inertial one in the
#: Newton solve (Re_p 1e16 at 1e-20 Pa s: a gradient 8 times low, exit 0; at 1e-30 no
#: convergence after two minutes).
MIN_VISCOSITY_PA_S = 1e-7


class RemovedOption(argparse.Action):
    """An option the command does not take: its use is bad input (exit 2) whose one line names
    what to use instead (``replacement``); hidden from ``--help``."""

    def __init__(self, option_strings, dest, *, replacement: str, **kw):
        kw.update(nargs="?", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
        super().__init__(option_strings, dest, **kw)
        self.replacement = replacement

    def __call__(self, parser, namespace, values, option_string=None):
        parser.error(f"{option_string} is not an option: {self.replacement}")


#: Largest particle Reynolds number the inertial law is checked at (against the Beetstra law
#: to 200, against the resolved flow to 93; docs/inertial-flow.md)
RE_P_CHECKED = 200.0


def warn_validity(reynolds_particle=None, pressure_drop_pa=None) -> None:
    """``warning:`` lines for a result outside the model's range: Re_p above
    :data:`RE_P_CHECKED` (the per-conduit law extrapolated, the flow likely unsteady), a pressure
    drop above 10 % of :data:`~network._air.P_ATM_PA` (the air's density changes by as much;
    the model takes it constant)."""
    if reynolds_particle is not None and reynolds_particle > RE_P_CHECKED:
        warn(f"Re_p {reynolds_particle:.3g} is beyond the {RE_P_CHECKED:g} the inertial law is "
             "checked to: the result is an extrapolation (docs/inertial-flow.md)")
    if pressure_drop_pa is not None and pressure_drop_pa > 0.1 * P_ATM_PA:
        warn(f"a pressure drop of {pressure_drop_pa:.3g} Pa is {pressure_drop_pa / P_ATM_PA:.0%} "
             "of the atmosphere's: the air is compressed by as much, which the model (constant "
             "density) leaves out")


def warn_curve(points, depth_m: float, key: str = "pressure_gradient_pa_per_m") -> None:
    """:func:`warn_validity` for every point of a curve, converged or not (a velocity beyond
    the checked range is so whether or not its solve finished): the largest Re_p, and the
    largest finite drop over ``depth_m`` (Pa) = gradient ``key`` (Pa/m) x depth."""
    if not points:
        return
    drops = [p[key] * depth_m for p in points if math.isfinite(p[key])]
    warn_validity(max(p["reynolds_particle"] for p in points), max(drops) if drops else None)


# ------------------------------------------------------------------ arguments
def add_packing(ap, *, bundled: bool = True) -> None:
    """The optional packing positional (``bundled``: the bundled scene when left out) and
    ``--units``."""
    ap.add_argument("packing", nargs="?", default=None,
                    help="sphere packing: delimited text x,y,z,r (comma, semicolon, spaces; "
                         "header optional; r, radius or diameter), .npz (centers, radii) or a "
                         "LAMMPS/LIGGGHTS dump" + (f"; default: the bundled scene "
                                                   f"{default_packing_path().name}"
                                                   if bundled else ""))
    ap.add_argument("--units", default="m", type=str.lower, choices=list(UNITS),
                    help="length unit of the packing file (and of --sample, --margin, --entry); "
                         "a mean grain diameter outside 0.5-50 mm after conversion is warned "
                         "about")


def add_sample(ap, *, cylinder: bool = True) -> None:
    """``--sample`` box, ``--margin`` (and ``--cylinder``), in the packing's unit."""
    ap.add_argument("--sample", nargs=6, type=float,
                    metavar=("XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"), default=None,
                    help="sample box in the packing's unit (--units); it must lie inside the "
                         "packed bed; default: the interior box, --margin in from the bed")
    ap.add_argument("--margin", type=float, default=None,
                    help="wall margin of the default box in the packing's unit, >= 0 "
                         "(default: 1.5 mean diameters)")
    if cylinder:
        ap.add_argument("--cylinder", action="store_true",
                        help="use the cylinder inscribed in the sample box, its axis the flow "
                             "axis")


def add_table(ap) -> None:
    """``--rtol`` and ``--db``: the Q* tolerance and the throat table of the FE policies."""
    ap.add_argument("--rtol", type=float, default=1e-3,
                    help="Q* relative tolerance of table+fe and fe-only, > 0")
    ap.add_argument("--db", default=None,
                    help="throat table, SQLite (default: the cache's default database)")


def add_air(ap, *, density: bool = True) -> None:
    """``--viscosity`` (and ``--density``), SI."""
    ap.add_argument("--viscosity", type=float, default=MU_AIR_PA_S,
                    help=f"dynamic viscosity of the air, Pa s, > 0 (at least "
                         f"{MIN_VISCOSITY_PA_S:g}; thesis air)")
    if density:
        ap.add_argument("--density", type=float, default=RHO_AIR_KG_M3,
                        help="air density for the inertial losses, kg/m^3, > 0")
        ap.add_argument("--inertial-law", action=RemovedOption,
                        replacement="the inertial loss is the conduit window law "
                                    "(docs/inertial-flow.md); python -m network.solve "
                                    "--stokes gives the linear (Stokes) answer")


# ------------------------------------------------------------------ checks
def packing_inputs(args) -> list:
    """``(what, path)`` of the files a network command reads: the packing file (``args.packing``)
    and its companion JSON when that holds the DEM's container (:func:`read_container`)."""
    if not args.packing:
        return []
    path = Path(args.packing)
    out = [("the packing file", path)]
    if path.is_file() and read_container(path) is not None:
        out.append(("the packing's companion JSON (its container)", path.with_suffix(".json")))
    return out


def check_plot(option: str = "--plot", path=None) -> None:
    """ValueError naming the extra to install when matplotlib is missing, or naming the
    formats matplotlib writes when ``path``'s suffix is not one of them (no suffix: PNG)."""
    try:
        import matplotlib  # noqa: F401 - optional dependency
        from matplotlib.backend_bases import FigureCanvasBase
    except ImportError as exc:
        raise ValueError(f"{option} needs matplotlib, which is not installed: "
                         "pip install '.[plot]' (or pip install matplotlib)") from exc
    fmt = Path(path).suffix.lower().lstrip(".") if path else ""
    known = FigureCanvasBase.get_supported_filetypes()
    if fmt and fmt not in known:
        raise ValueError(f"{option} {path}: matplotlib cannot write .{fmt}; use one of "
                         + ", ".join(f".{k}" for k in sorted(known)))


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity; ``os.cpu_count()`` where the platform
    has no affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def check_common(args) -> None:
    """The numeric options every command may have, checked once (ValueError names them);
    ``--viscosity`` also at least :data:`MIN_VISCOSITY_PA_S`."""
    for name in ("viscosity", "density", "velocity", "depth", "rtol"):
        if getattr(args, name, None) is not None and not isinstance(getattr(args, name), list):
            check_positive(f"--{name}", getattr(args, name))
    if getattr(args, "viscosity", None) is not None and args.viscosity < MIN_VISCOSITY_PA_S:
        raise ValueError(f"--viscosity {args.viscosity:g} Pa s is below {MIN_VISCOSITY_PA_S:g} "
                         "Pa s, about a hundredth of the least viscous gas's (hydrogen, "
                         "8.8e-6 Pa s at 20 C): give the fluid's dynamic viscosity in Pa s")
    if getattr(args, "margin", None) is not None and not args.margin >= 0:
        raise ValueError(f"--margin must be >= 0 (packing units), got {args.margin!r}")
    for name in ("workers", "threads"):
        check_count(f"--{name}", getattr(args, name, None), MAX_WORKERS)


def load_packing(args, *, tables: bool = True):
    """(path, packing in metres) of ``args.packing`` (bundled scene if None) in ``args.units``;
    the scale warning, if any, as one stderr line, and first a ``note:`` progress line when
    the Q* tables are used for the first time on this machine (:func:`first_run_note`; not
    for a command that uses no table, ``tables=False``). A
    ``--depth`` thinner than the largest sphere of a packing at a grain's scale is refused
    (ValueError). A companion JSON whose container is of an unknown kind or malformed is
    refused here, before any work (:func:`read_container`)."""
    note = first_run_note(getattr(args, "policy", None)) if tables else None
    if note:
        log.info("note: %s", note)
    path = Path(args.packing) if args.packing else default_packing_path()
    packing = read_packing(path, units=args.units)
    check_three_dimensional(packing.centers, str(path))
    read_container(path)
    depth = getattr(args, "depth", None)
    msg = scale_warning(packing)
    if msg:                 # a packing in another unit, or dimensionless: its scale is the issue
        warn(msg)
    elif isinstance(depth, float) and packing.n and depth < 2.0 * float(packing.radii.max()):
        raise ValueError(f"--depth {depth:g} m is thinner than one grain of {path} (its largest "
                         f"sphere alone is {2e3 * float(packing.radii.max()):.3g} mm across): "
                         "give the bed depth in metres")
    return path, packing


def sample_box_m(args):
    """(``--sample`` box, ``--margin``) converted to metres (None stays None)."""
    s = UNITS[args.units]
    box = None if args.sample is None else [v * s for v in args.sample]
    margin = None if args.margin is None else args.margin * s
    return box, margin

"""Shared pieces of the network command-line tools (``network.solve``, ``.curve``, ``.throats``,
``.paths``): the packing/sample/units/air arguments, output-path checks, warning capture and the
exit-code convention (docs/cli.md).

Exit codes: 0 done, 1 the computation failed, 2 bad input. A failure prints one line
``error: ...`` on stderr naming the value, row or file, never a traceback (set
``GRAINFLOW_DEBUG=1`` to get one). Input, output paths included, is checked before anything is
computed or written. Numbers such as ``--viscosity -1.8e-5`` are read as values (and refused
with the option's own message), not as options.

Lengths that place something in the packing (``--sample``, ``--margin``, ``--entry``) are in
the packing file's unit (``--units``, default m); physical quantities (``--depth``,
``--velocity``, ``--viscosity``, ``--density``) are SI.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import logging
import os
import re
import sys
import tempfile
import warnings
from pathlib import Path

from ._air import MU_AIR_PA_S, P_ATM_PA, RHO_AIR_KG_M3, check_positive
from ._lean import keep_heap
from .packing import (UNITS, check_three_dimensional, default_packing_path, read_container,
                      read_packing, scale_warning)
from .flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

__all__ = ["EXIT_OK", "EXIT_FAILED", "EXIT_BAD_INPUT", "CliError", "CliParser", "bad_input",
           "computing", "run", "add_packing", "add_sample", "add_air", "check_outputs",
           "check_plot", "load_packing", "sample_box_m", "warn"]

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
#: Smallest ``--viscosity`` taken, Pa s: about a hundredth of hydrogen's (8.8e-6 Pa s at 20 °C),
#: the least viscous gas. Far below it the viscous term is lost beside the inertial one in the
#: Newton solve (Re_p 1e16 at 1e-20 Pa s: a gradient 8 times low, exit 0; at 1e-30 no
#: convergence after two minutes).
MIN_VISCOSITY_PA_S = 1e-7
#: a number, negative ones and exponents included: argparse's own pattern misses ``-1.8e-5``
_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.I)


class CliError(Exception):
    """One line for the user and the exit code (1 or 2) that goes with it."""

    def __init__(self, message: str, code: int = EXIT_BAD_INPUT):
        super().__init__(message)
        self.code = code


class _Help(argparse.HelpFormatter):
    """Appends ``(default: X)`` to an option's help unless it says its default already or the
    default is None/False (an output not written, a switch off)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (action.default not in (None, False, argparse.SUPPRESS) and action.option_strings
                and "default" not in text):
            text += " (default: %(default)s)"
        return text


class CliParser(argparse.ArgumentParser):
    """``ArgumentParser`` that reads ``-1.8e-5`` as a value and reports a bad option in one
    line (exit 2) instead of the usage block."""

    def __init__(self, *a, **kw):
        kw.setdefault("formatter_class", _Help)
        super().__init__(*a, **kw)
        self._negative_number_matcher = _NUMBER

    def error(self, message):
        raise CliError(f"{message} (see {self.prog} --help)")


def _message(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        return f"{exc.strerror}: {exc.filename}"
    return str(exc) or type(exc).__name__


@contextlib.contextmanager
def bad_input():
    """ValueError/OSError inside become exit 2 (the user's input is wrong)."""
    try:
        yield
    except (ValueError, OSError) as exc:
        raise CliError(_message(exc), EXIT_BAD_INPUT) from exc


@contextlib.contextmanager
def computing():
    """ValueError/RuntimeError/ArithmeticError/OSError inside become exit 1 (the computation
    or writing its output failed); exit 2 for an error that marks itself ``bad_input`` (found
    only by computing, e.g. a packing too small for its sample: ``EmptySampleError``)."""
    try:
        yield
    except (ValueError, RuntimeError, ArithmeticError, NotImplementedError, OSError) as exc:
        code = EXIT_BAD_INPUT if getattr(exc, "bad_input", False) else EXIT_FAILED
        raise CliError(_message(exc), code) from exc


def warn(message: str) -> None:
    """One ``warning:`` line on stderr."""
    print(f"warning: {' '.join(str(message).split())}", file=sys.stderr)


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
    """:func:`warn_validity` for the converged points of a curve: the largest Re_p, and the
    largest drop over ``depth_m`` (Pa) = gradient ``key`` (Pa/m) x depth."""
    ok = [p for p in points if p["converged"]]
    if ok:
        warn_validity(max(p["reynolds_particle"] for p in ok),
                      max(p[key] for p in ok) * depth_m)


class _WarningLines(logging.Handler):
    """Log records of level WARNING and above as one ``warning:`` line each, a message
    repeated within the run (once per axis, a file read twice) printed once."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.seen: set[str] = set()

    def emit(self, record):
        text = " ".join(record.getMessage().split())
        if text not in self.seen:
            self.seen.add(text)
            warn(text)


def _below_warning(record) -> bool:
    return record.levelno < logging.WARNING


#: handlers :func:`run` installed on the root logger, removed when the command ends
_INSTALLED: list = []


def progress_log(args, fmt: str = "[%(relativeCreated)7.0f ms] %(message)s") -> None:
    """Stage progress on stderr (INFO log lines) unless ``--quiet`` or logging is configured
    already (a test's or an embedding program's handlers); warnings go to :func:`run`'s
    ``warning:`` lines, not here."""
    root = logging.getLogger()
    if getattr(args, "quiet", False) or any(h not in _INSTALLED for h in root.handlers):
        return
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(fmt))
    handler.addFilter(_below_warning)
    root.addHandler(handler)
    _INSTALLED.append(handler)
    root.setLevel(min(root.level or logging.WARNING, logging.INFO))


def run(body, parser: argparse.ArgumentParser, argv=None, *,
        interrupted: str | None = None) -> int:
    """Parse ``argv``, call ``body(args)`` with numpy/scipy warnings captured, return its exit
    code; a :class:`CliError` (or any other exception: exit 1) becomes one ``error:`` line.
    Ctrl-C is exit 1 with one ``error: interrupted`` line, or ``interrupted: <interrupted>``
    where that text is given.

    Captured warnings do not reach the terminal; when there were any, one line says how many
    and quotes the first (the checks of the result decide whether it is good). The library's
    logged warnings (``logging``) become ``warning:`` lines, each distinct one once.
    """
    debug = os.environ.get("GRAINFLOW_DEBUG")
    root = logging.getLogger()
    level, mark = root.level, len(_INSTALLED)      # a run inside a run keeps the outer's
    lines = _WarningLines()
    root.addHandler(lines)
    _INSTALLED.append(lines)
    try:
        return _run(body, parser, argv, debug, interrupted)
    finally:
        while len(_INSTALLED) > mark:
            root.removeHandler(_INSTALLED.pop())
        root.setLevel(level)


def _run(body, parser, argv, debug, interrupted=None) -> int:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = body(parser.parse_args(argv))
        except CliError as exc:
            print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
            code = exc.code
        except KeyboardInterrupt:
            print(f"interrupted: {interrupted}" if interrupted else
                  "error: interrupted; no output written after the interruption", file=sys.stderr)
            code = EXIT_FAILED
        except Exception as exc:  # noqa: BLE001 - the convention: one line, no traceback
            if debug:
                raise
            print(f"error: {type(exc).__name__}: {_message(exc)} (an internal error; "
                  "GRAINFLOW_DEBUG=1 shows the traceback)", file=sys.stderr)
            code = EXIT_FAILED
    distinct = list(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    if distinct:
        warn(f"{len(caught)} numerical warning(s) from numpy/scipy suppressed "
             f"({len(distinct)} distinct; first: {distinct[0][:160]})")
    return code


def finish(code: int):
    """End the command process with exit status ``code`` without tearing the interpreter down.

    An ordinary exit frees every module, array and solver hierarchy one by one: 0.05-0.1 s
    after a 5 000-sphere solve (``docs/network-bench.md``). By the time a command
    returns its outputs are written and closed (its ``with`` blocks) and every future of its
    worker threads awaited, so ``finish`` flushes stdout and stderr, runs the ``atexit``
    handlers (logging's flush, multiprocessing's clean-up), flushes again (what a handler
    printed) and ends with :func:`os._exit`. A stream that cannot be flushed (a reader that
    closed the pipe) loses what it could not take, as it would at an ordinary exit; an
    interpreter without ``atexit._run_exitfuncs`` exits the ordinary way.
    """
    run_handlers = getattr(atexit, "_run_exitfuncs", None)
    if run_handlers is None:
        sys.exit(code)
    _flush()
    run_handlers()
    _flush()
    os._exit(code)


def _flush() -> None:
    """Flush stdout and stderr, ignoring a stream that is closed or whose reader has gone."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()


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
        ap.add_argument("--inertial-law", default=DEFAULT_INERTIAL_LAW,
                        choices=tuple(INERTIAL_LAWS),
                        help="per-conduit inertial loss: window = the law from resolved 3-D "
                             "pore bodies in a chain, its two constants from each conduit's "
                             "window ratio (default), chain = the same with one pore's "
                             "constants (the default of sessions 8-10), pore = one body alone "
                             "(session 7's default), onset = laminar-jet expansion with X/(1+X) "
                             "onset (before session 7), quadratic = flat-profile K q|q| from the "
                             "start (docs/inertial-flow.md)")


# ------------------------------------------------------------------ checks
def check_outputs(*, inputs=(), **paths) -> None:
    """ValueError unless every given output path (``option=path``; None skipped) can be
    written: its folder exists and takes a new file (tried: a temporary file made and removed,
    which ``os.access`` cannot tell for root or a read-only mount), it is not a folder, and no
    two outputs, nor an output and one of ``inputs`` (``(what, path)`` pairs, e.g.
    :func:`packing_inputs`), name the same file."""
    check_output_list([("--" + k.replace("_", "-"), p) for k, p in paths.items()], inputs)


def check_output_list(pairs, inputs=()) -> None:
    """:func:`check_outputs` for ``(option, path)`` pairs (an option may come more than once)."""
    seen = {Path(p).resolve(): what for what, p in inputs if p is not None}
    for opt, p in pairs:
        if p is None:
            continue
        path = Path(p)
        folder = path.parent if str(path.parent) else Path(".")
        if path.is_dir():
            raise ValueError(f"{opt} {p}: is a folder, give a file name")
        if not folder.is_dir():
            raise ValueError(f"{opt} {p}: folder {folder} does not exist")
        key = path.resolve()
        if key in seen:
            raise ValueError(f"{opt} {p}: the same file as {seen[key]}; give another name")
        seen[key] = f"{opt} {p}"
        check_writable_folder(folder, f"{opt} {p}")
        if path.exists() and not os.access(path, os.W_OK):
            raise ValueError(f"{opt} {p}: file exists and is not writable")


def check_writable_folder(folder, what: str) -> None:
    """ValueError naming ``what`` unless a file can be made in ``folder``: tried with a temporary
    file, removed at once (``os.access`` says yes to root even on ``/proc``)."""
    try:
        tempfile.TemporaryFile(dir=folder, prefix=".grainflow-").close()
    except OSError as exc:
        raise ValueError(f"{what}: folder {folder} is not writable "
                         f"({exc.strerror or exc})") from None


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
        if getattr(args, name, 1) < 1:
            raise ValueError(f"--{name} must be >= 1, got {getattr(args, name)!r}")


def load_packing(args):
    """(path, packing in metres) of ``args.packing`` (bundled scene if None) in ``args.units``;
    the scale warning, if any, as one stderr line. A companion JSON whose container is of an
    unknown kind or malformed is refused here, before any work (:func:`read_container`)."""
    path = Path(args.packing) if args.packing else default_packing_path()
    packing = read_packing(path, units=args.units)
    check_three_dimensional(packing.centers, str(path))
    read_container(path)
    keep_heap(packing.n)
    msg = scale_warning(packing)
    if msg:
        warn(msg)
    return path, packing


def sample_box_m(args):
    """(``--sample`` box, ``--margin``) converted to metres (None stays None)."""
    s = UNITS[args.units]
    box = None if args.sample is None else [v * s for v in args.sample]
    margin = None if args.margin is None else args.margin * s
    return box, margin

"""The command-line base every grainflow command shares: exit codes, the one-line parser, the
run wrapper and the output check.

Exit codes: 0 done, 1 the computation failed, 2 bad input. A failure prints one line
``error: ...`` on stderr naming the value, row or file, never a traceback (set
``GRAINFLOW_DEBUG=1`` to get one). Every output path is checked before any work
(:func:`check_output_list`): writable, not a folder, and not the same file as an input or as
another output. Numbers such as ``--viscosity -1.8e-5`` are read as values (and refused with
the option's own message), not as options.
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

__all__ = ["EXIT_OK", "EXIT_FAILED", "EXIT_BAD_INPUT", "CliError", "CliParser", "bad_input",
           "computing", "run", "warn", "progress_log", "finish", "check_outputs",
           "check_output_list", "check_writable_folder", "same_file", "check_count",
           "MAX_WORKERS", "MAX_SPHERES", "MAX_REPEATS"]

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
#: a number, negative ones and exponents included: argparse's own pattern misses ``-1.8e-5``
_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.I)


class CliError(Exception):
    """One line for the user and the exit code (1 or 2) that goes with it; ``label`` starts
    the line (``error``, or e.g. ``unstable, not written`` for a simulation that blew up)."""

    def __init__(self, message: str, code: int = EXIT_BAD_INPUT, label: str = "error"):
        super().__init__(message)
        self.code = code
        self.label = label


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
            print(f"{exc.label}: {' '.join(str(exc).split())}", file=sys.stderr)
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



#: Largest ``--workers``/``--threads`` any command takes (far above any machine's cores: a
#: larger number is a typing slip, and each worker is a process or a thread started)
MAX_WORKERS = 1024
#: Largest count of spheres, particles or grains a command is asked to make or take
MAX_SPHERES = 10_000_000
#: Largest ``--repeat(s)`` of a benchmark
MAX_REPEATS = 1000


def check_count(option: str, value, high: int, low: int = 1) -> None:
    """ValueError naming ``option`` unless ``value`` (None: not given) is a whole number in
    ``low``..``high``: every count or size option is bounded before any work.

    >>> check_count("--workers", 4, MAX_WORKERS)
    >>> check_count("--workers", 10**6, MAX_WORKERS)
    Traceback (most recent call last):
    ...
    ValueError: --workers must be 1 to 1024, got 1000000
    """
    if value is None:
        return
    if isinstance(value, bool) or int(value) != value or not low <= value <= high:
        raise ValueError(f"{option} must be {low} to {high}, got {value}")


def check_outputs(*, inputs=(), **paths) -> None:
    """ValueError unless every given output path (``option=path``; None skipped) can be
    written: see :func:`check_output_list` (``inputs``: ``(what, path)`` pairs)."""
    check_output_list([("--" + k.replace("_", "-"), p) for k, p in paths.items()], inputs)


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name one file: the same real path (links and ``..``
    resolved), or, where both exist, one file under two names (:func:`os.path.samefile`: a
    hard link, a bind mount)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):           # one of them does not exist (yet)
        return False


def check_output_list(pairs, inputs=(), *, make_folders: bool = False, others=()) -> None:
    """ValueError naming the option unless every output can be written and none is an input.

    Parameters
    ----------
    pairs : iterable of (option, path)
        The files the command will write, every one of them (an option may come more than
        once: a folder's files each with the folder's option); None paths are skipped.
    inputs : iterable of (what, path)
        The files it reads (e.g. ``("--fan", path)``).
    make_folders : bool
        Missing folders are made when the output is written (the nearest existing folder must
        take a new file); otherwise the output's folder must exist.
    others : iterable of (option, path)
        Outputs checked by another call (under other folder rules), compared with these.

    Each output must not be a folder, its folder must take a new file (tried: a temporary
    file made and removed, which ``os.access`` cannot tell for root or a read-only mount), an
    existing file must be writable, and no output may be the same file (:func:`same_file`) as
    an input or as another output: the message names both.
    """
    seen = [(what, p) for what, p in inputs if p is not None]
    n_inputs = len(seen)
    seen += [(what, p) for what, p in others if p is not None]
    for opt, p in pairs:
        if p is None:
            continue
        path = Path(p)
        where = f"{opt} {p}"
        if path.is_dir():
            raise ValueError(f"{where}: is a folder, give a file name")
        folder = path.parent if str(path.parent) else Path(".")
        if make_folders:
            while not folder.is_dir():
                if folder.exists() or folder == folder.parent:
                    raise ValueError(f"{where}: {folder} is not a folder")
                folder = folder.parent
        elif not folder.is_dir():
            raise ValueError(f"{where}: folder {folder} does not exist")
        for k, (what, q) in enumerate(seen):
            if same_file(path, q):
                kind = "an input" if k < n_inputs else "another output"
                raise ValueError(f"{where}: the same file as {what} {q} ({kind}); give another "
                                 "name")
        seen.append((opt, p))
        check_writable_folder(folder, where)
        if path.exists() and not os.access(path, os.W_OK):
            raise ValueError(f"{where}: file exists and is not writable")


def check_writable_folder(folder, what: str) -> None:
    """ValueError naming ``what`` unless a file can be made in ``folder``: tried with a temporary
    file, removed at once (``os.access`` says yes to root even on ``/proc``)."""
    try:
        tempfile.TemporaryFile(dir=folder, prefix=".grainflow-").close()
    except OSError as exc:
        raise ValueError(f"{what}: folder {folder} is not writable "
                         f"({exc.strerror or exc})") from None

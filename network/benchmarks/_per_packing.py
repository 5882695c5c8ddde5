"""Per packing: the whole ``python -m network.solve FILE`` command, wall time.

What a user waits for: a fresh interpreter, the imports, reading the file, every stage,
printing, exit. Each command runs ``repeats`` times after one warm-up run (which writes the
bytecode caches and the Q* table's derived arrays, as a user's first run does); the bench
packings of the scaling part and the bundled scene, ``--stokes`` (file to permeability, the
target) and the default command (with inertia). The child's environment is the user's (without
this command process's ``OPENBLAS_NUM_THREADS``, ``network._lean``) and drops
``PYTHONDONTWRITEBYTECODE`` so that Python caches bytecode as it does by default. The speed
targets (:data:`TARGETS_S`) are 0.8 s at 5 000 spheres and 2 s at 20 000.

With ``yade=True`` (``network.bench --per-packing --yade``) YADE's FlowEngine (its own
triangulation and Cholesky solve) runs on the same packings on this machine
(``docs/scripts/yade_flowengine.py`` through ``yade -n -x``; Debian's ``yade`` package): its
first ``emulateAction`` (FlowEngine's triangulation, factorisation and solve, without YADE's
start-up) and its whole command, one YADE run right after each of ours on the ``--stokes``
rows, so that each pair sees the same host speed (a shared host's speed moves within an hour):
the row carries the paired ratio ours / FlowEngine. Our counted runs follow one of ours, as
without ``--yade``; the run right after each YADE run is timed apart (``ours_after_yade_s``),
so that the two can be compared.

A shared host's speed also moves from one hour to the next, so a speed-up is judged against
other code on the same host at the same time: ``baseline=DIR`` (``network.bench --per-packing
--baseline DIR``, DIR a source checkout, or a commit of this checkout's git, extracted for the
run: ``--baseline REF``) runs DIR's own command, its packages imported from DIR, right after
each counted ``--stokes`` run of ours; the row carries the paired speed-up baseline / ours.
"""

from __future__ import annotations

import io
import os
import re
import shutil
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

from .._lean import user_environment
from ..packing import default_packing_path
from ._scaling import packing_file

#: Wall-time targets of ``python -m network.solve FILE --stokes`` by sphere count, s.
TARGETS_S = {5000: 0.8, 20000: 2.0}
MODES = {"stokes": ["--stokes"], "default": []}


#: YADE's FlowEngine script (a research script beside the docs; present in a source checkout).
YADE_SCRIPT = Path(__file__).resolve().parents[2] / "docs" / "scripts" / "yade_flowengine.py"
_YADE_FIRST = re.compile(r"first emulateAction ([0-9.]+) s")


def yade_available() -> bool:
    """Whether the ``yade`` program and the FlowEngine script are here."""
    return shutil.which("yade") is not None and YADE_SCRIPT.is_file()


def yade_run(path: Path) -> tuple[float, float] | None:
    """One YADE run on ``path``: (FlowEngine's first solve, the whole command) in s, or None
    where ``yade`` or the script is missing."""
    exe = shutil.which("yade")
    if exe is None or not YADE_SCRIPT.is_file():
        return None
    t0 = time.perf_counter()
    out = subprocess.run([exe, "-n", "-x", str(YADE_SCRIPT), str(path)], env=user_environment(),
                         capture_output=True, text=True, check=False)
    dt = time.perf_counter() - t0
    m = _YADE_FIRST.search(out.stdout + out.stderr)
    if out.returncode != 0 or m is None:
        raise RuntimeError(f"yade on {path} exited {out.returncode}: "
                           f"{(out.stdout + out.stderr).strip()[-200:]}")
    return float(m.group(1)), dt


def yade_summary(runs: list, ours: list) -> dict | None:
    """FlowEngine and whole-command times of YADE ``runs`` (from :func:`yade_run`), each run
    right after the one of ``ours`` (s) at the same index: medians, and the paired ratio
    ours / FlowEngine (median; how many pairs ours was faster). None without YADE."""
    if not runs or runs[0] is None:
        return None
    engine, whole = [r[0] for r in runs], [r[1] for r in runs]
    ratio = [a / e for a, e in zip(ours, engine)]
    return {"flowengine_s": engine, "command_s": whole,
            "flowengine_median_s": statistics.median(engine),
            "command_median_s": statistics.median(whole),
            "ratio_to_flowengine": ratio,
            "ratio_to_flowengine_median": statistics.median(ratio),
            "faster_than_flowengine_runs": sum(q < 1.0 for q in ratio)}


#: the source checkout this package runs from (a ``--baseline`` revision is taken from its git)
REPO = Path(__file__).resolve().parents[2]


def baseline_revision(spec) -> str | None:
    """The full commit of ``spec`` in this checkout's git where ``spec`` is not a directory
    (None where it is one); ValueError where it is neither a directory nor a commit here."""
    if Path(spec).is_dir():
        return None
    out = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--verify", "--quiet",
                          f"{spec}^{{commit}}"], capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise ValueError(f"--baseline {spec}: neither a directory nor a commit of the git "
                         f"checkout {REPO}")
    return out.stdout.strip()


def baseline_source(spec, workdir=None) -> dict:
    """The baseline's command environment: ``{"dir", "commit", "env", "temporary"}``. ``spec``
    a source checkout (its packages first on PYTHONPATH) or a commit of this checkout's git,
    extracted (``git archive``) into a new directory under ``workdir`` that the caller
    removes (``temporary``). ValueError where ``network`` is not imported from there."""
    rev = baseline_revision(spec)
    temporary = None
    if rev is not None:
        temporary = Path(tempfile.mkdtemp(prefix=f"baseline-{rev[:7]}-", dir=workdir))
        arc = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", rev],
                             capture_output=True, check=False)
        if arc.returncode != 0:
            shutil.rmtree(temporary, ignore_errors=True)
            raise ValueError(f"--baseline {spec}: git archive failed: "
                             f"{arc.stderr.decode(errors='replace').strip()[-120:]}")
        with tarfile.open(fileobj=io.BytesIO(arc.stdout)) as tar:
            tar.extractall(temporary, filter="data")
    d = Path(temporary or spec).resolve()
    try:
        if not (d / "network" / "solve.py").is_file():
            raise ValueError(f"--baseline {spec}: no network/solve.py there (not a source "
                             "checkout of grainflow)")
        env = user_environment()
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPATH"] = str(d) + (os.pathsep + env["PYTHONPATH"]
                                      if env.get("PYTHONPATH") else "")
        out = subprocess.run([sys.executable, "-c", "import network; print(network.__file__)"],
                             cwd=d, env=env, capture_output=True, text=True, check=False)
        where = Path(out.stdout.strip()).resolve().parent.parent if out.returncode == 0 else None
        if where != d:
            raise ValueError(f"--baseline {spec}: its network package is not imported from "
                             f"there ({out.stdout.strip() or out.stderr.strip()[-120:]})")
    except ValueError:
        if temporary is not None:
            shutil.rmtree(temporary, ignore_errors=True)
        raise
    if rev is None:
        head = subprocess.run(["git", "-C", str(d), "rev-parse", "HEAD"],
                              capture_output=True, text=True, check=False)
        rev = head.stdout.strip() if head.returncode == 0 else None
    return {"dir": str(d), "commit": rev[:7] if rev else None, "env": env,
            "temporary": temporary}


def baseline_summary(source: dict, runs: list, ours: list) -> dict:
    """Times of the baseline's runs, each right after the run of ``ours`` at the same index:
    medians and the paired speed-up baseline / ours."""
    ratio = [b / a for a, b in zip(ours, runs)]
    return {"dir": source["dir"], "commit": source["commit"], "times_s": runs,
            "median_s": statistics.median(runs), "speedup": ratio,
            "speedup_median": statistics.median(ratio), "speedup_min": min(ratio)}


def per_packing(sizes, workdir: Path, seed: int, repeats: int = 7,
                bundled: bool = True, yade: bool = False, baseline=None) -> list[dict]:
    """Wall times of ``python -m network.solve`` on the bench packings of ``sizes`` (and the
    bundled scene): one row per packing and mode with min, median and max over ``repeats``;
    with ``yade`` the ``--stokes`` rows of the bench packings carry the :func:`yade_summary`
    of YADE runs interleaved with ours: each run of ours that the row counts follows another
    of ours (as without YADE) and is followed by YADE's; that other run, the one right after
    YADE's, is timed apart (``ours_after_yade_s``). With ``baseline`` (a directory or a commit,
    or what :func:`baseline_source` made of one; a temporary extraction is removed at the end)
    those rows also carry the :func:`baseline_summary` of the baseline's command run right
    after each counted run of ours (after one warm-up)."""
    env = user_environment()            # as a user starts it: not this process's additions
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    source = (baseline if isinstance(baseline, dict) or baseline is None
              else baseline_source(baseline, workdir))
    try:
        return _per_packing_rows(sizes, workdir, seed, repeats, bundled, yade, source, env)
    finally:
        if source is not None and source["temporary"] is not None:
            shutil.rmtree(source["temporary"], ignore_errors=True)


def _per_packing_rows(sizes, workdir, seed, repeats, bundled, yade, source, env):
    """:func:`per_packing`'s rows, the baseline (if any) prepared."""
    cases = [(n, packing_file(n, workdir, seed)) for n in sizes]
    if bundled:
        cases.append((None, default_packing_path()))
    rows = []
    for n, path in cases:
        for mode, extra in MODES.items():
            cmd = [sys.executable, "-m", "network.solve", str(path), "--quiet", *extra]
            times, yade_runs, after_yade, base_runs = [], [], [], []
            beside = yade and mode == "stokes" and n is not None
            apart = beside and yade_available()
            paired = source is not None and mode == "stokes" and n is not None
            for i in range(repeats + 1):
                dt = _timed(cmd, env)
                if i and apart:
                    # this run came right after YADE's: kept apart; the counted run follows
                    # one of ours, as without YADE
                    after_yade.append(dt)
                    dt = _timed(cmd, env)
                if paired:                  # the baseline's own warm-up, then one after each
                    b = _timed(cmd, source["env"], cwd=source["dir"])
                    if i:
                        base_runs.append(b)
                if i:                                   # the first run is the warm-up
                    times.append(dt)
                    if beside:              # YADE right after each run: the same host speed
                        yade_runs.append(yade_run(path))
            row = {"packing": str(path), "n_spheres": n, "mode": mode, "runs": repeats,
                   "min_s": min(times), "median_s": statistics.median(times),
                   "max_s": max(times), "times_s": times,
                   "target_s": TARGETS_S.get(n) if mode == "stokes" else None,
                   "loadavg_after": os.getloadavg()[0]}
            if row["target_s"] is not None:
                row["met"] = row["median_s"] <= row["target_s"]
            if beside:
                row["yade_here"] = yade_summary(yade_runs, times)
                if after_yade:
                    row["yade_here"]["ours_after_yade_s"] = after_yade
                    row["yade_here"]["ours_after_yade_median_s"] = statistics.median(after_yade)
            if paired:
                row["baseline"] = baseline_summary(source, base_runs, times)
            rows.append(row)
            print("  " + per_packing_line(row), flush=True)
    return rows


def _timed(cmd, env, cwd=None) -> float:
    """Wall seconds of one run of ``cmd`` (in ``cwd``); RuntimeError naming it where it fails."""
    t0 = time.perf_counter()
    out = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, check=False)
    dt = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {out.returncode}: "
                           f"{out.stderr.strip()[-200:]}")
    return dt


def per_packing_line(row: dict) -> str:
    """One printed line of a :func:`per_packing` row."""
    name = f"{row['n_spheres']} spheres" if row["n_spheres"] else "bundled scene"
    tail = ""
    if row.get("target_s") is not None:
        tail = f"; target {row['target_s']:.1f} s: {'met' if row['met'] else 'MISSED'}"
    here = row.get("yade_here")
    if here:
        tail += (f"; YADE here, each run after one of ours: FlowEngine "
                 f"{here['flowengine_median_s']:.2f} s, whole command "
                 f"{here['command_median_s']:.2f} s (medians of {len(here['command_s'])}); "
                 f"ours / FlowEngine {here['ratio_to_flowengine_median']:.2f} (faster in "
                 f"{here['faster_than_flowengine_runs']} of {len(here['command_s'])} pairs)")
        after = here.get("ours_after_yade_median_s")
        if after is not None:
            tail += f"; ours right after a YADE run: median {after:.3f} s"
    elif "yade_here" in row:
        tail += "; YADE here: not installed"
    base = row.get("baseline")
    if base:
        tail += (f"; baseline {base['commit'] or base['dir']} right after each: median "
                 f"{base['median_s']:.3f} s, speed-up {base['speedup_median']:.2f}x (min "
                 f"{base['speedup_min']:.2f})")
    return (f"{name:>16s} {row['mode']:>8s}: median {row['median_s']:.3f} s, min "
            f"{row['min_s']:.3f}, max {row['max_s']:.3f} over {row['runs']} runs (load "
            f"{row['loadavg_after']:.2f}){tail}")

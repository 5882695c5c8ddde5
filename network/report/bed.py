r"""Which bed ``network.report`` solves, and packing a new one with ``dem.pack``.

The bed is chosen before anything is written (:func:`plan_bed`), in this order:

1. ``--packing FILE``: the user's bed, never packed anew;
2. ``--move-along-band``: the bundled bed, the prediction moved along the band's slope;
3. ``--seed N`` given, or a ``--porosity P`` farther than :data:`PACK_TOL` (dem.pack's
   tolerance, 0.005) from the bundled bed's own porosity, and the grain has a multi-sphere
   template in ``dem.templates`` (:data:`TEMPLATE_GRAINS`): a **new bed**, packed by
   ``python -m dem.pack --scene box --size LX LY --height H --grain G --porosity P --seed N``
   in the bundled bed's box (``--bed-box`` otherwise), at P = ``--porosity`` or the grain's
   measured loose-fill porosity; the report is then for the new bed's own porosity
   (dem.pack reaches P within 0.005 in network's sample region, or refuses, exit 2, naming
   the range it reaches: measured once per grain, box and seed, then kept); a P outside the
   range recorded for the grain in that box and seed (:func:`network.core.recorded_reach`) is
   refused at once, nothing packed;
4. else the bundled bed (the default run: seconds).

dem.pack runs as a subprocess (network does not import dem; the CSV and its companion JSON are
the file contract) into a temporary folder inside ``--bed-dir``; its files are moved into place
only when it succeeded, so an interrupted or failed packing leaves nothing. A bed of the same
grain, box, porosity and seed already in ``--bed-dir`` (its JSON says so) is reused.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .._cli import EXIT_BAD_INPUT, EXIT_FAILED, CliError, computing
from .._grains import BED
from ..core import reach_refusal, recorded_reach
from .porosity import bundled_packing, packing_meta

__all__ = ["TEMPLATE_GRAINS", "PACK_TOL", "add_bed_options", "plan_bed", "bed_paths", "find_bed",
           "pack_bed", "pack_command", "prepare_bed", "bed_label", "bed_json", "check_bed_dir",
           "user_bed_json"]

#: grains with a multi-sphere template in ``dem.templates.TEMPLATE_GRAINS`` (a copy: network may
#: not import dem; tests/network/test_report_bed.py checks that the two agree)
TEMPLATE_GRAINS = ("soybean", "wheat", "shelled_corn", "barley", "canola")
#: dem.pack --porosity's tolerance (its default --porosity-tol): a request this close to the
#: bundled bed's own porosity is that bed
PACK_TOL = 0.005
#: dem.pack's step cap per stage for the report's beds (dem.pack's own default for grains is
#: 60 000): shelled corn in the 0.08 m cube reached equilibrium only after 119 400 steps
#: (docs/report.md); the cap only bounds a bed that never settles, a settled one stops earlier
PACK_MAX_STEPS = 240_000
#: the project root that holds ``dem/`` beside ``network/`` (the subprocess's PYTHONPATH)
_ROOT = Path(__file__).resolve().parents[2]


def add_bed_options(ap) -> None:
    """``--seed``, ``--bed-dir``, ``--bed-box``, ``--move-along-band``, ``--band-seed``."""
    ap.add_argument("--seed", type=int, default=None,
                    help="pack a new bed of the grain with this seed (dem.pack, minutes; "
                         f"grains with a template: {', '.join(TEMPLATE_GRAINS)}) at --porosity "
                         "or the grain's measured loose-fill porosity, in the bundled bed's box; "
                         "default: the bundled bed")
    ap.add_argument("--bed-dir", default=None, metavar="DIR",
                    help="folder of the beds packed anew (made if missing); a bed of the same "
                         "grain, box, porosity and seed already there is reused (default: "
                         "beds/ in the figures' folder, report_<grain>/beds)")
    ap.add_argument("--bed-box", nargs=3, type=float, default=None, metavar=("LX", "LY", "H"),
                    help="box of a bed packed anew, m (default: the bundled bed's)")
    ap.add_argument("--move-along-band", action="store_true",
                    help="never pack: solve the bundled bed and move the prediction along the "
                         "band's computed slope to --porosity (seconds)")
    ap.add_argument("--band-seed", type=int, default=1,
                    help="first seed of the porosity band's sphere packings (seed, seed + 1)")


def _box(meta: dict):
    c = meta.get("container") if isinstance(meta, dict) else None
    if not isinstance(c, dict) or c.get("kind") != "box":
        return None
    try:
        lx, ly = (float(v) for v in c["size_m"])
        return lx, ly, float(c["fill_height_m"])
    except (KeyError, TypeError, ValueError):
        return None


def plan_bed(grain: str, *, porosity, seed, packing, move_along_band: bool, bed_box,
             bed_dir) -> dict:
    """The bed of a report, decided from the options alone (no file written).

    Returns a dict: ``action`` (``"user"``, ``"bundled"`` or ``"pack"``), ``packing`` (the
    path, None for a bed still to pack), ``not_packed`` (why no bed is packed, None when one
    is or none was asked for) and, for ``"pack"``, ``porosity`` (P), ``porosity_why``,
    ``seed``, ``box`` (lx, ly, h m) and ``bed_dir``. ValueError for input that cannot work.
    """
    plan = {"grain": grain, "action": "user", "packing": packing, "not_packed": None,
            "seed": seed, "move_along_band": bool(move_along_band)}
    if packing is not None:
        if seed is not None or porosity is not None:
            plan["not_packed"] = (f"--packing {packing} given: the report uses that bed as it "
                                  "is" + ("" if grain in TEMPLATE_GRAINS else
                                          f" ({grain} has no multi-sphere template in dem)"))
        return plan
    bundled = bundled_packing(grain)
    meta = packing_meta(bundled) if bundled is not None else {}
    own = meta.get("porosity_network_region")
    plan.update(action="bundled", packing=None if bundled is None else str(bundled))
    if move_along_band:
        if seed is not None:
            plan["not_packed"] = "--move-along-band: the bundled bed, moved along the band"
        if bundled is None:
            raise ValueError(f"--move-along-band needs a bundled bed; {grain} has none")
        return plan
    far = porosity is not None and (own is None or abs(porosity - own) > PACK_TOL)
    if seed is None and not far:
        if bundled is None:
            raise ValueError(
                f"no bundled packing for {grain}: give --porosity P or --seed N to pack one "
                f"(dem.pack, minutes), or --packing FILE")
        return plan
    why = ("--seed given" if seed is not None else
           f"--porosity {porosity:g} is more than {PACK_TOL} from the bundled bed's own "
           f"{own:.4f}" if own is not None else f"--porosity {porosity:g}")
    if grain not in TEMPLATE_GRAINS:
        plan["not_packed"] = (f"{why}, but {grain} has no multi-sphere template in dem "
                              f"(dem.templates: {', '.join(TEMPLATE_GRAINS)}), so no bed is "
                              "packed anew")
        if bundled is None:
            raise ValueError(f"no bundled packing for {grain} and no template to pack one: "
                             "give --packing FILE")
        return plan
    p_why = "--porosity (the user's)"
    if porosity is None:
        porosity = BED[grain].loose_fill_porosity
        if porosity is None:
            raise ValueError(f"--seed packs {grain} at its measured loose-fill porosity, and "
                             f"{grain} has none (docs/grain-library.md): give --porosity P")
        lo, hi = BED[grain].bulk_porosity
        p_why = (f"the grain's measured loose-fill bulk porosity, middle of {lo:g}-{hi:g} "
                 f"({BED[grain].bulk_porosity_source})")
    if seed is None:
        seed = int(meta.get("seed", 1))
    box = bed_box if bed_box is not None else _box(meta)
    if box is None:
        raise ValueError(f"no bundled bed of {grain} to take the box from: give --bed-box LX LY "
                         "H (m), e.g. 0.04 0.04 0.04 (network/data/README.md, docs/report.md)")
    box = tuple(float(v) for v in box)
    if not all(v > 0 and v < 10 for v in box):
        raise ValueError(f"--bed-box must be three lengths in (0, 10) m, got {list(box)}")
    rec = recorded_reach(grain, {"kind": "box", "size_m": list(box[:2]), "fill_height_m": box[2]},
                         int(seed))
    if rec is not None and not rec["range"][0] - rec["tol"] <= porosity <= rec["range"][1] \
            + rec["tol"]:
        raise ValueError(f"{reach_refusal(porosity, grain, rec)}; no bed packed")
    d = check_bed_dir(bed_dir)
    plan.update(action="pack", packing=None, porosity=float(porosity), porosity_why=p_why,
                seed=int(seed), box=box, bed_dir=str(d), why=why)
    if (bundled is not None and bed_box is None and int(seed) == int(meta.get("seed", -1))
            and meta.get("porosity_search", {}).get("target") == float(porosity)):
        plan.update(action="bundled", packing=str(bundled), not_packed=(
            f"the bundled bed is dem.pack's packing of {grain} at {porosity:g} with seed {seed} "
            "in this box: the same bed"))
    return plan


def check_bed_dir(bed_dir) -> Path:
    """``bed_dir`` as a Path; ValueError naming ``--bed-dir`` when it, or the nearest of its
    folders that exists, is not a folder or not writable (missing folders are made on packing)."""
    d = Path(bed_dir)
    for p in [d, *d.parents]:
        if p.exists():
            if not p.is_dir():
                raise ValueError(f"--bed-dir {bed_dir}: {p} exists and is not a folder")
            if not os.access(p, os.W_OK | os.X_OK):
                raise ValueError(f"--bed-dir {bed_dir}: folder {p} is not writable")
            break
    return d


def bed_paths(plan: dict) -> Path:
    """The CSV of a plan's bed in its folder: ``<grain>_<lx>x<ly>x<h>m_e<P>_seed<N>.csv``."""
    lx, ly, h = plan["box"]
    name = f"{plan['grain']}_{lx:g}x{ly:g}x{h:g}m_e{plan['porosity']:.4f}_seed{plan['seed']}.csv"
    return Path(plan["bed_dir"]) / name


def _matches(meta: dict, plan: dict) -> bool:
    s = meta.get("porosity_search", {})
    return (meta.get("template") == plan["grain"] and meta.get("seed") == plan["seed"]
            and _box(meta) is not None
            and all(abs(a - b) < 1e-12 for a, b in zip(_box(meta), plan["box"]))
            and isinstance(s.get("target"), (int, float))
            and abs(s["target"] - plan["porosity"]) < 1e-12
            and meta.get("converged", True) is not False)


def find_bed(plan: dict) -> Path | None:
    """The plan's bed if ``--bed-dir`` holds it already (its JSON names the same grain, seed,
    box and target porosity, and the CSV is there), else None."""
    p = bed_paths(plan)
    if p.is_file() and _matches(packing_meta(p), plan):
        return p
    return None


def pack_command(plan: dict, out, *, quiet: bool = False) -> list[str]:
    """The dem.pack command line of a plan, writing ``out``."""
    lx, ly, h = plan["box"]
    cmd = [sys.executable, "-m", "dem.pack", "--scene", "box", "--size", f"{lx:g}", f"{ly:g}",
           "--height", f"{h:g}", "--grain", plan["grain"], "--porosity", repr(plan["porosity"]),
           "--porosity-tol", repr(PACK_TOL), "--max-steps", str(PACK_MAX_STEPS),
           "--seed", str(plan["seed"]), "--out", str(out)]
    return cmd + (["--quiet"] if quiet else [])


def _last_error(lines) -> str:
    for line in reversed(lines):
        s = line.strip()
        for tag in ("error:", "unstable, not written:", "interrupted:"):
            if s.startswith(tag):
                return s[len(tag):].strip()
    return lines[-1].strip() if lines else "no message"


def pack_bed(plan: dict, *, quiet: bool = False) -> tuple[Path, dict]:
    """Pack the plan's bed with dem.pack (its progress on stderr, as it comes) into a temporary
    folder in ``bed_dir``, then move the CSV, ``.grains.csv`` and JSON into place; returns
    (csv path, info: command, seconds, reused). A bed already there is reused (seconds).

    dem.pack's refusal (exit 2: the porosity it cannot reach, with the range it reaches)
    becomes a :class:`CliError` with exit 2; any other failure exit 1; Ctrl-C stops dem.pack,
    removes the temporary folder and is exit 1. Nothing is left half-written.
    """
    final = bed_paths(plan)
    found = find_bed(plan)
    if found is not None:
        return found, {"reused": True, "seconds": 0.0, "command": None}
    d = Path(plan["bed_dir"])
    made_dirs = [p for p in [d, *d.parents] if not p.exists()]
    d.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".packing-", dir=d))
    done = False
    cmd = pack_command(plan, tmp / final.name, quiet=quiet)
    env = dict(os.environ, PYTHONUNBUFFERED="1",
               PYTHONPATH=os.pathsep.join([str(_ROOT)] + [p for p in [
                   os.environ.get("PYTHONPATH")] if p]))
    lines: list[str] = []
    t0 = time.perf_counter()
    proc = None
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, text=True, env=env)
        with proc.stdout:
            for line in proc.stdout:
                lines.append(line)
                if not line.startswith(("error:", "interrupted:", "unstable")) and not quiet:
                    print(f"[dem.pack] {line.rstrip()}", file=sys.stderr, flush=True)
        code = proc.wait()
        if code != 0:
            msg = f"dem.pack (packing {plan['grain']} at porosity {plan['porosity']:g}, seed " \
                  f"{plan['seed']}): {_last_error(lines)}"
            raise CliError(msg, EXIT_BAD_INPUT if code == EXIT_BAD_INPUT else EXIT_FAILED)
        made = [tmp / final.name, tmp / (final.stem + ".grains.csv"), tmp / (final.stem + ".json")]
        missing = [p.name for p in made if not p.is_file()]
        if missing:
            raise CliError(f"dem.pack exited 0 but did not write {', '.join(missing)}",
                           EXIT_FAILED)
        for p in made:                      # the JSON last: find_bed needs CSV and JSON
            os.replace(p, final.parent / p.name)
        done = True
    except KeyboardInterrupt:
        raise CliError("interrupted while packing (dem.pack stopped); no bed written to "
                       f"{plan['bed_dir']}, no report written", EXIT_FAILED) from None
    finally:
        if proc is not None and proc.poll() is None:  # Ctrl-C reached dem.pack too: let it end
            try:
                proc.wait(timeout=3)
            except subprocess.TimeoutExpired:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
        if proc is not None and proc.stdout is not None:
            proc.stdout.close()
        shutil.rmtree(tmp, ignore_errors=True)
        if not done:                        # folders this call made, if still empty
            for p in made_dirs:
                try:
                    p.rmdir()
                except OSError:
                    break
    return final, {"reused": False, "seconds": time.perf_counter() - t0,
                   "command": " ".join(["python"] + cmd[1:])}


def prepare_bed(plan: dict, *, quiet: bool = False) -> str:
    """After the checks: pack the planned bed if there is one, label the plan's bed (its
    ``label``, the first words of ``porosity_source``) and return the path of the packing the
    report solves (the new bed's, else the plan's)."""
    packing = plan["packing"]
    if plan["action"] == "pack":
        if not quiet:
            print(f"packing a new bed of {plan['grain']} at porosity {plan['porosity']:g}, seed "
                  f"{plan['seed']}, box {' x '.join(f'{v:g}' for v in plan['box'])} m with "
                  "dem.pack: this takes minutes (2-6 packings of 0.5-8 min each; an existing "
                  f"bed in {plan['bed_dir']} is reused)", file=sys.stderr, flush=True)
        with computing():
            found, info = pack_bed(plan, quiet=quiet)
        plan.update(info)
        plan["pack_seconds"] = None if info["reused"] else info["seconds"]
        packing = str(found)
    plan["label"] = bed_label(plan, packing_meta(packing))
    return packing


def bed_label(bed: dict, meta: dict) -> str:
    """Which bed, first words of ``porosity_source``: packed anew / bundled / the user's."""
    if bed["action"] == "pack":
        how = f"packed anew with seed {bed['seed']}"
        if bed.get("reused"):
            how += f" (reused: already in {bed['bed_dir']})"
        e = meta.get("porosity_network_region")
        return (how + f": dem.pack --porosity {bed['porosity']:g} reached "
                + ("?" if e is None else f"{e:.4f}") + f" in network's sample region (tolerance "
                f"{PACK_TOL}); the report is for this bed's own porosity")
    if bed["action"] == "binset":
        return (f"the surface bed of the bin's bed set (rain-filled, packed on first use in "
                f"{bed['bed_dir']})")
    label = ("bundled bed" if bed["action"] == "bundled" else "the user's packing (--packing)")
    if bed["action"] == "bundled" and bed.get("move_along_band"):
        label += ", moved along the band (--move-along-band)"
    if bed["not_packed"]:
        label += f" (not packed anew: {bed['not_packed']})"
    return label


def user_bed_json(path) -> dict:
    """The ``bed`` entry of a report on a user's packing at ``path`` (no plan)."""
    return bed_json({"action": "user", "not_packed": None}, path)


def bed_json(b: dict, path) -> dict:
    """The ``bed`` entry of the report's JSON: how the bed came, its path, seed, dem.pack's run."""
    how = {"pack": "packed anew", "bundled": "bundled", "user": "user's packing",
           "binset": "the bin set's surface bed"}[b["action"]]
    return {"how": how, "path": str(path), "seed": b.get("seed"),
            "porosity_requested": b.get("porosity"), "box_m": b.get("box"),
            "bed_dir": b.get("bed_dir"), "reused": b.get("reused"),
            "pack_seconds": b.get("pack_seconds"), "command": b.get("command"),
            "why_packed": b.get("why") if b["action"] == "pack" else None,
            "not_packed": b["not_packed"]}

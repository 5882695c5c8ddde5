"""``python -m network.bench``: speed against error of the network model.

Three parts, each a module of ``network.benchmarks``:

1. **Policies** — one packing (``--policy-spheres``) solved with each conductance model
   (``--models``) and Q* policy (``--policies``), each against its own fresh copy of the table
   (``--db``, default the cache's default table): k, its difference from the same model's
   fe-only answer, wall time.
2. **Scaling** — packings of ``--sizes`` spheres (periodic, solid fraction 0.60, kept in
   ``--workdir``), each in its own subprocess: time per stage, solver iterations, peak resident
   and traced memory, and the exponent of wall time ~ N^a.
3. **References** — k/k_ref and wall time for every model × policy on SC, BCC and FCC arrays
   (``--ref-lattices``) and random monodisperse packings (``--ref-random``), every cell from a
   fresh (by default empty) table; FE policies on random packings only at ``--fe-random``.

4. **Inertial** (``--inertial``, run alone) — a 12-point resistance curve on the
   ``--inertial-spheres`` benchmark packing, timed per stage against the Stokes pipeline with
   Newton iterations per velocity, and k/k_app against the Beetstra and Hill-Koch-Ladd drag
   laws on Finney's packing, periodic random packings and three settled beds of ``dem.pack``
   (packed into ``--workdir`` on first use, flow vertical and horizontal;
   ``docs/inertial-flow.md``).

Prints a table and writes JSON with the load average, platform, CPU count and a timestamp.
``--skip-references`` leaves part 3 out; ``--references-only`` runs part 3 alone. What each
part measures, its timing rules and the measured FE costs: ``docs/network-bench.md``.

Examples
--------
    python -m network.bench --sizes 5000 20000 --policy-spheres 600 --skip-references
    python -m network.bench --sizes 5000 20000 100000 500000 --skip-policies --skip-references \\
        --json bench.json
    python -m network.bench --references-only --json references.json
    python -m network.bench --references-only --fe-random 0.36 0.40 0.45   # ~30 min
    python -m network.bench --inertial --json inertial.json                 # ~7 min
    python -m network.bench --per-packing --json per_packing.json           # ~1 min
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ._cli import (EXIT_OK, CliParser, bad_input, check_outputs, check_writable_folder, computing,
                   run)
from .core import MAX_REPEATS, MAX_SPHERES, MAX_WORKERS, check_count
from .benchmarks import (REF_LATTICE_CASES, REF_RANDOM_POROSITIES, baseline_source, has_grid,
                         inertial_lines, inertial_speed, inertial_validation, lattice_case,
                         machine, per_packing, policies, policy_lines, references,
                         references_table, run_one, scaling, scaling_exponent)
from .conductance import MODELS, POLICIES

#: fewest spheres of a generated packing (``network.packing.random_packing``'s own limit)
MIN_SPHERES = 5
#: the parts that each run alone (the help says so): any two of them are refused
ALONE = ("references_only", "inertial", "per_packing")
INTERRUPTED = ("the benchmark stopped; no JSON report written (packings generated so far are "
               "kept in --workdir)")


def build_parser() -> CliParser:
    """The options of ``python -m network.bench``."""
    ap = CliParser(prog="python -m network.bench", description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=None,
                    help="sphere counts of the scaling part (default 5000 20000 100000; add "
                         "500000 for the full run; --per-packing: default 5000 20000)")
    ap.add_argument("--policy", default="table-only", choices=POLICIES,
                    help="Q* policy of the scaling part (default table-only: a precomputed table)")
    ap.add_argument("--policies", nargs="*", default=list(POLICIES), choices=POLICIES,
                    help="Q* policies of the policy comparison, part 1 (default all)")
    ap.add_argument("--models", nargs="*", default=["conduit", "thesis"], choices=MODELS,
                    help="conductance models of the policy comparison (default both)")
    ap.add_argument("--model", default="conduit", choices=MODELS,
                    help="conductance model of the scaling part (default conduit)")
    ap.add_argument("--policy-spheres", type=int, default=600,
                    help="packing size of the policy comparison (FE cost grows with it)")
    ap.add_argument("--skip-policies", action="store_true",
                    help="leave out part 1 (Q* policies: speed against error)")
    ap.add_argument("--skip-references", action="store_true",
                    help="leave out part 3 (permeability error against the references)")
    ap.add_argument("--references-only", action="store_true",
                    help="run part 3 alone (no policy comparison, no scaling)")
    ap.add_argument("--ref-lattices", nargs="*", type=lattice_case, default=None,
                    metavar="KIND:PHI",
                    help="lattice cases of part 3, e.g. sc:0.45 fcc:touch (default the 13 cases "
                         "of REF_LATTICE_CASES: sc, bcc and fcc from dilute to touching)")
    ap.add_argument("--ref-random", nargs="*", type=float, default=list(REF_RANDOM_POROSITIES),
                    metavar="POROSITY",
                    help="random-packing porosities of part 3 (default 0.36 0.40 0.45; none "
                         "with an empty list)")
    ap.add_argument("--fe-random", nargs="*", type=float, default=[0.40], metavar="POROSITY",
                    help="porosities at which the FE policies (table+fe, fe-only) run on random "
                         "packings (default 0.40: ~10 min of FE; all three: ~30 min)")
    ap.add_argument("--ref-spheres", type=int, default=800,
                    help="spheres in the periodic random packings of part 3 (default 800)")
    ap.add_argument("--ref-seed", type=int, default=1, help="seed of those packings (default 1)")
    ap.add_argument("--ref-repeats", type=int, default=2,
                    help="repeats per part-3 cell, minimum wall time reported (default 2; FE "
                         "cells on random packings run once)")
    ap.add_argument("--db", default=None,
                    help="throat table with the interpolation grid (default: the cache's default; "
                         "the policy part works on copies)")
    ap.add_argument("--workers", type=int, default=1, help="FE processes (default 1)")
    ap.add_argument("--workdir", default=None,
                    help="where generated packings are kept (default ~/.cache/grainflow/bench)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the generated packings (default 1)")
    ap.add_argument("--repeats", type=int, default=None,
                    help="repeats per size (minimum reported; default 2, --per-packing 7)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per-size limit, s, > 0")
    ap.add_argument("--json", dest="json_out", default="network_bench.json",
                    help="output JSON path (default network_bench.json)")
    ap.add_argument("--inertial", action="store_true",
                    help="run part 4 alone: inertial curve speed and drag-law errors")
    ap.add_argument("--inertial-spheres", type=int, default=20000,
                    help="spheres of the inertial speed packing (default 20000)")
    ap.add_argument("--inertial-workers", type=int, default=None,
                    help="continuation chains of the timed curve, solved side by side "
                         "(default: the usable cores, as network.curve --workers)")
    ap.add_argument("--per-packing", action="store_true",
                    help="run alone: wall time of the whole `python -m network.solve FILE` "
                         "command on the --sizes bench packings (default 5000 20000 here) and "
                         "the bundled scene, --stokes and default, --repeats runs each (default "
                         "7 here) after a warm-up, against the targets of 0.8 s (5000) and 2 s "
                         "(20000)")
    ap.add_argument("--yade", action="store_true",
                    help="with --per-packing: also time YADE's FlowEngine on the same packings "
                         "here (needs the yade program; docs/scripts/yade_flowengine.py)")
    ap.add_argument("--baseline", metavar="COMMIT|DIR", default=None,
                    help="with --per-packing: a commit of this checkout (extracted for the run) "
                         "or a source checkout, whose command runs right after each --stokes "
                         "run of ours: the paired speed-up on this host")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--no-trace", action="store_true", help=argparse.SUPPRESS)
    return ap


def main(argv=None) -> int:
    """Run the benchmark: 0 done; SystemExit(1) the computation failed or was interrupted,
    SystemExit(2) bad input (one ``error:`` line naming the option, before any work)."""
    code = run(_main, build_parser(), argv, interrupted=INTERRUPTED)
    if code != EXIT_OK:
        raise SystemExit(code)
    return code


def _at_least(option: str, values, low, high=None) -> None:
    for v in values:
        if v is not None and v < low:
            raise ValueError(f"{option} must be >= {low}, got {v}")
        if high is not None:
            check_count(option, v, high, low)


def _porosities(option: str, values) -> None:
    for eps in values:
        if not 0.36 <= eps < 1.0:
            raise ValueError(f"{option} porosity {eps} outside [0.36, 1)")


def _check_workdir(path: Path) -> None:
    """ValueError unless ``--workdir`` is a folder that takes new files, or can be made as one
    (its nearest existing parent a writable folder)."""
    here = path
    while not here.exists() and here != here.parent:
        here = here.parent
    if not here.is_dir():
        raise ValueError(f"--workdir {path}: {here} is not a folder")
    check_writable_folder(here, f"--workdir {path}")


def _check(args) -> None:
    """Every option, before any work (ValueError names the option and its value)."""
    alone = [f"--{k.replace('_', '-')}" for k in ALONE if getattr(args, k)]
    if len(alone) > 1:
        raise ValueError(f"{' and '.join(alone)} exclude each other: each runs alone "
                         "(see --help)")
    check_count("--inertial-workers", args.inertial_workers, MAX_WORKERS)
    if (args.yade or args.baseline) and not args.per_packing:
        raise ValueError("--yade and --baseline go with --per-packing (and not --inertial)")
    if args.references_only and args.skip_references:
        raise ValueError("--references-only and --skip-references exclude each other")
    _at_least("--ref-repeats", [args.ref_repeats], 1, MAX_REPEATS)
    _at_least("--workers", [args.workers], 1, MAX_WORKERS)
    for opt in ("--sizes", "--policy-spheres", "--inertial-spheres", "--ref-spheres"):
        value = getattr(args, opt[2:].replace("-", "_"))
        _at_least(opt, value if isinstance(value, list) else [value], MIN_SPHERES, MAX_SPHERES)
    _at_least("--seed", [args.seed], 0)
    _at_least("--ref-seed", [args.ref_seed], 0)
    if not (math.isfinite(args.timeout) and args.timeout > 0):
        raise ValueError(f"--timeout must be a finite number of seconds > 0, got {args.timeout}")
    _porosities("--ref-random", args.ref_random)
    _porosities("--fe-random", args.fe_random)
    if args.db is not None and Path(args.db).is_dir():
        raise ValueError(f"--db {args.db}: is a folder, give the table's file")
    parts_3 = not (args.skip_references or args.inertial or args.per_packing or args.one)
    if args.db is not None and parts_3 and not Path(args.db).is_file():
        raise ValueError(f"--db {args.db}: no such file (part 3 reads the table)")
    if args.references_only:
        args.skip_policies = True
        args.sizes = []
    if args.sizes is None:
        args.sizes = [5000, 20000] if args.per_packing else [5000, 20000, 100000]
    if args.repeats is None:
        args.repeats = 7 if args.per_packing else 2
    _at_least("--repeats", [args.repeats], 1, MAX_REPEATS)


def _main(args) -> int:
    with bad_input():
        _check(args)
        if not args.one:
            check_outputs(json=args.json_out, inputs=[("--db", args.db)])
            args.workdir = Path(args.workdir or Path.home() / ".cache" / "grainflow" / "bench")
            _check_workdir(args.workdir)
        if args.baseline:   # the last check: a commit is extracted here, removed by per_packing
            args.baseline = baseline_source(args.baseline)
    with computing():
        return _work(args)


def _work(args) -> int:
    if args.one:  # child process of the scaling part
        row = run_one(Path(args.one), args.policy, args.db, args.repeats, trace=not args.no_trace,
                      model=args.model)
        print(json.dumps(row))
        return 0

    workdir = args.workdir
    workdir.mkdir(parents=True, exist_ok=True)
    if args.inertial:
        report = {"machine_start": machine()}
        print(f"inertial curve on {args.inertial_spheres} spheres and drag laws:", flush=True)
        report["inertial_speed"] = inertial_speed(args.inertial_spheres, seed=args.seed,
                                                  db=args.db, workers=args.inertial_workers)
        report["inertial_validation"] = inertial_validation(n_spheres=args.ref_spheres,
                                                            seed=args.ref_seed, db=args.db,
                                                            workdir=workdir)
        print("\n".join(inertial_lines(report["inertial_speed"],
                                       report["inertial_validation"])), flush=True)
        report["machine_end"] = machine()
        with open(args.json_out, "w") as f:
            json.dump(report, f, indent=2, default=str)
        print(f"load average {report['machine_end']['loadavg']}; wrote {args.json_out}")
        return 0

    report = {"machine_start": machine()}
    if args.per_packing:
        print(f"per packing: python -m network.solve FILE, wall time ({args.repeats} runs "
              "after a warm-up):", flush=True)
        report["per_packing"] = per_packing(args.sizes, workdir, args.seed,
                                            repeats=args.repeats, yade=args.yade,
                                            baseline=args.baseline)
        report["machine_end"] = machine()
        with open(args.json_out, "w") as f:
            json.dump(report, f, indent=2, default=str)
        print(f"load average {report['machine_end']['loadavg']}; wrote {args.json_out}")
        return 0
    if not args.skip_policies:
        print(f"policies on a {args.policy_spheres}-sphere packing:", flush=True)
        pol = policies(args.policy_spheres, args.policies, args.db, args.seed, args.workers,
                       models=args.models)
        report["policies"] = pol
        for line in policy_lines(pol):
            print(line)
    if args.sizes:
        policy = args.policy
        if policy in ("table-only", "table+fe") and not has_grid(args.db):
            report["scaling_policy_note"] = (f"no interpolation table for {args.db or 'the default db'}"
                                             f": {policy} replaced by shape-factor")
            print(f"  note: {report['scaling_policy_note']}")
            policy = "shape-factor"
        report["scaling_policy"] = policy
        report["scaling_model"] = args.model
        print(f"scaling ({args.model} model, {policy}):", flush=True)
        report["scaling"] = scaling(args.sizes, workdir, policy, args.db, args.seed,
                                    args.repeats, args.timeout, model=args.model)
        fit = scaling_exponent(report["scaling"])
        if fit is not None:
            slope, n_min, n_max = fit
            report["scaling_exponent"] = slope
            print(f"  wall time ~ N^{slope:.2f} over {n_min}..{n_max} spheres")
    if not args.skip_references:
        lat = REF_LATTICE_CASES if args.ref_lattices is None else args.ref_lattices
        print(f"references ({len(lat)} lattices, {len(args.ref_random)} random packings; "
              f"models {' '.join(args.models)}; policies {' '.join(args.policies)}):", flush=True)
        ref = references(lat, args.ref_random, args.models, args.policies, args.db,
                         fe_random=args.fe_random, repeats=args.ref_repeats,
                         n_spheres=args.ref_spheres, seed=args.ref_seed)
        report["references"] = ref
        print("\n".join(references_table(ref)), flush=True)
    report["machine_end"] = machine()
    with open(args.json_out, "w") as f:
        json.dump(report, f, indent=2, default=str)
    print(f"load average {report['machine_end']['loadavg']}; wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

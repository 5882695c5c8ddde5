"""The parts of ``python -m network.bench``: Q* policies, scaling, references.

:func:`policies` (part 1) solves one packing with every conductance model × Q* policy;
:func:`scaling` (part 2) times each stage against packing size, one subprocess per size
(:func:`run_one` is what the subprocess runs); :func:`references` (part 3) compares k with
published and computed Stokes permeabilities, printed by :func:`references_table`;
:func:`inertial_speed` and :func:`inertial_validation` (part 4, ``--inertial``) time the
inertial curve and compare it with the drag laws, printed by :func:`inertial_lines`;
:func:`per_packing` (``--per-packing``) times the whole ``network.solve`` command per packing. The throat
table is read only through ``_table`` (a stand-in until ``network.conductance`` exposes it).
Method and measurement history: ``docs/network-bench.md``.
"""

from ._common import machine, qstar_sources
from ._inertial import INERTIAL_REYNOLDS, inertial_lines, inertial_speed, inertial_validation
from ._per_packing import baseline_source, per_packing, per_packing_line
from ._policies import policies, policy_lines
from ._references import (FE_POLICIES, REF_LATTICE_CASES, REF_RANDOM_POROSITIES, lattice_case,
                          references, references_table)
from ._scaling import DIRECT_MAX, packing_file, run_one, scaling, scaling_exponent
from ._table import has_grid

__all__ = ["baseline_source", "DIRECT_MAX", "FE_POLICIES", "INERTIAL_REYNOLDS", "inertial_lines", "inertial_speed",
           "inertial_validation", "REF_LATTICE_CASES", "REF_RANDOM_POROSITIES", "has_grid",
           "lattice_case", "machine", "packing_file", "per_packing", "per_packing_line", "policies", "policy_lines", "qstar_sources",
           "references", "references_table", "run_one", "scaling", "scaling_exponent"]

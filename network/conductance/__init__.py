"""Conductance stage: Q* by policy (the network's only importer of ``cache``) and g per throat.

:func:`throat_conductance` dispatches to the conduit model (:func:`conduit_conductance`) or the
thesis model (:func:`thesis_conductance`); both give a :class:`ConductanceResult`.
"""

from ._conduit import KERNEL_MIN_THROATS, SECTION_MODES, conduit_conductance, load_conduit_kernel
from ._sections import section_estimate, side_resistance
from ._inertial import (CHAIN_WINDOW_TABLE, conduit_law, expansion_coefficient,
                        inertial_coefficients, onset_scales, turning_cosines, window_constants)
from ._models import MODELS, check_model, throat_conductance
from ._qstar import POLICIES, QstarResult, check_policy, qstar_from_function, throat_qstar
from ._result import ConductanceResult
from ._table import default_table, first_run_note, has_grid, table_totals
from ._thesis import thesis_conductance

__all__ = ["CHAIN_WINDOW_TABLE", "KERNEL_MIN_THROATS", "MODELS", "POLICIES",
           "SECTION_MODES", "ConductanceResult", "QstarResult", "check_model", "check_policy",
           "conduit_conductance", "conduit_law",
           "default_table", "expansion_coefficient", "first_run_note", "has_grid",
           "inertial_coefficients", "load_conduit_kernel", "onset_scales",
           "qstar_from_function", "section_estimate",
           "side_resistance", "table_totals", "thesis_conductance", "throat_conductance",
           "throat_qstar", "turning_cosines", "window_constants"]

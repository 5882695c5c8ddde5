"""The light core of grainflow that ``network`` and ``dem`` share (NumPy only at import).

``Packing``, the table of sphere centres and radii (m) with optional grain ids, and its file
format: :func:`read_packing` (delimited text, ``.npz``, LAMMPS/LIGGGHTS dumps; validated at the
door, the row named in every refusal), :func:`write_packing_csv`, the JSON summary beside a
packing (:func:`read_summary`, :func:`write_summary`) and its container
(:func:`read_container`); the command-line base every command runs on: exit codes (0 done,
1 the computation failed, 2 bad input), :class:`CliParser`, :func:`run` (one ``error:`` line,
no traceback), and the output check :func:`check_output_list` (every output writable and no
output the same file as an input or another output).

SciPy's ``sparse`` and ``spatial`` load on first use (grain checks only), never at import, so
``import dem`` pays for NumPy alone here. Nothing here imports another layer of ``network``.
"""

from ._cli import (EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, MAX_REPEATS, MAX_SPHERES, MAX_WORKERS,
                   CliError, CliParser, bad_input, check_count, check_output_list, check_outputs, check_writable_folder, computing, finish,
                   progress_log, run, same_file, warn)
from ._io import (FORMATS, UNITS, default_packing_path, read_container, read_packing,
                  read_summary, summary_path, write_packing_csv, write_summary)
from ._porosity import MAX_EXACT_ERROR, POROSITY_METHODS, OverlapError, region_porosity
from ._region import AXES, Region, axis_index
from ._text import delimiter_of, read_table, read_text, split_fields
from ._packing import (MIN_SPHERES, PLAUSIBLE_DIAMETER_M, DegeneratePackingError, Packing,
                       check_grains, check_three_dimensional, grain_volumes, scale_warning,
                       validate_spheres)
from ._reach import (KEPLER_POROSITY, LOOSEST_POROSITY, check_physical_porosity, recorded_reach,
                     reach_refusal, reach_text)

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_OK", "FORMATS", "KEPLER_POROSITY",
           "LOOSEST_POROSITY", "MIN_SPHERES", "PLAUSIBLE_DIAMETER_M", "UNITS", "CliError",
           "CliParser", "DegeneratePackingError", "Packing", "bad_input", "check_grains",
           "check_output_list", "check_outputs", "check_physical_porosity",
           "check_three_dimensional", "check_writable_folder", "computing",
           "default_packing_path", "finish", "grain_volumes", "progress_log", "reach_refusal",
           "reach_text", "read_container", "read_packing", "read_summary", "recorded_reach", "run", "same_file",
           "scale_warning", "summary_path", "validate_spheres", "warn", "write_packing_csv",
           "write_summary", "read_text", "read_table", "split_fields", "delimiter_of",
           "check_count", "MAX_WORKERS", "MAX_SPHERES", "MAX_REPEATS", "AXES", "Region",
           "axis_index", "region_porosity", "OverlapError", "POROSITY_METHODS",
           "MAX_EXACT_ERROR"]

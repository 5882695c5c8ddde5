"""grainflow.dem: a discrete-element packer for grain beds (thesis sections 3.1–3.3), numba kernels.

Public API
----------
Material, SOYBEAN
    Grain and wall properties (thesis Table 3.1 defaults).
Container, SCENES, scene_container
    Box / cylinder bins; ``'rect-bin'`` (Appendix A) and ``'cyl-bin'`` (Appendices B–C).
pack_bed(container, *, porosity=0.408, rng=None, options=PackOptions(), run=RunOptions()) -> PackResult
    Generate at reduced radius, expand (Eqs. 3.1–3.10), settle to equilibrium; 'sediment'
    (frictionless sedimentation + annealed taps, friction restored for the last settle) is the
    rect-bin default (``SCENE_DEFAULTS``), the only way found to its 0.408 ± 0.01 target with
    overlaps below 1 % of a radius (0.415 interior; numbers in ``docs/dem-packing.md``).
vibrate_bed(centers, radii, container, *, vibration=VibrationOptions(), run=SETTLE_RUN) -> VibrationResult
    Sinusoidal vertical motion of the bin (Eq. 3.11) with porosity histories, steady stop and
    checkpoints to resume from; rest_motion tells whether a packing is at rest.
Simulation, DemInstabilityError, PlaneWall, CylinderWall, ClumpSimulation
    The time integrator (Verlet list, linear spring–dashpot–Coulomb contacts, walls); rigid
    multi-sphere grains (ClumpSimulation) run on its kernels with a rigid-body update.
linear_contact_forces, series_stiffness, damping_coefficient, restitution_coefficient
    The contact law and its closed forms.
porosity_in_spheres, porosity_in_region, coordination_numbers, Region, lens_volume, sphere_volume
    Measurements; summarize, surface_height, default_measure_spheres (B1–B5) for whole packings.
generate_spheres, thesis_particle_count, intensity_g
    Random sequential addition, Eq. 3.10, Eq. 3.11's Γ = Aω²/g.
FillOptions, pour_grains, janssen_stress, load_bed
    Poured grain beds (rain over the cross-section or a centre spout) with the grains' real
    masses, and the overburden: Janssen's vertical stress and a servo-controlled lid that
    applies it (``python -m dem.pack --grain G --fill rain|spout --depth Z --bin-diameter D``).
write_packing, read_packing
    CSV ``x,y,z,r`` (m) + JSON summary. CLIs: ``python -m dem.pack``, ``python -m dem.vibrate``
    (``--study thesis``: the thesis's vibration study, :mod:`dem.study`), ``python -m dem.bench``.

Model: PFC3D's linear contact (series stiffness, critical-damping ratio 0.1, Coulomb friction),
density scaling S for grown and vibrated beds (poured beds use real masses), equilibrium by the
mean unbalanced-force ratio below ``tol``: ``docs/dem-packing.md``, ``docs/dem-fill.md``; speed
``docs/dem-speed.md``.
"""

from ._contacts import damping_coefficient, linear_contact_forces, restitution_coefficient, series_stiffness
from ._integrate import DemInstabilityError, Simulation
from ._material import SOYBEAN, Material
from ._io import read_packing, write_packing
from ._measure import Region, coordination_numbers, porosity_in_region, porosity_in_spheres
from ._container import SCENE_DEFAULTS, SCENES, Container, default_measure_spheres, scene_container
from ._fill import generate_spheres, thesis_particle_count
from ._measure import lens_volume, sphere_volume
from ._procedures import PROCEDURES, PackOptions, PackResult, RunOptions, pack_bed
from ._summary import summarize, surface_height
from ._vibrate import (SETTLE_RUN, VibrationOptions, VibrationResult, intensity_g, rest_motion,
                       vibrate_bed)
from ._walls import CylinderWall, PlaneWall
from .clumps import ClumpSimulation
from ._load import janssen_stress, load_bed
from ._pour import FillOptions, pour_grains
from .grains import GRAIN_FIELDS, GRAINS, Grain, Sourced, grain
from .templates import (LIBRARY_MAX_SPHERES, ROW_SPACING, TEMPLATE_GRAINS, Template, check_template,
                        library_template, read_template, resolve_template, sphere_template,
                        template_from_axes)

__all__ = [
    "Material", "SOYBEAN", "Simulation", "DemInstabilityError",
    "linear_contact_forces", "series_stiffness", "damping_coefficient", "restitution_coefficient",
    "Container", "SCENES", "SCENE_DEFAULTS", "PROCEDURES", "scene_container", "pack_bed", "PackResult", "PackOptions", "RunOptions", "summarize", "thesis_particle_count",
    "vibrate_bed", "VibrationOptions", "VibrationResult", "SETTLE_RUN",
    "Region", "porosity_in_spheres", "porosity_in_region", "coordination_numbers",
    "read_packing", "write_packing",
    # walls, generation and measuring helpers (the tests and CLIs use these, not private modules)
    "PlaneWall", "CylinderWall", "generate_spheres", "default_measure_spheres", "surface_height",
    "lens_volume", "sphere_volume", "intensity_g", "rest_motion",
    # the grain library: kernel axes, densities, porosity, friction, each sourced
    "GRAINS", "GRAIN_FIELDS", "Grain", "Sourced", "grain",
    # multi-sphere grains: templates from measured axes, the rigid-grain engine
    "ClumpSimulation", "LIBRARY_MAX_SPHERES", "ROW_SPACING", "TEMPLATE_GRAINS", "Template",
    "check_template", "library_template", "read_template", "resolve_template", "sphere_template",
    "template_from_axes",
    # poured fills and the overburden lid
    "FillOptions", "pour_grains", "janssen_stress", "load_bed",
]

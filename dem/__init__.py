"""grainflow.dem: a numpy discrete-element packer for grain beds (thesis sections 3.1–3.3).

Public API
----------
Material, SOYBEAN
    Grain and wall properties (thesis Table 3.1 defaults).
Container, SCENES, scene_container
    Box / cylinder bins; ``'rect-bin'`` (Appendix A) and ``'cyl-bin'`` (Appendices B–C).
pack(container, *, porosity=0.408, rng=None, ...) -> PackResult
    Generate at reduced radius, expand (Eqs. 3.1–3.10), settle to equilibrium.
vibrate(centers, radii, container, *, freq_hz, amplitude_m, duration_s, ...) -> VibrationResult
    Sinusoidal vertical motion of the bin (Eq. 3.11) with porosity histories.
Simulation, DemInstabilityError
    The time integrator (Verlet list, linear spring–dashpot–Coulomb contacts, walls).
linear_contact_forces, series_stiffness, damping_coefficient, restitution_coefficient
    The contact law and its closed forms.
porosity_in_spheres, porosity_in_region, coordination_numbers, Region
    Measurements.
write_packing, read_packing
    CSV ``x,y,z,r`` (m) + JSON summary.

CLIs: ``python -m dem.pack``, ``python -m dem.vibrate``, ``python -m dem.bench``.
"""

from ._contacts import damping_coefficient, linear_contact_forces, restitution_coefficient, series_stiffness
from ._integrate import SOYBEAN, DemInstabilityError, Material, Simulation
from ._io import read_packing, write_packing
from ._measure import Region, coordination_numbers, porosity_in_region, porosity_in_spheres
from ._scenes import SCENES, Container, PackResult, pack, scene_container, summarize, thesis_particle_count
from ._vibrate import VibrationResult, vibrate

__all__ = [
    "Material", "SOYBEAN", "Simulation", "DemInstabilityError",
    "linear_contact_forces", "series_stiffness", "damping_coefficient", "restitution_coefficient",
    "Container", "SCENES", "scene_container", "pack", "PackResult", "summarize", "thesis_particle_count",
    "vibrate", "VibrationResult",
    "Region", "porosity_in_spheres", "porosity_in_region", "coordination_numbers",
    "read_packing", "write_packing",
]

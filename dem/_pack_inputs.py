"""The run's inputs that ``python -m dem.pack`` builds from its options, shared by the sphere bed,
the grown grain bed and the poured one (:mod:`dem._pack_pour`): the material (the options', and a
library grain's density and friction over them), the porosity that sets a grain count, the
progress line's view of a clump simulation and the summary lines' number format.
"""

from __future__ import annotations

from dataclasses import replace

from ._material import Material
from ._reach import count_porosity
from .grains import grain


def grain_material(args, name):
    """Library density and friction of a grain (thesis values for soybean); the rest from the options."""
    mat = material_from_args(args)
    try:
        g = grain(name)
    except ValueError:
        return mat, {}
    used = {}
    for field, attr in [("particle_density_kg_m3", "density_kg_m3"), ("friction_pp", "friction"),
                        ("friction_pw", "wall_friction")]:
        v = getattr(g, field)
        if v.value is not None:
            used[attr] = {"value": v.value, "source": v.source}
    vals = {k: v["value"] for k, v in used.items()}
    return replace(mat, **vals), used


def grain_porosity(args, name):
    """The porosity that sets the grain count of one packing: --porosity, else the middle of the
    grain's measured loose-fill range, else 0.408 (thesis Table 3.1): dem._reach.count_porosity."""
    return args.porosity if args.porosity is not None else count_porosity(name)[0]


class Progress:
    """The few attributes progress_printer reads, from a ClumpSimulation."""

    def __init__(self, sim):
        self.steps, self.n, self.time_s = sim.steps, sim.n_grains, sim.time_s
        self.kinetic_energy = sim.kinetic_energy


def material_from_args(args):
    return Material(
        density_kg_m3=args.density, kn_n_m=args.kn, ks_n_m=args.ks, friction=args.friction,
        wall_kn_n_m=args.wall_kn, wall_ks_n_m=args.wall_ks, wall_friction=args.wall_friction,
        damping_ratio=args.damping, radius_min_m=args.r_min, radius_max_m=args.r_max,
    )


def fmt_num(v, digits=2) -> str:
    return "n/a" if v is None else f"{v:.{digits}f}"

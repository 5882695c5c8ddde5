r"""Containers, the thesis's bins, sphere generation and the packing procedure.

Procedure (thesis 3.1 and Appendices A–B, PFC3D ``generate`` / ``ini rad mul`` / ``solve``):

1. Number of spheres from the target porosity φ and the mean radius
   r̄ = (r_lo + r_hi)/2 (thesis Eq. 3.10): :math:`N = \lfloor (1-φ) V / (\tfrac43 π r̄^3) \rfloor`
   with V the container volume up to the fill height.
2. Generate N non-overlapping spheres at radii uniform in [r_lo, r_hi] / m₀ (m₀ = 1.4)
   below the fill height (random sequential addition).
3. Expand the radii by the multiplier of Eqs. 3.5–3.7, :math:`m^3 = (1-φ)/(1-φ_0)`, so the
   spheres' volume is exactly (1 − φ) V; growth is spread over ``grow_steps`` steps under
   gravity, with a lid at (1 + ``lid_headroom``) × the fill height (Appendix B puts it
   0.05 m above a 0.25 m fill: headroom 0.2).
4. Cycle under the lid until the mean unbalanced-force ratio is below 1e-2, remove the
   lid, cycle to equilibrium (ratio below ``tol``).

``lid_headroom = 0`` with ``open_top=False`` is Appendix A's closed box: the global porosity
is then φ by construction, but in a bin only three grains thick the spheres cannot fill
(1 − φ) of the box without being pressed into each other (large overlaps, reported as
``max_overlap_fraction``). With headroom the bed finds its own height and porosity.

What Appendix A actually does (thesis PFC3D script for the 0.25 × 0.02 m bin): friction 0.47
(walls 0.3) is set right after ``generate``, so it is active during expansion and cycling; the
radii are multiplied in one go (``ini rad mul``) inside the closed box (lid at the fill height),
gravity on, ``cycle 3000``, ``solve`` (PFC's default: mean unbalanced-force ratio 1e-2); the
walls are then replaced by taller ones with a lid at 0.275 m and nothing is cycled after that.
The thesis's packing is therefore the compressed closed-box one, global porosity 0.408 by
construction. Here that is ``procedure='lid', lid_headroom=0, open_top=False``; measured on
rect-bin (seed 1, 4.6 s): global 0.408, interior 0.4026, but particle overlaps max 25.6 % and
mean 6.5 % of a radius (5.5 true contacts per sphere): a compressed bed, not a settled one.

Procedure ``'sediment'`` (default of ``--scene rect-bin``, :data:`SCENE_DEFAULTS`)
-----------------------------------------------------------------------------------
A bin three grains thick with friction 0.47 locks a loose structure (``'lid'``: interior
porosity 0.452), so the dense structure is built without friction and friction is restored
only for the last settle (it can only add stability to a frictionless static bed):

1. Generate at r/m₀ in the whole box up to the lid at (1 + ``lid_headroom``) H (0.3), expand to
   the Eq. 3.7 radii with particle and wall friction 0 (``packing_friction``): a dilute
   suspension, no forced overlaps.
2. ``sediment_steps`` of frictionless settling under gravity.
3. Taps: the container moves as :math:`z = A(t)\sin 2\pi f t` for a whole number of periods;
   with ``tap_decay`` the amplitude falls linearly from A₀ to 0 (annealed tapping, which ends
   denser than constant amplitude), then ``tap_settle_steps`` more.
4. Table 3.1 friction restored, lid removed, settle to ``tol``.

Measured on rect-bin, seed 1, mass scale 100, this machine (2 cores shared, load ≈ 2), interior
porosity / max overlap (% of a radius) / wall time:

* ``'lid'`` (headroom 0.2, friction 0.47 throughout): 0.452 / 0.6 % / 66 s.
* frictionless sedimentation only (no taps): 0.424 / 0.7 % / 31 s.
* + constant taps 30 Hz, 0.4 mm (1.45 g), 0.6 s: 0.418 / 0.4 % / 102 s; 0.3 mm (1.09 g): 0.419.
* + annealed taps 30 Hz, A₀ = 0.6 mm (2.17 g → 0), 0.6 s: 0.417 / 0.9 % / 109 s.
* + annealed taps 30 Hz, A₀ = 0.8 mm (2.90 g → 0), 0.6 s after 3000 sedimentation steps:
  interior 0.4168 / max 0.78 %, mean 0.08 % / 87 s at load 1.7; seeds 2, 3: 0.4164, 0.4172.
  Tapping 1.0 s instead of 0.6 s: 0.4151 in 128 s. 15 Hz, A₀ = 3.2 mm (2.90 g): 0.4170.
* + annealed taps 30 Hz, A₀ = 1.2 mm (4.35 g → 0), 0.6 s: 0.4157 (seed 2: 0.4153) / 80 s.
* + annealed taps 30 Hz, A₀ = 1.6 mm (5.80 g → 0), 0.6 s after 3000 sedimentation steps (the
  rect-bin default): interior 0.4152 / max 0.58 %, mean 0.07 % (walls: max 0.47 %) / 75 s at
  load 0.8 (55 424 steps, 3.8e6 particle-steps/s); global porosity to the bed surface 0.420,
  closed-volume 0.408, 4.8 true contacts per sphere (8.5 within 1.05 d_max). Seeds 2 and 3:
  0.4153 and 0.4158, 76-78 s each.

Random packings of frictionless spheres in this slab plateau near 0.42 (the walls, 3.1 grain
diameters apart, keep the structure layered and loose); only the taps push it into the
0.408 ± 0.01 band, and only just. The thesis's 0.408 is a closed-box value with forced overlaps.

Equilibrium criterion: mean unbalanced-force ratio (:meth:`Simulation.unbalanced_force_ratio`)
below ``tol``. All stages use density scaling S (``mass_scale``; see :mod:`dem._integrate`);
the physical parameters are otherwise those of Table 3.1.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree

from ._integrate import SOYBEAN, Material, Simulation
from ._measure import Region, coordination_numbers, porosity_in_region, porosity_in_spheres, sphere_volume
from ._walls import CylinderWall, PlaneWall

__all__ = [
    "Container",
    "SCENES",
    "SCENE_DEFAULTS",
    "PROCEDURES",
    "scene_container",
    "default_measure_spheres",
    "thesis_particle_count",
    "generate_spheres",
    "make_simulation",
    "pack_bed",
    "PackResult",
    "summarize",
]

log = logging.getLogger(__name__)

#: Densest packing of equal spheres (Kepler), porosity 1 − π/√18.
KEPLER_POROSITY = 1.0 - np.pi / np.sqrt(18.0)


@dataclass(frozen=True)
class Container:
    """A bin with its floor at z = 0, centred on the z axis.

    ``kind`` 'box': ``size_m`` = (length_x, width_y); 'cylinder': ``size_m`` = (diameter,).
    ``fill_height_m`` is the height the bed is filled to (lid height during expansion).
    """

    kind: str
    size_m: tuple
    fill_height_m: float

    def __post_init__(self):
        if self.kind not in ("box", "cylinder"):
            raise ValueError(f"container kind must be 'box' or 'cylinder', got {self.kind!r}")
        need = 2 if self.kind == "box" else 1
        if len(self.size_m) != need:
            raise ValueError(f"{self.kind} needs {need} size value(s), got {self.size_m}")
        if not all(s > 0 for s in self.size_m) or not self.fill_height_m > 0:
            raise ValueError(f"container dimensions must be positive, got {self.size_m}, {self.fill_height_m}")

    @property
    def area_m2(self):
        if self.kind == "box":
            return float(self.size_m[0] * self.size_m[1])
        return float(np.pi * self.size_m[0] ** 2 / 4)

    @property
    def volume_m3(self):
        return self.area_m2 * self.fill_height_m

    @property
    def min_dimension_m(self):
        return float(min(min(self.size_m), self.fill_height_m))

    def walls(self, *, lid=True, lid_height_m=None):
        """Wall list: side walls and floor move with the container; the lid (at the fill
        height unless ``lid_height_m`` is given) is fixed."""
        h = self.fill_height_m if lid_height_m is None else float(lid_height_m)
        if self.kind == "box":
            lx, ly = self.size_m
            walls = [
                PlaneWall((-lx / 2, 0, 0), (1, 0, 0), "x-"),
                PlaneWall((lx / 2, 0, 0), (-1, 0, 0), "x+"),
                PlaneWall((0, -ly / 2, 0), (0, 1, 0), "y-"),
                PlaneWall((0, ly / 2, 0), (0, -1, 0), "y+"),
            ]
        else:
            walls = [CylinderWall(self.size_m[0] / 2, (0.0, 0.0), "cylinder")]
        walls.append(PlaneWall((0, 0, 0), (0, 0, 1), "floor"))
        if lid:
            walls.append(PlaneWall((0, 0, h), (0, 0, -1), "lid", moves=False))
        return walls

    def bounds(self, r_max, *, headroom=1.0):
        """Box every centre must stay in (escape detection)."""
        h = self.fill_height_m
        if self.kind == "box":
            lx, ly = self.size_m
            half = np.array([lx / 2, ly / 2])
        else:
            half = np.array([self.size_m[0] / 2] * 2)
        lo = np.array([-half[0] - r_max, -half[1] - r_max, -r_max - 0.02])
        hi = np.array([half[0] + r_max, half[1] + r_max, h * (1 + headroom) + 0.05])
        return np.array([lo, hi])

    def interior(self, margin_m, top_m):
        """Region at least ``margin_m`` from the side walls (x only for a box thinner than
        4 margins in y), the floor and the bed top ``top_m``."""
        z = (margin_m, top_m - margin_m)
        if self.kind == "box":
            lx, ly = self.size_m
            my = margin_m if ly > 4 * margin_m else 0.0
            return Region("box", (-lx / 2 + margin_m, -ly / 2 + my, z[0]), (lx / 2 - margin_m, ly / 2 - my, z[1]))
        return Region("cylinder", (0, 0, z[0]), (0, 0, z[1]), radius=self.size_m[0] / 2 - margin_m)

    def sample_centers(self, radii, rng):
        """Uniform random centres such that each sphere lies inside the closed container."""
        h = self.fill_height_m
        z = rng.uniform(radii, h - radii)
        if self.kind == "box":
            lx, ly = self.size_m
            x = rng.uniform(-lx / 2 + radii, lx / 2 - radii)
            y = rng.uniform(-ly / 2 + radii, ly / 2 - radii)
        else:
            rad = self.size_m[0] / 2 - radii
            rho = rad * np.sqrt(rng.uniform(0, 1, len(radii)))
            phi = rng.uniform(0, 2 * np.pi, len(radii))
            x, y = rho * np.cos(phi), rho * np.sin(phi)
        return np.column_stack([x, y, z])

    def to_dict(self):
        return {"kind": self.kind, "size_m": list(map(float, self.size_m)), "fill_height_m": float(self.fill_height_m)}

    @classmethod
    def from_dict(cls, d):
        return cls(d["kind"], tuple(d["size_m"]), d["fill_height_m"])


#: The thesis's bins: Appendix A (rectangular, 0.25 × 0.02 m, filled to 0.25 m) and
#: Appendices B–C (cylinder 0.15 m in diameter, filled to 0.25 m).
SCENES = {
    "rect-bin": Container("box", (0.25, 0.02), 0.25),
    "cyl-bin": Container("cylinder", (0.15,), 0.25),
}


#: Packing options each named scene uses by default (``python -m dem.pack --scene NAME``); see the
#: module notes for the measurements behind the rect-bin choice.
SCENE_DEFAULTS = {
    "rect-bin": dict(procedure="sediment", lid_headroom=0.3, sediment_steps=3000, tap_freq_hz=30.0,
                     tap_amplitude_m=1.6e-3, tap_duration_s=0.6, tap_decay=True),
    "cyl-bin": dict(procedure="lid", lid_headroom=0.2),
}


def scene_container(name):
    """Container of a named scene ('rect-bin' | 'cyl-bin')."""
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}; choose from {sorted(SCENES)} or 'box'/'cylinder'") from None


def default_measure_spheres(container):
    """Thesis B1–B5 measurement spheres (Appendix C: x = 3/7·width, radius width/14).

    For a box the sphere radius is capped at 0.99 × half the thinner side so it stays inside.
    """
    zs = np.array([0.119, 0.129, 0.130, 0.136, 0.146]) * container.fill_height_m / 0.25
    if container.kind == "cylinder":
        w = container.size_m[0]
        r = w / 14.0
        x = 3.0 / 7.0 * w
        x = min(x, w / 2 - r)
    else:
        r = min(0.15 / 14.0, 0.99 * min(container.size_m) / 2)
        x = min(0.0643, container.size_m[0] / 2 - r)
    centers = np.column_stack([np.full(5, x), np.zeros(5), zs])
    return centers, r


def thesis_particle_count(container, porosity, material=SOYBEAN):
    r"""Sphere count of thesis Eq. 3.10 with r̄ = (r_lo + r_hi)/2:
    :math:`N = \lfloor (1-φ)V / (\tfrac43 π r̄^3) \rfloor` (rect-bin: 5146; cyl-bin: 18188)."""
    rbar = 0.5 * (material.radius_min_m + material.radius_max_m)
    return int((1.0 - porosity) * container.volume_m3 / (4.0 / 3.0 * np.pi * rbar**3))


def _validate(container, porosity, material):
    if not 0.0 < porosity < 1.0:
        raise ValueError(f"porosity must be in (0, 1), got {porosity}")
    if porosity <= KEPLER_POROSITY:
        raise ValueError(
            f"porosity {porosity} is unreachable: no sphere packing is denser than "
            f"{KEPLER_POROSITY:.4f} (face-centred cubic)"
        )
    if porosity < 0.35:
        raise ValueError(
            f"porosity {porosity} is unreachable by a random packing of near-equal spheres "
            "(random close packing is about 0.36)"
        )
    d = 2 * material.radius_max_m
    if container.min_dimension_m < d:
        raise ValueError(
            f"container ({container.size_m}, height {container.fill_height_m}) m is smaller than a "
            f"grain of diameter {d} m"
        )


def generate_spheres(container, n, r_lo, r_hi, rng, *, tries=200000):
    """N non-overlapping spheres, radii uniform in [r_lo, r_hi], random sequential addition.

    Candidates are drawn in batches and rejected against the accepted spheres (KD-tree)
    and against each other; raises ValueError after ``tries`` rejected candidates
    (PFC3D ``generate ... tries``).
    """
    radii_all = np.empty(0)
    centers_all = np.empty((0, 3))
    rejected = 0
    while len(radii_all) < n:
        need = n - len(radii_all)
        m = max(2 * need, 64)
        r = rng.uniform(r_lo, r_hi, m)
        x = container.sample_centers(r, rng)
        ok = np.ones(m, dtype=bool)
        if len(radii_all):
            tree = cKDTree(centers_all)
            k = min(16, len(radii_all))
            dist, idx = tree.query(x, k=k, distance_upper_bound=r_hi + r.max())
            dist = dist.reshape(m, k)
            idx = idx.reshape(m, k)
            valid = idx < len(radii_all)
            rr = np.where(valid, radii_all[np.minimum(idx, len(radii_all) - 1)], 0.0)
            ok &= ~np.any(valid & (dist < r[:, None] + rr), axis=1)
        pairs = cKDTree(x).query_pairs(2 * r_hi, output_type="ndarray")
        if len(pairs):
            i, j = pairs[:, 0], pairs[:, 1]
            clash = np.linalg.norm(x[i] - x[j], axis=1) < r[i] + r[j]
            ok[np.maximum(i, j)[clash]] = False
        acc = np.flatnonzero(ok)[:need]
        rejected += m - len(acc)
        radii_all = np.concatenate([radii_all, r[acc]])
        centers_all = np.concatenate([centers_all, x[acc]])
        if rejected > tries and len(radii_all) < n:
            raise ValueError(
                f"could only place {len(radii_all)} of {n} spheres after {rejected} tries: "
                "container too small or porosity too low for the initial radii"
            )
    return centers_all, radii_all


def make_simulation(container, centers, radii, *, material=SOYBEAN, lid=True, lid_height_m=None, **kw):
    """Simulation of spheres in a container's walls (lid optional), with escape bounds."""
    return Simulation(
        centers, radii, container.walls(lid=lid, lid_height_m=lid_height_m), material,
        bounds_m=container.bounds(material.radius_max_m * 1.2), **kw,
    )


@dataclass
class PackResult:
    """A finished packing and how it was made."""

    centers: np.ndarray
    radii: np.ndarray
    container: Container
    summary: dict = field(default_factory=dict)


def summarize(centers, radii, container, *, material=SOYBEAN, measure_spheres=None, interior_margin_m=None,
              coordination_box=None):
    """JSON-ready measurements of a packing (porosities, coordination distributions)."""
    centers = np.asarray(centers, float)
    radii = np.asarray(radii, float)
    vp = float(sphere_volume(radii).sum())
    top = float(np.max(centers[:, 2] + radii))
    rbar = 0.5 * (material.radius_min_m + material.radius_max_m)
    bhtf = float(np.max(centers[:, 2]) + rbar)
    dmean = float(2 * radii.mean())
    margin = interior_margin_m if interior_margin_m is not None else 2 * dmean
    # bed surface: mean top of the highest sphere in each column of the cross-section
    surface = _surface_height(centers, radii, container)
    region = container.interior(margin, surface)
    if measure_spheres is None:
        measure_spheres = default_measure_spheres(container)
    mc, mr = measure_spheres
    local = porosity_in_spheres(centers, radii, mc, mr)
    dmax = float(2 * radii.max())
    if coordination_box is None:
        if container.kind == "box":
            lx, ly = container.size_m
            coordination_box = ((-min(0.05, lx / 2), -ly / 2, 0.02), (min(0.05, lx / 2), ly / 2, surface - 0.02))
        else:
            coordination_box = ((-0.05, -0.05, 0.02), (0.05, 0.05, surface - 0.02))
    lo, hi = map(np.asarray, coordination_box)
    sel = np.all((centers >= lo) & (centers <= hi), axis=1)
    z_cut = coordination_numbers(centers, radii, cutoff_m=1.05 * dmax, select=sel)
    z_true = coordination_numbers(centers, radii, contact_tol_m=0.0, select=sel)
    d_all = 2 * radii
    return {
        "n_spheres": int(len(radii)),
        "container": container.to_dict(),
        "solid_volume_m3": vp,
        "porosity_closed_volume": 1.0 - vp / container.volume_m3,
        "bed_height_max_m": top,
        "bed_height_surface_m": surface,
        "porosity_global_surface": 1.0 - vp / (container.area_m2 * surface),
        "porosity_global_thesis": 1.0 - vp / (container.area_m2 * bhtf),
        "porosity_interior": porosity_in_region(centers, radii, region),
        "interior_region": region.to_dict(),
        "measure_spheres": {"centers_m": mc.tolist(), "radius_m": float(mr), "porosity": local.tolist(),
                            "mean": float(local.mean())},
        "coordination": {
            "box_m": [lo.tolist(), hi.tolist()],
            "n_particles": int(sel.sum()),
            "cutoff_m": 1.05 * dmax,
            "cutoff_mean": float(z_cut.mean()) if len(z_cut) else None,
            "cutoff_hist": np.bincount(z_cut).tolist() if len(z_cut) else [],
            "contact_mean": float(z_true.mean()) if len(z_true) else None,
            "contact_hist": np.bincount(z_true).tolist() if len(z_true) else [],
        },
        "diameter_m": {"min": float(d_all.min()), "max": float(d_all.max()), "mean": float(d_all.mean()),
                       "fraction_outside_nominal": float(np.mean((d_all < 2 * material.radius_min_m * (1 - 1e-9))
                                                                 | (d_all > 2 * material.radius_max_m * (1 + 1e-9))))},
    }


def _surface_height(centers, radii, container, cell=None):
    """Bed surface height, m: median over a grid of columns of the highest sphere top."""
    cell = cell or 2 * float(radii.mean())
    top = centers[:, 2] + radii
    ix = np.floor(centers[:, 0] / cell).astype(np.int64)
    iy = np.floor(centers[:, 1] / cell).astype(np.int64)
    key = (ix - ix.min()) * (iy.max() - iy.min() + 1) + (iy - iy.min())
    order = np.lexsort((top, key))
    last = np.r_[np.flatnonzero(np.diff(key[order])), len(order) - 1]
    return float(np.median(top[order][last]))


PROCEDURES = ("lid", "sediment")


def pack_bed(container, *, material=SOYBEAN, porosity=0.408, n_particles=None, rng=None, initial_multiplier=1.4,
         mass_scale=100.0, dt_safety=0.25, grow_steps=3000, tol=2e-3, max_steps=200000, check_every=200,
         open_top=True, packing_friction=None, lid_headroom=0.2, settle_time_s=None, measure_spheres=None,
         progress=None, procedure="lid", sediment_steps=3000, tap_freq_hz=30.0, tap_amplitude_m=1.6e-3,
         tap_duration_s=0.6, tap_settle_steps=3000, tap_decay=True):
    """Make a settled packing in ``container`` (procedures in the module notes).

    Parameters
    ----------
    container : Container
    material : Material
    porosity : float
        Target porosity φ of the closed volume (0.408, thesis Table 3.1).
    n_particles : int, optional
        Default: thesis Eq. 3.10.
    rng : numpy.random.Generator | int | None
        Seed or generator; the same seed gives the same packing.
    initial_multiplier : float
        m₀: generation radii are the nominal ones divided by m₀ (Appendix A: 1.4).
    mass_scale : float
        Density scaling S during expansion and settling (1 = physical masses).
    grow_steps : int
        Steps over which the radii grow to their final size.
    tol : float
        Mean unbalanced-force ratio that counts as equilibrium (each stage).
    max_steps : int
        Step limit per equilibrium stage.
    packing_friction : float, optional
        Particle–particle friction used during expansion and the closed-box stage
        (None: the material's). The material's friction is restored before the open-box
        settling.
    lid_headroom : float
        The lid sits at (1 + lid_headroom) × the fill height during expansion (Appendix B:
        0.05 m above a 0.25 m fill, i.e. 0.2); 0 is Appendix A's closed box.
    settle_time_s : float, optional
        Settle for this simulated time instead of until ``tol`` (used to compare density
        scalings at equal physical time).
    open_top : bool
        Remove the lid and settle again (thesis Appendix A) before measuring.
    progress : callable(stage, sim, force) | None
        Called every ``check_every`` steps.
    procedure : {'lid', 'sediment'}
        'lid': expansion and closed stage under the lid with the material's friction (or
        ``packing_friction``), then settling (Appendices A–B). 'sediment': frictionless
        sedimentation and taps, friction restored for the last settle (module notes; the
        default of ``--scene rect-bin``). ``packing_friction`` (default 0 here) applies to
        particle and wall contacts.
    sediment_steps : int
        'sediment': steps of frictionless settling after the expansion.
    tap_freq_hz, tap_amplitude_m, tap_duration_s : float
        'sediment': container motion :math:`z = A \\sin 2\\pi f t` (Hz, m, s), run for
        round(f · duration) whole periods (at least one); A = 0 or duration 0 skips it.
    tap_decay : bool
        'sediment': amplitude falls linearly from ``tap_amplitude_m`` to 0 over the taps.
    tap_settle_steps : int
        'sediment': frictionless steps after the taps.

    Returns
    -------
    PackResult
    """
    if not isinstance(container, Container):
        raise TypeError(f"container must be a Container, got {type(container).__name__}")
    _validate(container, porosity, material)
    if not initial_multiplier >= 1.0:
        raise ValueError(f"initial_multiplier must be >= 1, got {initial_multiplier}")
    rng = np.random.default_rng(rng)
    n = thesis_particle_count(container, porosity, material) if n_particles is None else int(n_particles)
    if n < 1:
        raise ValueError(f"no sphere fits: n_particles = {n}")
    if procedure not in PROCEDURES:
        raise ValueError(f"procedure must be one of {PROCEDURES}, got {procedure!r}")
    if procedure == "sediment" and not (lid_headroom > 0 and sediment_steps >= 0 and tap_duration_s >= 0
                                        and tap_amplitude_m >= 0 and tap_freq_hz > 0 and tap_settle_steps >= 0):
        raise ValueError("procedure 'sediment' needs lid_headroom > 0, tap_freq_hz > 0 and non-negative "
                         "sediment_steps, tap_duration_s, tap_amplitude_m, tap_settle_steps (Appendix A's closed box is "
                         "procedure 'lid' with lid_headroom 0)")
    t_wall = time.perf_counter()
    r_lo = material.radius_min_m / initial_multiplier
    r_hi = material.radius_max_m / initial_multiplier
    lid_height = container.fill_height_m * (1 + lid_headroom)
    # 'lid' generates below the fill height (Appendices A-B); 'sediment' in the whole box under the lid,
    # so that the expanded spheres are a dilute suspension that settles without being forced together
    gen_box = container if procedure == "lid" else replace(container, fill_height_m=lid_height)
    centers, r0 = generate_spheres(gen_box, n, r_lo, r_hi, rng)
    phi0 = 1.0 - sphere_volume(r0).sum() / container.volume_m3
    mult = ((1.0 - porosity) / (1.0 - phi0)) ** (1.0 / 3.0)  # thesis Eq. 3.7
    log.info("generated %d spheres, porosity %.4f, radius multiplier %.4f", n, phi0, mult)
    if procedure == "lid":
        mat_pack = material if packing_friction is None else replace(material, friction=float(packing_friction))
    else:
        mu = 0.0 if packing_friction is None else float(packing_friction)
        mat_pack = replace(material, friction=mu, wall_friction=mu)
    sim = make_simulation(container, centers, r0, material=mat_pack, lid=True, lid_height_m=lid_height,
                          mass_scale=mass_scale, dt_safety=dt_safety)
    stages = {}

    def cb(stage):
        return None if progress is None else (lambda s, f: progress(stage, s, f))

    stages["expand"] = sim.run(max_steps=grow_steps, grow_from=r0, grow_to=r0 * mult, check_every=check_every,
                               callback=cb("expand"))
    if procedure == "lid":
        # closed stage: relax the expanded assembly under the lid before opening the top, so that
        # elastic energy stored by the expansion cannot launch spheres out of the bin. Appendix A's
        # closed box (lid_headroom = 0) is cycled to the full criterion, otherwise to 1e-2.
        tol_closed = tol if (lid_headroom == 0 and packing_friction is None) else max(tol, 1e-2)
        stages["closed"] = sim.run(max_steps=max_steps, tol=tol_closed, check_every=check_every,
                                   callback=cb("closed"))
        stages["closed"]["max_overlap_fraction"] = _max_overlap_fraction(sim)
    else:
        # frictionless sedimentation for a fixed number of steps (a frictionless bed under
        # viscous damping alone creeps towards the force criterion very slowly), then taps
        stages["sediment"] = sim.run(max_steps=sediment_steps, check_every=check_every, callback=cb("sediment"))
        stages["sediment"]["porosity_interior"] = _interior_porosity(sim, container)
        stages["tap"] = _tap(sim, tap_freq_hz, tap_amplitude_m, tap_duration_s, check_every, cb("tap"),
                             decay=tap_decay)
        stages["tap_settle"] = sim.run(max_steps=tap_settle_steps, check_every=check_every,
                                       callback=cb("tap_settle"))
        stages["tap_settle"]["porosity_interior"] = _interior_porosity(sim, container)
        stages["tap_settle"]["max_overlap_fraction"] = _max_overlap_fraction(sim)
        for name in ("sediment", "tap", "tap_settle"):
            stages[name]["converged"] = True  # fixed-length stages
    sim.set_material(material)
    if open_top:
        sim.set_walls(container.walls(lid=False))
    if settle_time_s is None:
        stages["settle"] = sim.run(max_steps=max_steps, tol=tol, check_every=check_every, callback=cb("settle"))
    else:
        stages["settle"] = sim.run(duration_s=settle_time_s, check_every=check_every, callback=cb("settle"))
        stages["settle"]["converged"] = True
    for name, st in stages.items():
        if name != "expand" and not st["converged"]:
            log.warning("stage %s stopped at the step limit (ratio %.3g > tol %.3g)", name, st["ratio"], tol)
    wall_s = time.perf_counter() - t_wall
    summary = summarize(sim.centers, sim.radii, container, material=material, measure_spheres=measure_spheres)
    steps = sum(st["steps"] for st in stages.values())
    summary.update({
        "target_porosity": porosity,
        "initial_porosity": float(phi0),
        "radius_multiplier": float(mult),
        "mass_scale": float(mass_scale),
        "dt_s": sim.dt,
        "dt_physical_s": sim.dt / np.sqrt(mass_scale),
        "simulated_time_s": sim.time_s,
        "steps": int(steps),
        "stages": stages,
        "tol_unbalanced_ratio": tol,
        "wall_time_s": wall_s,
        "particle_steps_per_s": steps * n / wall_s,
        "neighbour_rebuilds": int(sim.stats["rebuilds"]),
        "max_overlap_fraction": _max_overlap_fraction(sim),
        "mean_overlap_fraction": _mean_overlap_fraction(sim),
        "procedure": procedure,
        "final_friction": {"particle": sim.material.friction, "wall": sim.material.wall_friction},
        "material": {k: getattr(material, k) for k in material.__dataclass_fields__},
    })
    return PackResult(sim.centers.copy(), sim.radii.copy(), container, summary)


def _tap(sim, freq_hz, amplitude_m, duration_s, check_every, callback, decay=False):
    r"""Vertical sinusoidal motion of the container, :math:`z_w = A\sin(2\pi f t)`, for a whole
    number of periods (at least one when A·duration > 0) so the floor ends where it started."""
    t0 = time.perf_counter()
    n_cycles = int(round(duration_s * freq_hz))
    if amplitude_m == 0 or duration_s == 0:
        n_cycles = 0
    elif n_cycles == 0:
        n_cycles = 1
    period = 1.0 / freq_hz
    omega = 2 * np.pi * freq_hz
    start = sim.time_s
    k = 0
    t_end = n_cycles * period
    while n_cycles and sim.time_s - start < t_end:
        t = sim.time_s - start
        if decay:  # amplitude falling linearly to zero (annealed tapping)
            a, da = amplitude_m * (1 - t / t_end), -amplitude_m / t_end
        else:
            a, da = amplitude_m, 0.0
        sim.z_offset_m = a * np.sin(omega * t)
        sim.wall_vz_m_s = a * omega * np.cos(omega * t) + da * np.sin(omega * t)
        force = sim.step()
        k += 1
        if k % check_every == 0:
            sim.check_stability()
            if callback is not None:
                callback(sim, force)
    sim.z_offset_m = 0.0
    sim.wall_vz_m_s = 0.0
    return {"steps": k, "time_s": sim.time_s, "cycles": n_cycles, "freq_hz": float(freq_hz),
            "duration_s": sim.time_s - start, "amplitude_m": float(amplitude_m), "decay": bool(decay),
            "intensity_g": float(amplitude_m * omega**2 / 9.81), "wall_s": time.perf_counter() - t0}


def _interior_porosity(sim, container):
    c, r = sim.centers, sim.radii
    region = container.interior(4 * float(r.mean()), _surface_height(c, r, container))
    return porosity_in_region(c, r, region)


def _overlap_fractions(sim):
    """Particle-particle overlaps of the touching pairs, as fractions of the smaller radius."""
    pairs = sim.touching_pairs
    if len(pairs) == 0:
        return np.zeros(1)
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.linalg.norm(sim.centers[j] - sim.centers[i], axis=1)
    return (sim.radii[i] + sim.radii[j] - d) / np.minimum(sim.radii[i], sim.radii[j])


def _max_overlap_fraction(sim):
    return float(np.max(_overlap_fractions(sim)))


def _mean_overlap_fraction(sim):
    """Mean particle-particle overlap over the touching pairs, as a fraction of the smaller radius."""
    return float(np.mean(_overlap_fractions(sim)))

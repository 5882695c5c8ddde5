r"""Lattice-Boltzmann reference for k/k_app(Re) of our own periodic random sphere packings.

Research script (``docs/inertial-lbm.md``): a resolved flow computation on the very
packing the network model uses, to tell whether the network's gap to Beetstra et al. (2007) is
the network's physics or the law's application to our packings.

Method
------
* D3Q19 lattice, TRT collision (Ginzburg): symmetric rate :math:`\omega^+ = 1/\tau`,
  :math:`\nu = (\tau - 1/2)/3`, antisymmetric rate from the magic parameter
  :math:`\Lambda = (1/\omega^+ - 1/2)(1/\omega^- - 1/2) = 3/16`: the halfway bounce-back wall
  sits half-way between nodes and the Stokes permeability does not depend on :math:`\nu`.
* Forcing: Guo et al. (2002) source, split into its symmetric part times
  :math:`1-\omega^+/2` and its antisymmetric part times :math:`1-\omega^-/2`; velocity
  :math:`u = (\sum_i f_i c_i + F/2)/\rho` in the equilibrium and in the output.  Its linear
  (antisymmetric) part equals Ginzburg's first-order source, so the Stokes solution keeps the
  TRT viscosity independence.
* Boundary: halfway bounce-back on every link into a solid node; fully periodic box.
* Drive: uniform body force g per unit mass along x on fluid nodes (force density
  :math:`F = \rho g`).  In a periodic box this is the same problem as a mean pressure gradient
  :math:`G = \rho g` in the fluid (the periodic pressure and the velocity are identical), so
  Darcy's permeability is :math:`k = \nu U/g` with U the superficial velocity (mean of
  :math:`u_x` over all nodes, solid nodes 0).  The force on the fluid per unit box volume is
  :math:`\rho g\varepsilon` (the drag the spheres feel, without the pressure "buoyancy"); the
  ratio :math:`k/k_{app}(Re) = (g/U)(Re) / (g/U)(Re\to 0)` at equal :math:`\nu`-scaling is the
  same whichever of the two is called the gradient, as long as one definition is used at every
  Re: here :math:`k/k_{app} = k_{Stokes} g/(\nu U)`.
* Kernel: fused pull stream-collide over the fluid nodes only (compact SoA layout
  ``f[i * n_fluid + node]``), one precomputed gather index per (direction, node) that points
  either at the upstream fluid neighbour's post-collision population or, for a link from a
  solid node, at this node's own opposite post-collision population (halfway bounce-back).
  numba ``@njit(parallel=True, cache=True)``.
* Steady state: the superficial velocity, averaged over windows of 1000 steps, is compared
  window to window; converged when it changed by < 1e-6 relative, otherwise stopped at the
  step cap (reported per run) and U is the mean of the last 5 window means (their range
  relative to it is reported as ``spread_last5``).

Geometry: ``random_packing(n, diameter_range_m=(1, 1), solid_fraction=phi, periodic=True,
rng=seed)`` in a cube of side L = (pi/6 n/phi)^(1/3) diameters, voxelised with N = round(L D)
nodes per side (so D_eff = N/L lattice units per diameter), node centres at (i + 1/2) dx, a node
solid when inside a sphere (periodic images included).

CLI::

    python docs/scripts/lbm_periodic.py --phi 0.60 --n 40 --seed 1 --resolution 24 \
        --reynolds 0.1 1 5 10 20 50 --json out.json
    python docs/scripts/lbm_periodic.py --validate-sc 0.343 --resolution 24   # Zick & Homsy
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

try:
    from numba import njit, prange
except ImportError:     # a machine without numba can still run --backend cuda
    prange = range

    def njit(*args, **kwargs):
        return (lambda f: f) if not args or not callable(args[0]) else args[0]

# --- D3Q19: rest, then 9 directions, then their opposites (i and i + 9 are opposite) -------
_C9 = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1],
                [1, 1, 0], [1, -1, 0], [1, 0, 1], [1, 0, -1], [0, 1, 1], [0, 1, -1]])
C = np.vstack([[0, 0, 0], _C9, -_C9]).astype(np.int64)
W = np.array([1 / 3] + [1 / 18] * 3 + [1 / 36] * 6 + [1 / 18] * 3 + [1 / 36] * 6)
CX = C[:, 0].astype(np.float64)
CY = C[:, 1].astype(np.float64)
CZ = C[:, 2].astype(np.float64)
MAGIC = 3.0 / 16.0


# --------------------------------------------------------------------------- geometry -------
def voxelise(centers, radii, side, n):
    """Solid mask (n, n, n) bool of spheres in a periodic cube of side ``side``; node centres at
    (i + 1/2) side/n; a node is solid if it lies strictly within a sphere or a periodic image."""
    dx = side / n
    solid = np.zeros((n, n, n), dtype=bool)
    for c, r in zip(np.asarray(centers, float), np.asarray(radii, float)):
        lo = np.floor((c - r) / dx - 0.5).astype(int)
        hi = np.ceil((c + r) / dx - 0.5).astype(int)
        idx = [np.arange(lo[k], hi[k] + 1) for k in range(3)]
        d2 = [((ix + 0.5) * dx - c[k]) ** 2 for k, ix in enumerate(idx)]
        inside = (d2[0][:, None, None] + d2[1][None, :, None] + d2[2][None, None, :]) < r * r
        ii, jj, kk = np.nonzero(inside)
        solid[idx[0][ii] % n, idx[1][jj] % n, idx[2][kk] % n] = True
    return solid


def gather_index(solid):
    """Fluid node list and the pull-gather index (19 * n_fluid,) int32 described in the
    module notes; node ids in raster order (x fastest in memory order of ``solid``)."""
    n = solid.shape
    fluid = ~solid
    ids = -np.ones(n, dtype=np.int64)
    nf = int(fluid.sum())
    ids[fluid] = np.arange(nf)
    own = ids[fluid]
    index = np.empty(19 * nf, dtype=np.int32)   # 19 nf < 2^31
    opp = np.r_[0, np.arange(10, 19), np.arange(1, 10)]
    for i in range(19):
        # upstream node x - c_i: roll by +c_i brings the value at x - c_i to x
        up = np.roll(ids, shift=tuple(C[i]), axis=(0, 1, 2))[fluid]
        index[i * nf:(i + 1) * nf] = np.where(up >= 0, i * nf + up, opp[i] * nf + own)
    return index, nf


# --------------------------------------------------------------------------- kernel ---------
@njit(parallel=True, cache=True, fastmath=True)
def _step(fin, fout, index, nf, omp, omm, gx):
    """One pull stream + TRT/Guo collide over all fluid nodes; returns sum of u_x."""
    total = 0.0
    for n in prange(nf):
        rho = 0.0
        jx = 0.0
        jy = 0.0
        jz = 0.0
        for i in range(19):
            v = fin[index[i * nf + n]]
            rho += v
            jx += CX[i] * v
            jy += CY[i] * v
            jz += CZ[i] * v
        fx = rho * gx
        ux = (jx + 0.5 * fx) / rho
        uy = jy / rho
        uz = jz / rho
        usq = 1.5 * (ux * ux + uy * uy + uz * uz)
        ufx = ux * fx
        total += ux
        # rest population: symmetric only
        v0 = fin[index[n]]
        e0 = W[0] * rho * (1.0 - usq)
        s0 = W[0] * (-3.0 * ufx)
        fout[n] = v0 - omp * (v0 - e0) + (1.0 - 0.5 * omp) * s0
        for p in range(1, 10):
            q = p + 9
            a = fin[index[p * nf + n]]
            b = fin[index[q * nf + n]]
            cu = CX[p] * ux + CY[p] * uy + CZ[p] * uz
            cf = CX[p] * fx
            ep = W[p] * rho * (1.0 + 4.5 * cu * cu - usq)
            em = W[p] * rho * 3.0 * cu
            sp = W[p] * (9.0 * cu * cf - 3.0 * ufx)
            sm = W[p] * 3.0 * cf
            fp = 0.5 * (a + b)
            fm = 0.5 * (a - b)
            cp = -omp * (fp - ep) + (1.0 - 0.5 * omp) * sp
            cm = -omm * (fm - em) + (1.0 - 0.5 * omm) * sm
            fout[p * nf + n] = a + cp + cm
            fout[q * nf + n] = b + cp - cm
    return total


@njit(parallel=True, cache=True)
def _equilibrium(f, nf, ux):
    """Populations at rest density 1 with velocity (ux[n], 0, 0) (post-collision storage)."""
    for n in prange(nf):
        u = ux[n]
        usq = 1.5 * u * u
        for i in range(19):
            cu = CX[i] * u
            f[i * nf + n] = W[i] * (1.0 + 3.0 * cu + 4.5 * cu * cu - usq)


@njit(parallel=True, cache=True)
def _velocity_x(f, index, nf, gx, out):
    """u_x per fluid node of the post-collision state (one pull, as the kernel sees it)."""
    for n in prange(nf):
        rho = 0.0
        jx = 0.0
        for i in range(19):
            v = f[index[i * nf + n]]
            rho += v
            jx += CX[i] * v
        out[n] = (jx + 0.5 * rho * gx) / rho


def omegas(tau):
    """(omega+, omega-) of the TRT collision at relaxation time ``tau`` and Lambda = 3/16."""
    omp = 1.0 / tau
    omm = 1.0 / (MAGIC / (tau - 0.5) + 0.5)
    return omp, omm


# --------------------------------------------------------------------------- lattice ------
class Lattice:
    """Fluid nodes of one voxelised periodic box, the gather index and two population arrays."""

    def __init__(self, solid):
        self.shape = solid.shape
        self.n_nodes = int(solid.size)
        self.index, self.nf = gather_index(solid)
        self.f = np.empty(19 * self.nf)
        self.g = np.empty(19 * self.nf)
        self.ux = np.zeros(self.nf)
        _equilibrium(self.f, self.nf, self.ux)

    def start_from(self, ux):
        self.ux = np.asarray(ux, float).copy()
        _equilibrium(self.f, self.nf, self.ux)

    def steps(self, count, omp, omm, gx):
        """``count`` steps; returns the sum over them of sum_nodes u_x."""
        acc = 0.0
        for _ in range(count):
            acc += _step(self.f, self.g, self.index, self.nf, omp, omm, gx)
            self.f, self.g = self.g, self.f
        return acc

    def velocity_x(self, gx):
        """u_x per fluid node of the current state."""
        _velocity_x(self.f, self.index, self.nf, gx, self.ux)
        return self.ux

    def _sync(self):
        pass

    def run(self, tau, gx, *, tol=1e-6, check=1000, max_steps=30000):
        """Steps to steady state. Returns dict(U superficial, steps, converged, seconds)."""
        omp, omm = omegas(tau)
        self._sync()
        t0 = time.perf_counter()
        u_prev = None
        steps = 0
        converged = False
        history = []
        while steps < max_steps:
            acc = self.steps(check, omp, omm, gx)
            steps += check
            u = acc / check / self.n_nodes       # superficial velocity, mean over the window
            history.append(u)
            if not np.isfinite(u):
                break
            if u_prev is not None and abs(u - u_prev) < tol * abs(u):
                converged = True
                break
            u_prev = u
        self.ux = self.velocity_x(gx)
        if converged:
            u_sup = float(self.ux.sum()) / self.n_nodes
            spread = 0.0
        else:   # step cap: mean of the last 5 window means, their range as the spread
            tail = np.array(history[-5:])
            u_sup = float(tail.mean())
            spread = float((tail.max() - tail.min()) / abs(u_sup))
        rel = abs(history[-1] - history[-2]) / abs(history[-1]) if len(history) > 1 else np.nan
        return {"U": u_sup, "steps": steps, "converged": converged,
                "last_rel_change": float(rel), "spread_last5": spread,
                "seconds": time.perf_counter() - t0,
                "mlups": self.nf * steps / (time.perf_counter() - t0) / 1e6,
                "history": [float(h) for h in history]}


# --------------------------------------------------------------------------- CUDA backend ---
_CUDA_SRC = r"""
__constant__ double CXd[19] = {0,1,0,0,1,1,1,1,0,0,-1,0,0,-1,-1,-1,-1,0,0};
__constant__ double CYd[19] = {0,0,1,0,1,-1,0,0,1,1,0,-1,0,-1,1,0,0,-1,-1};
__constant__ double CZd[19] = {0,0,0,1,0,0,1,-1,1,-1,0,0,-1,0,0,-1,1,-1,1};
__constant__ double Wd[19] = {1.0/3, 1.0/18, 1.0/18, 1.0/18, 1.0/36, 1.0/36, 1.0/36, 1.0/36,
                              1.0/36, 1.0/36, 1.0/18, 1.0/18, 1.0/18, 1.0/36, 1.0/36, 1.0/36,
                              1.0/36, 1.0/36, 1.0/36};
extern "C" __global__ void lbm_step(const double* __restrict__ fin, double* __restrict__ fout,
                                    const int* __restrict__ index, const long long nf,
                                    const double omp, const double omm, const double gx,
                                    double* __restrict__ usum)
{
    long long n = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    double uxl = 0.0;
    if (n < nf) {
        double v[19];
        double rho = 0.0, jx = 0.0, jy = 0.0, jz = 0.0;
        #pragma unroll
        for (int i = 0; i < 19; ++i) {
            v[i] = fin[index[i * nf + n]];
            rho += v[i]; jx += CXd[i] * v[i]; jy += CYd[i] * v[i]; jz += CZd[i] * v[i];
        }
        double fx = rho * gx;
        double ux = (jx + 0.5 * fx) / rho, uy = jy / rho, uz = jz / rho;
        double usq = 1.5 * (ux * ux + uy * uy + uz * uz);
        double ufx = ux * fx;
        uxl = ux;
        double e0 = Wd[0] * rho * (1.0 - usq);
        double s0 = Wd[0] * (-3.0 * ufx);
        fout[n] = v[0] - omp * (v[0] - e0) + (1.0 - 0.5 * omp) * s0;
        #pragma unroll
        for (int p = 1; p < 10; ++p) {
            int q = p + 9;
            double a = v[p], b = v[q];
            double cu = CXd[p] * ux + CYd[p] * uy + CZd[p] * uz;
            double cf = CXd[p] * fx;
            double ep = Wd[p] * rho * (1.0 + 4.5 * cu * cu - usq);
            double em = Wd[p] * rho * 3.0 * cu;
            double sp = Wd[p] * (9.0 * cu * cf - 3.0 * ufx);
            double sm = Wd[p] * 3.0 * cf;
            double fp = 0.5 * (a + b), fm = 0.5 * (a - b);
            double cp = -omp * (fp - ep) + (1.0 - 0.5 * omp) * sp;
            double cm = -omm * (fm - em) + (1.0 - 0.5 * omm) * sm;
            fout[p * nf + n] = a + cp + cm;
            fout[q * nf + n] = b + cp - cm;
        }
    }
    // block sum of u_x -> one atomic add per block
    for (int off = 16; off > 0; off >>= 1) uxl += __shfl_down_sync(0xffffffff, uxl, off);
    __shared__ double part[32];
    int lane = threadIdx.x & 31, warp = threadIdx.x >> 5;
    if (lane == 0) part[warp] = uxl;
    __syncthreads();
    if (warp == 0) {
        uxl = (lane < (blockDim.x >> 5)) ? part[lane] : 0.0;
        for (int off = 16; off > 0; off >>= 1) uxl += __shfl_down_sync(0xffffffff, uxl, off);
        if (lane == 0) atomicAdd(usum, uxl);
    }
}
"""


class CudaLattice(Lattice):
    """The :class:`Lattice` on an NVIDIA GPU through CuPy: the same pull stream + TRT/Guo
    collide, one thread per fluid node (``_CUDA_SRC``), the populations in device memory;
    :meth:`Lattice.run` drives it (``ux`` is a device array)."""

    BLOCK = 256

    def __init__(self, solid):
        import cupy as cp

        self.cp = cp
        self.shape = solid.shape
        self.n_nodes = int(solid.size)
        index, self.nf = gather_index(solid)
        self.index = cp.asarray(index)
        self.f = cp.empty(19 * self.nf)
        self.g = cp.empty(19 * self.nf)
        self.usum = cp.zeros(1)
        self.kernel = cp.RawKernel(_CUDA_SRC, "lbm_step")
        self.start_from(cp.zeros(self.nf))

    def start_from(self, ux):
        cp = self.cp
        self.ux = cp.asarray(ux, dtype=cp.float64).copy()
        usq = 1.5 * self.ux * self.ux
        for i in range(19):
            cu = CX[i] * self.ux
            self.f[i * self.nf:(i + 1) * self.nf] = W[i] * (1.0 + 3.0 * cu + 4.5 * cu * cu - usq)

    def steps(self, count, omp, omm, gx):
        """``count`` steps; returns the sum over them of sum_nodes u_x (host float)."""
        cp = self.cp
        grid = ((self.nf + self.BLOCK - 1) // self.BLOCK,)
        self.usum[...] = 0.0
        args_tail = (np.int64(self.nf), np.float64(omp), np.float64(omm), np.float64(gx),
                     self.usum)
        for _ in range(count):
            self.kernel(grid, (self.BLOCK,), (self.f, self.g, self.index) + args_tail)
            self.f, self.g = self.g, self.f
        return float(self.usum.get()[0])

    def velocity_x(self, gx):
        cp = self.cp
        rho = cp.zeros(self.nf)
        jx = cp.zeros(self.nf)
        for i in range(19):
            v = self.f[self.index[i * self.nf:(i + 1) * self.nf]]
            rho += v
            jx += CX[i] * v
        return (jx + 0.5 * rho * gx) / rho

    def _sync(self):
        self.cp.cuda.Device().synchronize()


def check_cuda_against_numba(solid, steps=200, tau=0.6, gx=2e-5, log=print):
    """Run both kernels ``steps`` steps from the same non-trivial state; returns the largest
    |f_cuda - f_numba| over all populations (both float64; only summation order differs)."""
    cpu = Lattice(solid)
    gpu = CudaLattice(solid)
    rng = np.random.default_rng(0)
    ux0 = 0.01 * rng.random(cpu.nf)
    cpu.start_from(ux0)
    gpu.start_from(ux0)
    omp, omm = omegas(tau)
    s_cpu = cpu.steps(steps, omp, omm, gx)
    s_gpu = gpu.steps(steps, omp, omm, gx)
    diff = float(np.abs(gpu.f.get() - cpu.f).max())
    log(f"# CUDA vs numba after {steps} steps ({cpu.nf} fluid nodes): max |df| {diff:.2e}, "
        f"sum u_x {s_gpu:.12e} vs {s_cpu:.12e}")
    return diff, s_gpu, s_cpu


# --------------------------------------------------------------------------- drivers --------
def packing_box(phi, n, seed):
    from network.packing import random_packing

    pk = random_packing(n, diameter_range_m=(1.0, 1.0), solid_fraction=phi, periodic=True,
                        rng=seed)
    side = (math.pi / 6.0 * n / phi) ** (1.0 / 3.0)
    c = np.asarray(pk.centers, float)
    if c.min() < 0 or c.max() >= side:
        raise ValueError(f"centres outside [0, L): [{c.min()}, {c.max()}], L = {side}")
    return c, np.asarray(pk.radii, float), side


def array_box(kind, phi):
    """(centers, radii, side) of one cubic cell of a simple-cubic or FCC array of unit spheres
    at solid fraction ``phi``; flow along a cube axis (x), as ``lattice_inertial_case``."""
    per_cell = {"sc": 1, "fcc": 4}[kind]
    side = (per_cell * math.pi / (6.0 * phi)) ** (1.0 / 3.0)
    base = {"sc": [[0.5, 0.5, 0.5]],
            "fcc": [[0.25, 0.25, 0.25], [0.25, 0.75, 0.75], [0.75, 0.25, 0.75],
                    [0.75, 0.75, 0.25]]}[kind]
    return np.array(base) * side, np.full(per_cell, 0.5), side


def plan(re, d_lu, *, u_max=0.02, tau_stokes=1.0, tau_min=0.51):
    """(tau, target superficial U) for a run at particle Reynolds number ``re``: the Stokes
    tau while U = Re nu/d <= u_max, else U = u_max and nu = U d/Re (tau >= tau_min)."""
    nu0 = (tau_stokes - 0.5) / 3.0
    u = re * nu0 / d_lu
    if u <= u_max:
        return tau_stokes, u
    nu = u_max * d_lu / re
    tau = 3.0 * nu + 0.5
    if tau < tau_min:
        raise ValueError(f"Re {re} at d = {d_lu:.1f} lu needs tau {tau:.4f} < {tau_min}")
    return tau, u_max


def _laws():
    """(beetstra_permeability, drag_ratio) of network.validation, or None where the package
    cannot be imported (a bare GPU machine): the run then starts from a Kozeny-Carman guess and
    leaves the laws' columns empty, to be filled where the package is installed."""
    try:
        from network.validation import beetstra_permeability, drag_ratio
    except ImportError:
        return None
    return beetstra_permeability, drag_ratio


def load_packing(path):
    """(centers, radii, side, phi, n, seed) of a packing written by ``--export-packing``."""
    z = np.load(path)
    return (np.asarray(z["centers"], float), np.asarray(z["radii"], float), float(z["side"]),
            float(z["phi"]), int(z["n"]), int(z["seed"]))


def packing_curve(phi, n, seed, resolution, reynolds, *, u_max=0.02, tau_stokes=1.0,
                  max_steps=30000, backend="numba", packing=None, time_budget=None,
                  on_update=None, log=print):
    """k/k_app(Re) of one periodic packing (module notes). ``packing``: (centers, radii, side)
    instead of generating it; ``time_budget`` (s): no new Re is started after it; ``on_update``
    is called with the result so far after every Re (incremental JSON). ``u_max``: one
    superficial lattice velocity limit for every Re, or one per entry of ``reynolds``."""
    laws = _laws()
    limits = np.broadcast_to(np.asarray(u_max, float), (len(reynolds),))
    if not np.all(limits > 0):
        raise ValueError(f"u_max must be > 0 and one value or one per Reynolds number: {u_max}")
    u_limit = dict(zip(reynolds, limits))
    if packing is None:
        centers, radii, side = packing_box(phi, n, seed)
    else:
        centers, radii, side = packing
    nn = int(round(side * resolution))
    d_lu = nn / side
    t0 = time.perf_counter()
    solid = voxelise(centers, radii, side, nn)
    lat = (CudaLattice if backend == "cuda" else Lattice)(solid)
    phi_vox = float(solid.mean())
    log(f"# packing phi={phi} n={n} seed={seed}: L = {side:.4f} d, grid {nn}^3, "
        f"D_eff = {d_lu:.3f} lu/d, voxel solid fraction {phi_vox:.4f}, "
        f"{lat.nf} fluid nodes, setup {time.perf_counter() - t0:.1f} s, backend {backend}")
    rows = []
    k_stokes = None
    eps = 1.0 - phi
    k_guess = (float(laws[0](phi, d_lu)) if laws else
               d_lu**2 * eps**3 / (180.0 * (1.0 - eps)**2))
    res = {"phi": phi, "n": n, "seed": seed, "resolution": resolution, "side_d": side,
           "grid": nn, "d_lu": d_lu, "phi_voxel": phi_vox, "n_fluid": lat.nf,
           "backend": backend, "k_stokes_d2": None,
           "k_beetstra_d2": float(laws[0](phi, 1.0)) if laws else None, "rows": rows}
    for re in sorted(reynolds):
        if time_budget is not None and time.perf_counter() - t0 > time_budget:
            log(f"# time budget {time_budget:.0f} s spent: Re {re} and above not run")
            break
        tau, u_t = plan(re, d_lu, u_max=float(u_limit[re]), tau_stokes=tau_stokes)
        nu = (tau - 0.5) / 3.0
        k_use = k_stokes if k_stokes is not None else k_guess
        ratio_guess = float(laws[1]("beetstra", phi, re)) if laws else 1.0 + 0.01 * re
        gx = nu * u_t / k_use * ratio_guess
        if rows:   # warm start: previous field scaled to the expected superficial velocity
            lat.start_from(lat.ux * (u_t / rows[-1]["U_lu"]))
        r = lat.run(tau, gx, max_steps=max_steps)
        u = r["U"]
        re_got = u * d_lu / nu
        k_app = nu * u / gx
        if k_stokes is None:
            if re_got > 0.1 * 1.05:
                raise ValueError(f"first run must be Stokes (Re <= 0.1), got {re_got:.3g}")
            k_stokes = k_app
            res["k_stokes_d2"] = k_stokes / d_lu**2
        ok = bool(np.isfinite(re_got))
        row = {"re_target": re, "re": re_got, "tau": tau, "nu": nu, "g": gx, "U_lu": u,
               "u_max": float(u_limit[re]),
               "k_app_lu2": k_app, "k_ratio": k_stokes / k_app,
               "beetstra": float(laws[1]("beetstra", phi, re_got)) if laws and ok else None,
               "hill_koch_ladd": (float(laws[1]("hill_koch_ladd", phi, re_got))
                                  if laws and ok else None),
               "steps": r["steps"], "converged": r["converged"],
               "last_rel_change": r["last_rel_change"], "spread_last5": r["spread_last5"],
               "seconds": r["seconds"],
               "mlups": r["mlups"], "history_every_1000": r["history"]}
        rows.append(row)
        laws_txt = (f"Beetstra {row['beetstra']:.4f}  HKL {row['hill_koch_ladd']:.4f}  "
                    if laws and ok else "")
        log(f"Re {re_got:8.4f}  tau {tau:.4f}  U {u:.3e}  k/k_app {row['k_ratio']:.4f}  "
            f"{laws_txt}steps {r['steps']} ({'converged' if r['converged'] else 'step cap'}, "
            f"last change {r['last_rel_change']:.1e}, spread {r['spread_last5']:.1e})  "
            f"{r['seconds']:.0f} s, {r['mlups']:.1f} MLUPS")
        if on_update is not None:
            on_update(res)
        if not np.isfinite(u):
            log(f"# Re {re}: the lattice went unstable (tau {tau:.4f}); higher Re not run")
            break
    return res


def validate_sc(phi, resolution, taus=(1.0,), max_steps=30000, log=print):
    """Stokes flow through a simple-cubic array (one sphere of radius a per cell of side
    ``resolution`` lu): drag K = F/(6 pi mu a U) against Zick & Homsy (1982), per tau."""
    from network.validation import zick_homsy_sc_drag

    n = int(resolution)
    a = (3.0 * phi / (4.0 * math.pi)) ** (1.0 / 3.0) * n   # radius in lu
    solid = voxelise(np.array([[n / 2, n / 2, n / 2]]), np.array([a]), float(n), n)
    lat = Lattice(solid)
    out = []
    for tau in taus:
        nu = (tau - 0.5) / 3.0
        gx = 1e-6
        lat.start_from(np.zeros(lat.nf))
        r = lat.run(tau, gx, max_steps=max_steps)
        k = nu * r["U"] / gx
        # drag per sphere = G * cell volume, G = rho g (module notes): K = g n^3/(6 pi nu a U)
        kk = gx * n**3 / (6 * math.pi * nu * a * r["U"])
        ref = float(zick_homsy_sc_drag(phi))
        row = {"phi": phi, "cell_lu": n, "a_lu": a, "phi_voxel": float(solid.mean()),
               "tau": tau, "K": kk, "K_zick_homsy": ref, "error": kk / ref - 1,
               "k_over_a2": k / a**2, "steps": r["steps"], "converged": r["converged"],
               "seconds": r["seconds"]}
        log(f"SC phi {phi} cell {n} lu a {a:.2f} lu tau {tau}: K {kk:.4f} vs Zick-Homsy "
            f"{ref:.4f} ({100 * (kk / ref - 1):+.2f} %), k/a^2 {k / a**2:.6f}, "
            f"{r['steps']} steps ({'conv' if r['converged'] else 'cap'}), {r['seconds']:.1f} s")
        out.append(row)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--phi", type=float, default=0.60)
    p.add_argument("--n", type=int, default=40)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--resolution", type=float, default=24)
    p.add_argument("--reynolds", type=float, nargs="+", default=[0.1, 1, 5, 10, 20, 50])
    p.add_argument("--u-max", type=float, nargs="+", default=[0.02],
                   help="largest superficial lattice velocity (default 0.02); one value, or "
                        "one per --reynolds value")
    p.add_argument("--tau-stokes", type=float, default=1.0,
                   help="tau while the velocity limit allows it (default 1.0)")
    p.add_argument("--max-steps", type=int, default=30000)
    p.add_argument("--validate-sc", type=float, default=None, metavar="PHI",
                   help="Zick-Homsy simple-cubic check at this solid fraction instead")
    p.add_argument("--taus", type=float, nargs="+", default=[1.0])
    p.add_argument("--json", default=None)
    p.add_argument("--backend", choices=("numba", "cuda"), default="numba",
                   help="numba on the CPU cores (default) or CUDA through CuPy")
    p.add_argument("--packing", default=None, metavar="NPZ",
                   help="run this packing (written by --export-packing) instead of generating")
    p.add_argument("--export-packing", default=None, metavar="NPZ",
                   help="write the packing of --phi/--n/--seed to NPZ and stop")
    p.add_argument("--time-budget", type=float, default=None, metavar="S",
                   help="start no new Reynolds number after S seconds")
    p.add_argument("--array", choices=("sc", "fcc"), default=None,
                   help="a simple-cubic or FCC array's unit cell at --phi instead of a packing")
    p.add_argument("--check-cuda", type=int, default=0, metavar="STEPS",
                   help="first compare the CUDA and numba kernels over STEPS steps")
    a = p.parse_args(argv)

    def write(res):
        if a.json:
            out = {"threads": int(os.environ.get("NUMBA_NUM_THREADS", 0)) or None,
                   "result": res}
            with open(a.json, "w") as fh:
                json.dump(out, fh, indent=1)

    if a.export_packing:
        c, r, side = packing_box(a.phi, a.n, a.seed)
        np.savez(a.export_packing, centers=c, radii=r, side=side, phi=a.phi, n=a.n, seed=a.seed)
        print(f"wrote {a.export_packing}: {a.n} spheres, phi {a.phi}, seed {a.seed}, L {side:.4f}")
        return 0
    packing = None
    if a.array:
        packing = array_box(a.array, a.phi)
        a.n, a.seed = len(packing[1]), 0
    if a.packing:
        c, r, side, a.phi, a.n, a.seed = load_packing(a.packing)
        packing = (c, r, side)
    if a.validate_sc is not None:
        res = validate_sc(a.validate_sc, a.resolution, taus=a.taus, max_steps=a.max_steps)
    else:
        if a.check_cuda and njit.__module__ != __name__:
            c, r, side = packing if packing else packing_box(a.phi, a.n, a.seed)
            check_cuda_against_numba(voxelise(c, r, side, int(round(side * 16))),
                                     steps=a.check_cuda)
        res = packing_curve(a.phi, a.n, a.seed, a.resolution, a.reynolds, u_max=a.u_max,
                            tau_stokes=a.tau_stokes, max_steps=a.max_steps, backend=a.backend,
                            packing=packing, time_budget=a.time_budget, on_update=write)
        if res["k_beetstra_d2"]:
            print(f"Stokes k/d^2 = {res['k_stokes_d2']:.6f} (van der Hoef et al. 2005 law: "
                  f"{res['k_beetstra_d2']:.6f}, "
                  f"ratio {res['k_stokes_d2'] / res['k_beetstra_d2']:.3f})")
            print(f"{'Re':>8} {'LBM':>8} {'Beetstra':>9} {'HKL':>8} {'LBM/B-1 %':>10}")
            for r in res["rows"]:
                if r["beetstra"] is None:
                    continue
                print(f"{r['re']:8.3f} {r['k_ratio']:8.4f} {r['beetstra']:9.4f} "
                      f"{r['hill_koch_ladd']:8.4f} "
                      f"{100 * (r['k_ratio'] / r['beetstra'] - 1):+10.2f}")
    write(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Axisymmetric steady Navier-Stokes through one sphere-ring constriction (docs/inertial-flow.md).

The derivation behind ``network.conductance.onset_scales`` and the 'smooth' contraction: a
tube of radius R_b, narrowed to a window of radius r_w by a ring of spheres of radius a
(wall r(z) = r_w + a - sqrt(a^2 - z^2) for |z| <= h, R_b = r(h)), with a parabolic inflow
3 upstream and 25 (35 for the mesh check) downstream of the window. Taylor-Hood
P2/P1 on a mapped tensor mesh (wall-graded), Newton with continuation in Re, scikit-fem.
Printed per Re_w = rho u_w 2 r_w / mu: the excess loss coefficient
k = (dp - dp_Stokes) / (rho u_w^2 / 2) over inlet-to-outlet section-mean pressures.

Not part of the package (network never imports scikit-fem): run it by hand,
``python docs/scripts/inertial_constriction_ns.py 0.3,0.6 0.15,0.6`` (r_w,h with a = 1),
about 30-90 s per constriction on one core.
"""

import json
import sys

import numpy as np
from skfem import (Basis, BilinearForm, ElementTriP1, ElementTriP2, ElementVector, LinearForm,
                   MeshTri, asm, bmat, condense, solve)
from skfem.helpers import ddot, dot, grad

from _ns_newton import newton      # this folder's Newton loop, shared by both scripts


@BilinearForm
def viscous(u, v, w):
    r = w.x[1]                       # x[0] = z (axial), x[1] = r
    return (ddot(grad(u), grad(v)) + u[1] * v[1] / r**2) * r


@BilinearForm
def divergence(u, q, w):
    r = w.x[1]
    return -(grad(u)[0, 0] + grad(u)[1, 1] + u[1] / r) * q * r


@BilinearForm
def convection_jacobian(u, v, w):
    r, u0 = w.x[1], w["u0"]
    a = (np.einsum("j...,ij...->i...", u0, grad(u))
         + np.einsum("j...,ij...->i...", u, grad(u0)))
    return dot(a, v) * r


@LinearForm
def convection(v, w):
    r, u0 = w.x[1], w["u0"]
    return dot(np.einsum("j...,ij...->i...", u0, grad(u0)), v) * r


def _z_nodes(h, up, down, dz):
    def stretch(length):
        pts, d = [0.0], dz
        while pts[-1] < length:
            pts.append(pts[-1] + d)
            d *= 1.06
        return np.array(pts) * (length / pts[-1])
    core = np.linspace(-h, h, int(round(2 * h / dz)) + 1)
    return np.concatenate([-h - stretch(up)[1:][::-1], core, h + stretch(down)[1:]])


def constriction(rw, h, reynolds, *, a=1.0, up=3.0, down=25.0, dz=0.025, n_radial=24):
    """Rows (dict) per window Reynolds number; ``k_excess`` as in the module docstring."""
    rb = rw + a - np.sqrt(a * a - h * h)

    def wall(z):
        zz = np.clip(z, -h, h)
        return rw + a - np.sqrt(a * a - zz * zz)

    zs = _z_nodes(h, up, down, dz)
    s = 1 - (1 - np.linspace(0, 1, n_radial + 1)) ** 1.6
    m = MeshTri.init_tensor(zs, s)
    m = MeshTri(np.vstack([m.p[0], m.p[1] * wall(m.p[0])]), m.t)
    bu = Basis(m, ElementVector(ElementTriP2()), intorder=4)
    bp = Basis(m, ElementTriP1(), intorder=4)
    A, B = asm(viscous, bu), asm(divergence, bu, bp)
    nu = bu.N
    stokes = bmat([[A, B.T], [B, None]], "csr")
    bf = m.boundary_facets()
    fv = m.p[:, m.facets[:, bf]]
    on_wall = bf[np.all(np.abs(fv[1] - wall(fv[0])) < 1e-9, axis=0)]
    on_axis = bf[np.all(np.abs(fv[1]) < 1e-12, axis=0)]
    inlet = bf[np.all(np.abs(fv[0] - zs[0]) < 1e-12, axis=0)]
    radial = np.zeros(nu, bool)
    radial[bu.dofs.nodal_dofs[1]] = radial[bu.dofs.facet_dofs[1]] = True
    d_in, d_axis = bu.get_dofs(inlet).all(), bu.get_dofs(on_axis).all()
    D = np.unique(np.concatenate([bu.get_dofs(on_wall).all(), d_in, d_axis[radial[d_axis]]]))
    x = np.zeros(nu + bp.N)
    axial_in = d_in[~radial[d_in]]
    x[axial_in] = 2.0 * (1 - (bu.doflocs[1][axial_in] / rb) ** 2)       # mean velocity 1
    q = np.pi * rb**2

    def section_mean(p, z):
        col = np.flatnonzero(np.abs(bp.doflocs[0] - z) < 1e-9)
        o = np.argsort(bp.doflocs[1][col])
        rr, pp = bp.doflocs[1][col][o], p[col][o]
        return np.trapezoid(pp * rr, rr) / np.trapezoid(rr, rr)

    z_out = zs[np.searchsorted(zs, zs[-1] - 2.0)]
    U = solve(*condense(stokes, np.zeros_like(x), x=x, D=D))
    dp_stokes = section_mean(U[nu:], zs[0]) - section_mean(U[nu:], z_out)
    dp_conduit = section_mean(U[nu:], -h) - section_mean(U[nu:], h)
    uw = q / (np.pi * rw**2)
    rows = []
    for re in reynolds:
        rho = re / (uw * 2 * rw)             # mu = 1
        U, steps = newton(U, rho, A=A, B=B, stokes=stokes, basis_u=bu, nu=nu, D=D,
                          convection=convection, convection_jacobian=convection_jacobian,
                          rtol=1e-9, maxiter=60)
        dp = section_mean(U[nu:], zs[0]) - section_mean(U[nu:], z_out)
        rows.append({"rw": rw, "h": h, "sigma": rw**2 / rb**2, "Re": re, "newton": steps,
                     "k_excess": (dp - dp_stokes) / (0.5 * rho * uw**2),
                     "excess_over_conduit_stokes": (dp - dp_stokes) / dp_conduit})
    return rows


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        rw, h = map(float, arg.split(","))
        for row in constriction(rw, h, [1, 2, 5, 10, 20, 50, 100, 200]):
            print(json.dumps(row), flush=True)

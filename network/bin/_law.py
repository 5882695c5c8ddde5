r"""The resistance law of the grain bulk: Darcy-Forchheimer (or D272's Shedd form) with a tensor
permeability, inverted for the velocity in closed form.

Isotropic law, superficial velocity u (m/s), pressure gradient (Pa/m):

.. math:: \nabla p = -\Big(\frac{\mu}{k} + \beta\rho|u|\Big) u .

Anisotropy. With K = k_v A, A = diag(a, a, 1) (a = k_h/k_v; in r-z, A = diag(a, 1)), the law
used is

.. math:: \nabla p = -\big(\mu k_v^{-1} + \beta_v\rho|w|\big)\,A^{-1}u, \qquad w = A^{-1/2}u,

the inertial term acting on the K-scaled velocity w. Writing g = ∇p, the scaled gradient
magnitude G = (g·A g)^{1/2} (Pa/m) and W = |w| (m/s), multiplying by A^{1/2} gives
A^{1/2} g = -(F(W)/W) w, so G = F(W) with F(W) = μW/k_v + β_v ρ W², a scalar quadratic whose
positive root is

.. math:: W(G) = \frac{2G}{c_1 + \sqrt{c_1^2 + 4 c_2 G}}, \quad c_1 = \mu/k_v,\;
          c_2 = \beta_v\rho, \qquad u = -M(G)\,A\,g, \quad M = W/G .

Along a principal axis it is the directional law: vertical flow gives (k_v, β_v), horizontal
flow (k_h = a k_v, β_h = β_v a^{-3/2}). The flux q(g) = -M(G) A g is the gradient of the convex
potential Φ(g) = ∫_0^G W(s) ds, so the Newton matrix

.. math:: \frac{\partial q}{\partial g} = -\big(M A + (W' - M)\,n n^{\mathsf T}\big),\qquad
          n = A g / G,\ W' = 1/F'(W),

is symmetric and (M > 0, W' > 0) positive definite. Among the diagonal scalings of the inertial
norm |C u| this one, C = A^{-1/2}, is the only one that keeps that symmetry (for another C the
derivative of |C A g| is C²A g/|·|, not A g/G); it fixes β_h/β_v = (k_v/k_h)^{3/2}.

D272's Shedd form: F(W) = f a_D W²/ln(1 + b_D W) (a_D Pa s²/m³, b_D s/m, f a porosity factor), the
same K-scaled construction; W(G) by Newton's method per point (vectorised), from the
Forchheimer form's root as start (ln(1+x) ≈ x - x²/2: c_1 = f a_D/b_D, c_2 = f a_D/2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ForchheimerLaw", "SheddLaw", "closed_form_radial_airflow"]


@dataclass(frozen=True)
class ForchheimerLaw:
    r"""Per element: c1 = μ/k_v (Pa s/m²), c2 = β_v ρ (kg/m⁴), anisotropy a = k_h/k_v.

    >>> law = ForchheimerLaw(np.array([2.0]), np.array([3.0]), 1.0)
    >>> w, dw = law.speed(np.array([2.0 * 0.5 + 3.0 * 0.25]))   # F(0.5) = 1.75
    >>> float(w[0]), round(float(dw[0]), 12)
    (0.5, 0.2)
    """

    c1: np.ndarray
    c2: np.ndarray
    anisotropy: float = 1.0
    name: str = "network"

    def resistance(self, w):
        """F(W), Pa/m: μW/k_v + β_v ρ W²."""
        return self.c1 * w + self.c2 * w * w

    def speed(self, g_scaled):
        """(W, dW/dG) for the scaled gradient magnitude G (Pa/m), closed form."""
        g = np.asarray(g_scaled, dtype=float)
        w = 2.0 * g / (self.c1 + np.sqrt(self.c1**2 + 4.0 * self.c2 * g))
        return w, 1.0 / (self.c1 + 2.0 * self.c2 * w)


@dataclass(frozen=True)
class SheddLaw:
    r"""D272's Shedd form per element: F(W) = f a W² / ln(1 + b W), f per element.

    >>> law = SheddLaw(np.array([1.0]), 2.7e4, 8.77)
    >>> g = law.resistance(np.array([0.1])); w, _ = law.speed(g)
    >>> round(float(w[0]), 12)
    0.1
    """

    factor: np.ndarray
    a: float
    b: float
    anisotropy: float = 1.0
    name: str = "d272"

    def resistance(self, w):
        """F(W), Pa/m: f a W²/ln(1 + bW) (f a W/b at W = 0)."""
        w = np.asarray(w, dtype=float)
        x = self.b * w
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.where(x > 1e-12, self.a * w * w / np.log1p(np.maximum(x, 1e-300)),
                         self.a * w / self.b * (1 + 0.5 * x))
        return self.factor * r

    def _dresistance(self, w):
        x = self.b * w
        lg = np.log1p(x)
        with np.errstate(invalid="ignore", divide="ignore"):
            d = np.where(x > 1e-8, self.a * (2 * w * lg - w * w * self.b / (1 + x)) / lg**2,
                         self.a / self.b * (1 + x))
        return self.factor * d

    def speed(self, g_scaled):
        """(W, dW/dG) for the scaled gradient magnitude G (Pa/m): Newton's method per point
        from the Forchheimer approximation's root, to round-off."""
        g = np.asarray(g_scaled, dtype=float)
        c1, c2 = self.factor * self.a / self.b, self.factor * self.a / 2.0
        w = 2.0 * g / (c1 + np.sqrt(c1**2 + 4.0 * c2 * g))
        for _ in range(60):
            step = (self.resistance(w) - g) / self._dresistance(w)
            w = np.maximum(w - step, 0.5 * w)
            if np.all(np.abs(step) <= 1e-15 * np.maximum(w, 1e-300)):
                break
        return w, 1.0 / self._dresistance(w)


def closed_form_radial_airflow(pressure_pa, *, inner_radius_m, outer_radius_m, length_m,
                               viscosity_pa_s, permeability_m2, beta_per_m, density_kg_m3):
    r"""Airflow, m³/s, of steady radial Darcy-Forchheimer flow from a perforated cylinder of
    radius r_0 and length L to a cylinder r_1 at atmospheric pressure.

    With u = Q/(2π r L): P = (μ/k) Q/(2πL) ln(r_1/r_0) + βρ (Q/(2πL))² (1/r_0 - 1/r_1), the
    positive root of that quadratic in Q.

    >>> q = closed_form_radial_airflow(100.0, inner_radius_m=0.1, outer_radius_m=1.0,
    ...     length_m=1.0, viscosity_pa_s=1.0, permeability_m2=1.0, beta_per_m=0.0,
    ...     density_kg_m3=1.0)
    >>> round(q, 6), round(float(2 * np.pi * 100.0 / np.log(10.0)), 6)  # 2 pi L k P/(mu ln 10)
    (272.875271, 272.875271)
    """
    s = 1.0 / (2 * np.pi * length_m)
    a = beta_per_m * density_kg_m3 * s * s * (1 / inner_radius_m - 1 / outer_radius_m)
    b = viscosity_pa_s / permeability_m2 * s * np.log(outer_radius_m / inner_radius_m)
    return float(2 * pressure_pa / (b + np.sqrt(b * b + 4 * a * pressure_pa)))

"""The mass a collision captures and the specific energy of each captured particle
(docs/grinding.md, Section 3). SI units: m, kg, J, J/kg.

Monolayer capture (the assumption of the UFRJ mechanistic model, Tavares and Carvalho 2009;
tested against DEM by Rodriguez, Carvalho and Tavares 2018): a collision between two media
surfaces nips one layer of particles. A particle of size d is caught where the gap between the
surfaces is narrower than d: between two spheres of radius R the gap at distance r from the
contact axis is r^2 / R, on a plane r^2 / (2 R), so the capture disc has area pi R_eff d with
R_eff = R (spheres) or 2 R (plane). The disc holds a close-packed monolayer (mass per area
PACKING_MONOLAYER rho d, hexagonal packing) of the charge's composition, covered to the fraction
`coverage`. Class i then loses, per collision,

    m_cap,i = w_i * coverage * PACKING_MONOLAYER * rho * pi * R_eff * d_i^2,

w_i its mass fraction of the charge: the same fraction of every class's mass per collision of a
given geometry, so the capture alone is first order.

Collisions that catch nothing: the number caught is Poisson with mean nbar = sum m_cap,i / m_p,i
(m_p,i one particle's mass). A share exp(-nbar) of the collisions catch no particle; the others
catch the expected mass over 1 - exp(-nbar). The energy a collision gives the ore is shared by
mass among the particles it catches (one specific energy for all), so each caught particle
receives e = E (1 - exp(-nbar)) / sum m_cap,i: with nbar >> 1 the plain monolayer E / m_cap,
with nbar << 1 the energy of one collision into one particle.
"""
from __future__ import annotations

import math

import numpy as np

#: mass per unit area of a close-packed monolayer of spheres of diameter d: rho d pi / (3 sqrt 3)
PACKING_MONOLAYER = math.pi / (3.0 * math.sqrt(3.0))


class CaptureModel:
    """Monolayer capture between media of diameter `ball_diameter` (m) for ore of density
    `density` (kg/m3), the capture disc covered by ore to the fraction `coverage` (0-1]."""

    def __init__(self, density, ball_diameter, coverage=1.0):
        self.density = float(density)
        self.radius = 0.5 * float(ball_diameter)
        self.coverage = float(coverage)

    def monolayer_mass(self, sizes, plane=False):
        """Mass (kg) of a covered monolayer of size d (m) over the capture disc of that size:
        coverage PACKING_MONOLAYER rho pi R_eff d^2; `plane` (bool or array broadcasting
        against sizes) selects R_eff = 2R."""
        r_eff = self.radius * np.where(plane, 2.0, 1.0)
        sizes = np.asarray(sizes, dtype=float)
        return self.coverage * PACKING_MONOLAYER * self.density * math.pi * r_eff * sizes ** 2

    def particle_mass(self, sizes):
        """Mass (kg) of one sphere of diameter d (m)."""
        return self.density * math.pi / 6.0 * np.asarray(sizes, dtype=float) ** 3

    def captured_mass(self, fractions, sizes, plane=False):
        """Expected mass (kg) of each class captured per collision, shape plane.shape +
        sizes.shape: w_i times the monolayer mass of d_i."""
        plane = np.asarray(plane)[..., None]
        return np.asarray(fractions, dtype=float) * self.monolayer_mass(sizes, plane)

    def expected_count(self, fractions, sizes, plane=False):
        """nbar, the expected number of particles caught per collision (Poisson mean)."""
        return (self.captured_mass(fractions, sizes, plane) / self.particle_mass(sizes)).sum(-1)

    def specific_energy(self, energy, fractions, sizes, plane=False):
        """Specific energy (J/kg) of each particle caught by a collision that gives the ore
        `energy` J: E (1 - exp(-nbar)) / sum_i m_cap,i. Broadcasts energy against plane."""
        m_cap = self.captured_mass(fractions, sizes, plane)
        nbar = (m_cap / self.particle_mass(sizes)).sum(-1)
        return np.asarray(energy, dtype=float) * -np.expm1(-nbar) / m_cap.sum(-1)


__all__ = ["PACKING_MONOLAYER", "CaptureModel"]

"""Ranges of accepted numbers, one home for the check and its wording: the scripts' options
(tools.options) and attach()'s options (coupling.config) both check their values with it; the
physical ranges of material properties below are checked in material files and scenes. Model
layer: no YADE."""
from __future__ import annotations

import math
from dataclasses import dataclass


class InputError(ValueError):
    """A user's input that yadebreak does not accept (an option, a file's field, a scene): the
    message names it, the value, the accepted range and the unit. Scripts report it in one line
    with exit code 2 (tools.lifecycle.run_script); every layer's own input errors derive from it."""


@dataclass(frozen=True)
class Interval:
    """Finite numbers from lo to hi, each end open (excluded) or closed; infinite ends are open
    by nature. `v in Interval(0, 1, lo_open=True)` tests 0 < v <= 1; str() words it ("in (0, 1]",
    "> 0", "any number")."""
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False

    def __contains__(self, v):
        return (math.isfinite(v) and (v > self.lo if self.lo_open else v >= self.lo)
                and (v < self.hi if self.hi_open else v <= self.hi))

    def __str__(self):
        if self.lo == -math.inf and self.hi == math.inf:
            return "any number"
        if self.hi == math.inf:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.lo == -math.inf:
            return f"{'<' if self.hi_open else '<='} {self.hi:g}"
        return (f"in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}"
                f"{')' if self.hi_open else ']'}")

    def scaled(self, factor):
        """The interval in a unit worth `factor` SI units (GPa: 1e9): its ends divided by it."""
        return Interval(self.lo / factor, self.hi / factor, self.lo_open, self.hi_open)


# -- physical ranges of material properties (SI) ---------------------------------------------------
# Material files (materials.py, bonds.py) and the scene's YADE materials (engine/materials.py)
# are checked against these before a run. Within them the Rayleigh time of a sphere of radius R
# lies between 4.1e-5 R and 2.9 R s (R in m): the time step is finite and positive for any size.
#: kg/m3: from polymer foams and wood (~100) to the densest metals (osmium, 22,600)
DENSITY = Interval(100.0, 25000.0)
#: Pa: from soft rubber (0.1 MPa) to diamond (1,050-1,200 GPa)
YOUNG_MODULUS = Interval(1e5, 1.5e12)
#: -: isotropic compressible solids (0.5, incompressible, excluded)
POISSON_RATIO = Interval(0.0, 0.5, hi_open=True)
#: m: particle and sphere sizes and the models' size parameters, 1 um to 1 m
PARTICLE_SIZE = Interval(1e-6, 1.0)
#: J/kg: specific impact energies v^2/2 below the fastest elastic wave speed sqrt(E/rho) of the
#: ranges above (7.5e9 J/kg); a known material has its own, lower limit (elastic_wave_speed)
SPECIFIC_ENERGY = Interval(0.0, 0.5 * YOUNG_MODULUS.hi / DENSITY.lo, lo_open=True, hi_open=True)


def elastic_wave_speed(young_modulus, density):
    """sqrt(E/rho) (m/s): the speed of sound in a rod of the material. An impact at or above it
    is not a contact that Hertz's quasi-static law describes: the scripts refuse such speeds."""
    return math.sqrt(young_modulus / density)


# -- the bed impact's ball (the paper's steel ball) ------------------------------------------------
BALL_DIAMETER = 0.088          # m
BALL_MASS = 2.78               # kg

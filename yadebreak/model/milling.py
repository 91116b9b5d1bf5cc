"""Laboratory batch ball mill: speeds, power and product analysis as plain, vectorised functions.

The classical relations a ball-mill simulation is checked against: the critical speed, Bond's
ball-mill power equation, the torque-arm power of the charge, the first-order specific rate of
breakage, sieve classes on a root-2 series and the collision energy spectrum of mechanistic mill
models. SI units throughout: lengths in metres, masses in kg, times in s, speeds in rev/s or
rad/s as named, powers in W, specific energies in J/kg.

This module imports only numpy and the standard library: it never imports yade.
"""
from __future__ import annotations

import math

import numpy as np

#: Acceleration of gravity, m/s^2 (the value behind the classical 42.3 / sqrt(D - d) rpm).
GRAVITY = 9.81
#: solid fraction of a settled charge (bulk volume -> solid volume)
PACKING = 0.6


def charge_counts(args):
    """(balls, ore particles) for the fillings: a filling is the bulk volume of the charge over the
    drum's volume; the bulk is PACKING solid."""
    volume = math.pi * (0.5 * args.drum_diameter) ** 2 * args.drum_length
    ball_volume = math.pi / 6 * args.ball_size ** 3
    ore_volume = math.pi / 6 * args.size ** 3
    return (max(1, round(args.ball_filling * volume * PACKING / ball_volume)),
            max(1, round(args.ore_filling * volume * PACKING / ore_volume)))


def _scalar_or_array(a):
    """A 0-d array as a numpy scalar, anything else unchanged (as model.py returns them)."""
    return a[()] if a.ndim == 0 else a


# --------------------------------------------------------------------------- speed and power
def critical_speed(drum_diameter, ball_diameter=0.0):
    """Critical speed N_c of a tumbling mill, rev/s: the speed at which a ball of diameter d
    touching the liner of a drum of inside diameter D (both in m) centrifuges.

    N_c = sqrt(2 g / (D - d)) / (2 pi), g = 9.81 m/s^2: the classical 42.3 / sqrt(D - d) rpm.
    Raises ValueError unless D > d.
    """
    drum_diameter, ball_diameter = np.broadcast_arrays(
        np.asarray(drum_diameter, dtype=float), np.asarray(ball_diameter, dtype=float))
    gap = drum_diameter - ball_diameter
    if not np.all(gap > 0.0):
        raise ValueError("critical_speed: the drum diameter must exceed the ball diameter")
    return _scalar_or_array(np.sqrt(2.0 * GRAVITY / gap) / (2.0 * math.pi))


def bond_mill_power_per_ball_mass(drum_diameter, ball_filling, speed_fraction):
    """Bond's ball-mill power equation, W per kg of balls (1 kW/t = 1 W/kg).

    F.C. Bond (1961), in the form of C.A. Rowland and D.M. Kjos (1980):
    kW/t of balls = 4.879 D^0.3 (3.2 - 3 Vp) Cs (1 - 0.1 / 2^(9 - 10 Cs)) + Ss, with
    D the mill diameter inside the liners (m), Vp the ball filling (fraction of the mill volume
    taken by the ball bed, 0-0.5) and Cs the fraction of critical speed. The ball-size factor Ss
    is zero for D < 3.3 m and is left out: laboratory mills (D ~ 0.2-0.5 m) are far below that, so
    for D >= 3.3 m this underestimates by Ss. An empirical fit for overflow wet mills, meant for
    Cs about 0.6-0.85 and Vp 0.2-0.5; nothing outside that range is refused.
    """
    drum_diameter, ball_filling, speed_fraction = (
        np.asarray(a, dtype=float) for a in (drum_diameter, ball_filling, speed_fraction))
    power = (4.879 * drum_diameter ** 0.3 * (3.2 - 3.0 * ball_filling) * speed_fraction
             * (1.0 - 0.1 / 2.0 ** (9.0 - 10.0 * speed_fraction)))
    return _scalar_or_array(np.asarray(power))


def charge_torque_power(charge_mass, lever_arm, angular_speed):
    """Torque-arm power of a tumbling charge, W (Hogg and Fuerstenau 1972): P = M g x omega.

    charge_mass M in kg, lever_arm x the horizontal distance (m) from the drum axis to the
    charge's centre of mass, angular_speed omega in rad/s. The charge's weight, offset by x,
    is the torque the drive holds; its sign follows that of x and omega. Broadcasts.
    """
    charge_mass, lever_arm, angular_speed = (
        np.asarray(a, dtype=float) for a in (charge_mass, lever_arm, angular_speed))
    return _scalar_or_array(np.asarray(charge_mass * GRAVITY * lever_arm * angular_speed))


# --------------------------------------------------------------------------- breakage kinetics
def first_order_breakage_rate(times, mass_remaining):
    """First-order specific rate of breakage S (1/s) of a size class and its standard error.

    dm/dt = -S m gives ln(m(t)/m(0)) = -S t; S is fitted by least squares through the origin,
    S = -sum(t y) / sum(t^2) with y = ln(m/m(0)), t = times - times[0] and m(0) = mass_remaining[0]
    (kg, any consistent unit). Points after the first with mass 0 (all broken: log undefined) are
    dropped. The first point defines the origin and is not itself a data point of the fit (it
    would add a zero residual and a spurious degree of freedom): with n usable points in all, the
    n_fit = n - 1 later ones are fitted, and the standard error of the slope through the origin is
    sqrt(sum(residual^2) / (n_fit - 1) / sum(t^2)). With n == 2 one point determines S exactly,
    leaving no degree of freedom: the standard error is then NaN, not 0.
    Raises ValueError if the first mass is <= 0, a mass is negative or NaN, a later time is not
    after times[0], the arrays differ in length, or fewer than 2 usable points remain.
    """
    times = np.asarray(times, dtype=float).ravel()
    mass = np.asarray(mass_remaining, dtype=float).ravel()
    if times.shape != mass.shape:
        raise ValueError(f"first_order_breakage_rate: {times.size} times but {mass.size} masses")
    if mass.size == 0 or not mass[0] > 0.0:
        raise ValueError("first_order_breakage_rate: the first mass must be positive")
    if np.any(~(mass >= 0.0)):
        raise ValueError("first_order_breakage_rate: masses must be non-negative numbers")
    t = times[1:] - times[0]
    if np.any(~(t > 0.0)):
        raise ValueError("first_order_breakage_rate: every later time must be after times[0]")
    keep = mass[1:] > 0.0
    t = t[keep]
    if t.size < 1:
        raise ValueError("first_order_breakage_rate: fewer than 2 usable points (mass > 0)")
    y = np.log(mass[1:][keep] / mass[0])
    stt = float(np.dot(t, t))
    rate = -float(np.dot(t, y)) / stt
    if t.size < 2:
        return rate, float("nan")
    residual = y + rate * t
    return rate, math.sqrt(float(np.dot(residual, residual)) / (t.size - 1) / stt)


# --------------------------------------------------------------------------- sieve analysis
def size_classes(top_size, n_classes, ratio=math.sqrt(2.0)):
    """Sieve sizes (m) of a geometric series descending from top_size: top_size / ratio**k,
    k = 0 ... n_classes, so n_classes + 1 sieves bounding n_classes classes.

    The default ratio sqrt(2) is the usual root-2 sieve series (every second sieve halves the
    size). Raises ValueError unless top_size > 0, n_classes >= 1 and ratio > 1.
    """
    if not top_size > 0.0:
        raise ValueError(f"size_classes: top_size = {top_size} must be positive")
    if int(n_classes) != n_classes or n_classes < 1:
        raise ValueError(f"size_classes: n_classes = {n_classes} must be a whole number >= 1")
    if not ratio > 1.0:
        raise ValueError(f"size_classes: ratio = {ratio} must exceed 1")
    return top_size / float(ratio) ** np.arange(int(n_classes) + 1)


def mass_in_classes(sizes, masses, sieves):
    """Mass (kg) in each class between consecutive sieves, an array of len(sieves) - 1.

    sieves: sizes (m), strictly descending (as size_classes gives them). A particle of size d
    (m) with mass m (kg) is in class k if sieves[k + 1] < d <= sieves[k]: a particle exactly at a
    sieve size is counted in the class that sieve tops (it passes that sieve, is retained on the
    next). Particles larger than sieves[0] or no larger than sieves[-1] are in no class, so the
    classes sum to the total mass only when every size lies in (sieves[-1], sieves[0]].
    """
    sizes, masses = np.broadcast_arrays(np.asarray(sizes, dtype=float).ravel(),
                                        np.asarray(masses, dtype=float).ravel())
    sieves = np.asarray(sieves, dtype=float).ravel()
    if sieves.size < 2 or np.any(np.diff(sieves) >= 0.0):
        raise ValueError("mass_in_classes: sieves must be at least 2 sizes, strictly descending")
    ascending = sieves[::-1]
    # side="left": index j with ascending[j-1] < d <= ascending[j], i.e. sieve j's upper edge
    # includes d; j = 0 (d <= finest sieve) and j = len (d > top sieve) fall outside.
    j = np.searchsorted(ascending, sizes, side="left")
    inside = (j > 0) & (j < sieves.size)
    k = sieves.size - 1 - j[inside]            # back to the descending class index
    return np.bincount(k, weights=masses[inside], minlength=sieves.size - 1).astype(float)


# --------------------------------------------------------------------------- collision energies
def event_spectrum(specific_energies, duration, energy_bins):
    """Collision energy spectrum: (events per second in each bin, events per second with energy
    >= each bin's lower edge), both arrays of len(energy_bins) - 1.

    specific_energies: the specific energy (J/kg) of every collision (or stressing event) seen in
    `duration` seconds (> 0). energy_bins: strictly ascending bin edges (J/kg); bin k holds
    energies e with energy_bins[k] <= e < energy_bins[k + 1]. The cumulative rate counts every
    event at or above the bin's lower edge, including those at or above the top edge, so it is
    non-increasing and cumulative[k] - cumulative[k + 1] is bin k's rate. Energies below the first
    edge appear in neither. This is the input of mechanistic mill models, which multiply it by
    the breakage probability at each energy.
    """
    energies = np.asarray(specific_energies, dtype=float).ravel()
    edges = np.asarray(energy_bins, dtype=float).ravel()
    if not duration > 0.0:
        raise ValueError(f"event_spectrum: duration = {duration} s must be positive")
    if edges.size < 2 or np.any(np.diff(edges) <= 0.0):
        raise ValueError("event_spectrum: energy_bins must be at least 2 edges, strictly ascending")
    if np.any(np.isnan(energies)):
        raise ValueError("event_spectrum: specific energies must not be NaN")
    # Events at or above each edge, from one sort: both outputs follow from the same counts, so
    # the per-bin and the cumulative rates can never disagree.
    at_or_above = energies.size - np.searchsorted(np.sort(energies), edges, side="left")
    per_bin = -np.diff(at_or_above)
    return per_bin / duration, at_or_above[:-1] / duration

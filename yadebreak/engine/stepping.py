"""The time step that follows the finest sphere, and the damping of fresh fragments (when to
read is reads.py's)."""
from __future__ import annotations

import math

from yadebreak.model import placement
from yadebreak.options.table import AttachError
from yadebreak.adapter.yade_api import O, wrapper

def smallest_rayleigh_time():
    """Rayleigh time (s) of the smallest sphere in the scene (None if there is none): one pass
    for the smallest radius of each material, then one Rayleigh time per material."""
    smallest = {}                                  # material id -> (radius, material)
    sphere = wrapper.Sphere
    for b in O.bodies:
        if b is not None and isinstance(b.shape, sphere):
            r, mat = b.shape.radius, b.material
            if mat.id not in smallest or r < smallest[mat.id][0]:
                smallest[mat.id] = (r, mat)
    times = [float(placement.rayleigh_time(r, mat.density, mat.young, mat.poisson))
             for r, mat in smallest.values()]
    return min(times) if times else None


#: a step that follows the loading (TimeStep.follow) grows back towards the rules' step by at
#: most this factor a step: a contact's energy rate changes little over one step of the ~100
#: of an impact, so a doubled step does not outrun the rate it was chosen for
STEP_GROWTH = 2.0
#: ... and falls to no less than this share of the rules' step (a body whose loading asks for
#: less is read late, and the late-read warning says so)
STEP_FLOOR = 1e-3


class TimeStep:
    """O.dt at most time_step_fraction of the Rayleigh time of the smallest sphere present; a
    smaller O.dt is kept. With time_step_fraction=None the user owns O.dt: warn when it exceeds
    20 % of that Rayleigh time (Hertz contacts go unstable near it).

    On a contact law read every step (contacts/laws.py: reads_every_step) reads cannot come
    closer, so O.dt also follows the loading (follow): no body's energy rises by more than
    fast_tolerance of its fracture energy, or half its way to it, in a step, as "fast" reads
    space theirs (judging.steps_allowed). The rules' step (`ruled`: the scene's, lowered for the
    finest fragment) comes back as the loading eases."""

    def __init__(self, fraction, warn):
        self.fraction = fraction
        self.warn = warn                      # warn(cause, message), once per cause
        self.ruled = None                     # the rules' O.dt (s), once follow() has run
        self.chosen = None                    # the O.dt (s) follow() set last

    def at_attach(self, rayleigh_time, user_dt):
        """`user_dt`: O.dt if the user set one before attach, else None."""
        if rayleigh_time is None:
            return
        if not self.fraction:
            self.check(rayleigh_time)
        elif user_dt is None or user_dt > self.fraction * rayleigh_time:
            O.dt = self.fraction * rayleigh_time

    def check(self, rayleigh_time):
        if O.dt > 0.2 * rayleigh_time:
            self.warn("dt", (
                f"O.dt = {O.dt:.3g} s is {100 * O.dt / rayleigh_time:.0f} % of the Rayleigh time "
                f"of the smallest sphere ({rayleigh_time:.3g} s): contacts may go unstable and "
                f"energies be wrong; use time_step_fraction (0.05 recommended) or lower O.dt"))

    def for_fragments(self, radius, material, modulus, fraction=None):
        """The time step fragments of `radius` (m) of a YADE `material` need (inf if O.dt stays
        the user's): time_step_fraction, or the contact law's own `fraction` if smaller, of the
        Rayleigh time with Young's modulus `modulus` (Pa; the law's: contacts/laws.py,
        fragment_time_step)."""
        tr = float(placement.rayleigh_time(radius, material.density, modulus, material.poisson))
        if self.fraction:
            return min(fraction or self.fraction, self.fraction) * tr
        self.check(tr)
        return math.inf

    def lower(self, new_dt, moving):
        """O.dt = new_dt if that is smaller (also the rules' step), the leapfrog kept exact
        (change)."""
        if self.ruled is not None:
            self.ruled = min(self.ruled, new_dt)
        if new_dt < O.dt:
            self.change(new_dt, moving)

    def follow(self, limits, moving):
        """After a read and its breakages: O.dt = the time the loaded bodies allow (`limits`:
        steps of the present O.dt, judging.steps_allowed; none: no body loading towards its
        threshold), within STEP_FLOOR to 1 times the rules' step and at most STEP_GROWTH times
        the present one. An O.dt lowered by someone else meanwhile becomes the rules' step."""
        dt = O.dt
        if self.ruled is None or (self.chosen is not None and dt < self.chosen):
            self.ruled = dt if self.ruled is None else min(self.ruled, dt)
        want = min(self.ruled, STEP_GROWTH * dt)
        if limits:
            want = min(want, dt * min(limits))
        want = max(want, STEP_FLOOR * self.ruled)
        if want != dt:
            self.change(want, moving)
        self.chosen = O.dt

    def to_list(self):
        return [self.ruled, self.chosen]

    def restore(self, saved):
        self.ruled, self.chosen = saved

    @staticmethod
    def change(new_dt, moving):
        """O.dt = new_dt, keeping the leapfrog exact across the change.

        YADE's Newton takes v(n+1/2) = v(n-1/2) + a dt with the new dt; across a change the right
        increment is a (dt_old + dt_new) / 2. Without the a (dt_old - dt_new) / 2 added here, a
        body in mid-contact when a breakage shrinks dt gains energy (1.9 % measured on impacts of
        5.5 mm copper ore at 100 J/kg when dt fell 19-fold). Likewise the spin: the angular
        momentum where Newton integrates it (aspherical bodies), else the angular velocity. Done
        for the bodies in tracked contacts (`moving()`, asked only when dt changes), the only
        ones with a large acceleration that yadebreak knows of."""
        old = O.dt
        newton = next((e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator)), None)
        gravity = newton.gravity if newton is not None else None
        half = 0.5 * (old - new_dt)
        exact = newton is not None and newton.exactAsphericalRot
        bodies, force_of, torque_of = O.bodies, O.forces.f, O.forces.t
        for bid in moving():
            b = bodies[bid]
            if b is None or not b.dynamic:
                continue
            state = b.state
            accel = force_of(bid) / state.mass
            if gravity is not None:
                accel = accel + gravity
            state.vel = state.vel + accel * half
            if not b.aspherical:                       # a sphere: isotropic inertia
                state.angVel = state.angVel + torque_of(bid) * (half / state.inertia[0])
            elif exact:                                # Newton integrates the angular momentum
                state.angMom = state.angMom + torque_of(bid) * half
            else:
                torque, inertia = torque_of(bid), state.inertia
                state.angVel = state.angVel + type(torque)(
                    *(torque[k] / inertia[k] * half for k in range(3)))
        O.dt = new_dt


class FragmentDamping:
    """The paper's global damping: fragments only, from their creation, for global_damping_time
    seconds (None: as long as they exist). Each material has its strength (its file's
    global_damping, or attach's global_damping for all).

    It is YADE's Newton (Cundall) damping, switched on for fragments only through
    state.isDamped: on a damped body each component of the force (and torque) is reduced by the
    strength times its magnitude when it speeds the body up and increased likewise when it slows
    it down, i.e. a force of `strength` times the force on the body, always against the body's
    motion (the EDEM manual's "percentage of total contact force upon the particle"). It is never
    on the parent or any body that existed at attach, so the contacts that stress an intact
    particle (the impact, Eqs. 1-6) are untouched; it only takes kinetic energy from fragments
    (its power -strength sum |F_i v_i| <= 0), in C++ every step at no cost in Python. Newton has
    one damping value per scene: materials with different non-zero strengths in one scene are
    refused (attach's global_damping sets one for all). docs/high_energy.md, "Global damping"."""

    def __init__(self, strengths, duration):
        """strengths: material label -> strength in [0, 1); duration: s, or None (for the
        fragment's life)."""
        self.duration = duration
        nonzero = sorted({v for v in strengths.values() if v > 0.0})
        if len(nonzero) > 1:
            raise AttachError(
                f"global_damping: the materials' files give {nonzero} (by label: "
                f"{dict(strengths)}) but YADE's Newton damping is one value per scene: pass "
                f"global_damping (in [0, 1)) to attach() for all")
        self.strength = nonzero[0] if nonzero else 0.0
        self.damped_labels = {lab for lab, v in strengths.items() if v > 0.0}
        self.until = []                       # [time (s), [ids]]

    def apply_at_attach(self):
        """Newton's damping set to the strength, and taken off every body present."""
        if self.strength <= 0.0:
            return
        newton = next((e for e in O.engines if isinstance(e, wrapper.NewtonIntegrator)), None)
        if newton is None:
            raise AttachError(f"global_damping = {self.strength:g}: the scene has no "
                              f"NewtonIntegrator to apply it; add one or set global_damping=0")
        newton.damping = self.strength
        for b in O.bodies:
            if b is not None:
                b.state.isDamped = False

    def add(self, ids):
        if self.strength > 0.0 and self.duration is not None:
            self.until.append((O.time + self.duration, list(ids)))

    def release(self):
        if not self.until:
            return
        now = O.time
        keep = []
        for until, ids in self.until:
            if now >= until:
                for i in ids:
                    b = O.bodies[i] if i < len(O.bodies) else None
                    if b is not None:
                        b.state.isDamped = False
            else:
                keep.append((until, ids))
        self.until = keep

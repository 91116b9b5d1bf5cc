"""Rolling friction per contact pair on YADE's Hertz-Mindlin law (docs/model.md, "Rolling friction").

YADE's Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True) resists the relative rotation of two
bodies with an elastic-plastic moment: it grows by kr times the relative rolling rotation and is
capped at maxBendPl |F_n| (N m). Its Ip2 gives every contact the same kr and maxBendPl = eta
(R_1 + R_2) / 2, one eta for all material pairs (no MatchMaker in YADE 2023.02), and the mean
radius makes a particle against the 88 mm ball eight times too stiff in rolling. So the Ip2 gives
kr = 0 (no moment) and RollingFriction gives each contact, once seen, its pair's values:

    maxBendPl = mu_r(pair) R_roll,     R_roll = the smaller sphere's radius (a wall's or facet's
                                       partner: that sphere's radius)
    kr        = STIFFNESS I_min / dt^2 (I_min: the smaller moment of inertia of the pair's spheres)

so that a rolling sphere feels the constant moment mu_r F_n R of the paper's code (EDEM's
constant directional torque) once kr has built it, within a few steps. kr stays below the limit
of stable rotation, 2 I_min / dt^2, also when the time step falls for finer fragments.

Which contacts are new is found without a pass over every interaction: each check compares every
body's count of real interactions (YADE's numIntrsOfEachBody, in C++) with the count at the last
check and looks only at the bodies whose count changed (withBody). A contact that replaces another
of the same body between two checks leaves the count alone; a full pass every FULL_PASS checks
finds those. Checks run every `period` steps; a new contact has no rolling moment until the
next check (at most period - 1 steps: its rolling moment then builds from there).
"""
from __future__ import annotations

from yadebreak.adapter.yade_api import O, utils, wrapper
from yadebreak.engine.parts import protocol

#: kr = STIFFNESS I_min / dt^2: stable (rotation frequency sqrt(2 kr / I_min) well below 2 / dt),
#: and the cap mu_r F_n R is reached within a few steps of rolling
STIFFNESS = 0.1
#: a pass over every interaction every FULL_PASS checks, for contacts that replaced another
FULL_PASS = 200
DEFAULT_PERIOD = 10


class RollingFriction(protocol.Part):
    """Gives each new real interaction its pair's rolling friction (maxBendPl, kr), after
    Newton's step every `period` steps.

    mu: {(YADE material id a, id b) with a <= b: rolling friction coefficient (-)}; pairs not in
    it (or with 0) get no rolling moment."""

    kind = "rolling"
    hook = protocol.AFTER_NEWTON

    def __init__(self, mu, period=DEFAULT_PERIOD, label="rolling"):
        super().__init__(label, period)
        self.mu = {(min(a, b), max(a, b)): float(v) for (a, b), v in mu.items()}
        self._seen = []                    # each body's count of real interactions at the check
        self._checks = 0
        self.configured = 0                # contacts given their values so far

    def act(self):
        counts = utils.numIntrsOfEachBody()
        self._checks += 1
        if self._checks % FULL_PASS == 1:             # the first check too (a loaded scene)
            self._configure(O.interactions)
        elif counts != self._seen:
            seen = self._seen
            changed = [i for i, c in enumerate(counts) if i >= len(seen) or c != seen[i]]
            bodies = O.bodies
            for bid in changed:
                if bodies[bid] is not None:           # (an erased body's count falls to 0)
                    self._configure(O.interactions.withBody(bid))
        self._seen = counts

    def _configure(self, interactions):
        dt = O.dt
        for inter in interactions:
            phys = inter.phys
            if not inter.isReal or not isinstance(phys, wrapper.MindlinPhys) or phys.kr != 0.0:
                continue
            b1, b2 = O.bodies[inter.id1], O.bodies[inter.id2]
            m1, m2 = b1.material.id, b2.material.id
            mu = self.mu.get((min(m1, m2), max(m1, m2)), 0.0)
            if mu <= 0.0:
                continue                   # kr stays 0: no moment (maxBendPl 0 would not cap it)
            geom = inter.geom
            radius = min(r for r in (geom.refR1, geom.refR2) if r > 0.0)
            inertia = min(b.state.inertia[0] for b in (b1, b2)
                          if isinstance(b.shape, wrapper.Sphere) and b.state.inertia[0] > 0.0)
            phys.maxBendPl = mu * radius
            phys.kr = STIFFNESS * inertia / dt**2
            self.configured += 1

    def to_state(self, folder=None):
        """The settings and where the checks are (which check passes over every interaction,
        the counts the next check compares with): a loaded scene configures the contacts at the
        same steps as the saved one would have."""
        return {"mu": [[a, b, v] for (a, b), v in self.mu.items()],
                "checks": self._checks, "seen": list(self._seen)}

    @classmethod
    def from_state(cls, label, period, state):
        part = cls({(a, b): v for a, b, v in state["mu"]}, period, label)
        part._checks = state.get("checks", 0)
        part._seen = list(state.get("seen", ()))
        return part


def install_rolling(mu, engines=None, period=DEFAULT_PERIOD, label="rolling"):
    """Rolling friction `mu` ({(material id, id): mu_r}) applied every `period` steps after
    Newton's step, in `engines` (a list about to be O.engines; None: O.engines); its settings
    travel in O.tags, so that a saved scene finds them again. Returns the engines."""
    return protocol.install(RollingFriction(mu, period, label), engines)


def on_step(label):
    """The entry point that scenes saved by earlier versions name in their PyRunner commands."""
    protocol.run(RollingFriction.kind, label)


def share_pairs(parent, alias):
    """Material `alias` (a copy of `parent`, e.g. the dummies' softer one) gets `parent`'s
    rolling friction in every part of this scene, and in the settings stored with it."""
    for part in protocol.live(RollingFriction.kind).values():
        for (a, b), mu in list(part.mu.items()):
            if parent in (a, b):
                other = b if a == parent else a
                for pair in ((alias, other),) + (((alias, alias),) if other == parent else ()):
                    part.mu[(min(pair), max(pair))] = mu
        protocol.save_state(part)

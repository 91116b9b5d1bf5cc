"""YADE's Hertz-Mindlin law (Law2_ScGeom_MindlinPhys_Mindlin) as the reader reads it: spheres,
and polyhedra through ScGeom. Its physics is law.py's (Eqs. 15-16); here is what the reader and
the replacer ask of a law (laws.py lists them): how a read goes, the energy a row holds, the
elastic energy of a parent's contacts. Duck-typed on YADE's objects; no yade import."""
from __future__ import annotations

from yadebreak.engine.contacts.each import read_each
from yadebreak.engine.contacts.law import HertzMindlinWork
from yadebreak.engine.contacts.table import OVERLAP


def contact_elastic_energy(inter, zeroed):
    """Elastic energy (J) a Hertz-Mindlin contact holds: 0.4 kno0 (d - d0)^2.5 in the normal
    direction (Fn = kno0 (d - d0)^1.5, d0 its zeroed overlap, if any; none while the zeroing
    holds it slack, kno = 0) plus |Fs|^2 / (2 ks) of the elastic shear force (the law's
    shearForce adds the viscous part)."""
    phys, d = inter.phys, inter.geom.penetrationDepth
    kno0, d0 = (zeroed.kno0, zeroed.artificial) if zeroed is not None else (phys.kno, 0.0)
    if phys.kno == 0.0:
        kno0 = 0.0                    # a slack zeroed pair (asleep too): it makes no force
    energy = 0.4 * kno0 * max(d - d0, 0.0) ** 2.5
    if phys.ks > 0.0:
        energy += 0.5 * phys.shearElastic.squaredNorm() / phys.ks
    return energy


class HertzMindlin:
    """The reader's view of Law2_ScGeom_MindlinPhys_Mindlin: any read schedule; a read goes
    contact by contact for a few contacts, with numpy for many (reader.py's measurements)."""

    name = "hertz_mindlin"
    yade_law = "Law2_ScGeom_MindlinPhys_Mindlin"
    #: the reads may be sparse: law.py integrates between them
    reads_every_step = False
    #: no warning of YADE's to count on this law
    pair_checks = None
    #: the engine sets O.dt from the Rayleigh time of the smallest breakable body
    time_step_advice = None

    def inherited(self, pairs, zeroed):
        """Fresh fragments overlap as `pairs`: the zeroing (engine/zeroing.py) holds a sphere
        fragment's overlaps; nothing of the law's own (ContactReader.inherit)."""

    def settle(self, scene):
        """Nothing to correct after the InteractionLoop."""

    def to_dict(self):
        return {}

    def restore(self, data):
        pass

    def problems(self, reading):
        """What in the read options (config.Reading) this law cannot honour: none."""
        return None

    @staticmethod
    def fragment_time_step(time_step, radius, material):
        """The time step (s) fragments of `radius` (m) in a YADE `material` need: time_step_
        fraction of their Rayleigh time (stepping.TimeStep)."""
        return time_step.for_fragments(radius, material, material.young)

    def young_is_stiffness(self, material):
        """Whether a YADE material's `young` is the law's own stiffness rather than a Young's
        modulus: never here (Eq. 4's shares take Y / (1 - nu^2))."""
        return False

    def read(self, reader, interactions, bodies, tracked, zeroed, now, interval, asleep, counts,
             zeroing_changes):
        """One read (ContactReader.read): contact by contact while the rows are at most
        reader.small or the counts are not given, else with numpy."""
        if counts is None or len(reader.table) <= reader.small:
            loading = read_each(reader, interactions.all(True), bodies, tracked, zeroed, now,
                                interval, asleep)
            reader.arrays.zeroed_rows.forget()    # it does not follow the zeroing's changes
            return loading
        return reader.arrays(interactions, bodies, tracked, zeroed, now, interval, asleep,
                             counts, zeroing_changes)

    @staticmethod
    def held(table, row, physs):
        """Elastic energy (J) contact `row` holds now: 0.4 kno delta^2.5 while it overlaps."""
        overlap = table.value(row, OVERLAP)
        return HertzMindlinWork.stored(physs[row].kno, overlap) if overlap > 0.0 else 0.0

    @staticmethod
    def neighbour_energy(reader, body, interactions, zeroed_pairs, each=None):
        """The neighbours (ids) of `body` over `interactions` (YADE's, with it) and the elastic
        energy (J) of those contacts (contact_elastic_energy, zeroed overlaps off); `each` (a
        dict), if given, receives each neighbour's."""
        found, energy = [], 0.0
        for inter in interactions:
            other = inter.id2 if inter.id1 == body else inter.id1
            found.append(other)
            held = contact_elastic_energy(inter, zeroed_pairs.get((min(body, other),
                                                                   max(body, other))))
            energy += held
            if each is not None:
                each[other] = held
        return found, energy

"""Materials in the scene: YADE FrictMats and the Hertz-Mindlin Ip2 from material files, and the
mapping from YADE's material labels to yadebreak's Materials."""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

from yadebreak import model
from yadebreak.model.intervals import DENSITY, POISSON_RATIO, YOUNG_MODULUS, Interval
from yadebreak.model.materials import Material, MaterialError
from yadebreak.criteria import load_material
from yadebreak.adapter.yade_api import O, extend_match_makers, wrapper
from yadebreak.options.table import AttachError
from yadebreak.criteria import criterion_for
from yadebreak.engine.parts.rolling import share_pairs as share_rolling_pairs
from yadebreak.engine.shapes import SHAPES, shape_of
from yadebreak.engine.state import Breakable


def _frict_material(mat: Material, label: str, stiffness_scale: float = 1.0, kind="FrictMat"):
    contact = mat.contacts.get("self") or next(iter(mat.contacts.values()), None)
    friction = contact.friction if contact else 0.5
    return getattr(wrapper, kind)(young=mat.young_modulus * stiffness_scale, poisson=mat.poisson_ratio,
                            density=mat.density, frictionAngle=math.atan(friction), label=label)


#: what YADE's time step and the engine read of every YADE material: (attribute, range, unit)
_PHYSICAL = (("young", YOUNG_MODULUS, "Pa"), ("poisson", POISSON_RATIO, "-"),
             ("density", DENSITY, "kg/m3"))


def check_physical(mat, what, fields=_PHYSICAL):
    """Raise AttachError, one line, if YADE material `mat` (any with these attributes) has a
    Young's modulus, Poisson's ratio or density outside its physical range (intervals.py);
    `what` names it. Checked before a run: such values overflow the time step midway."""
    for field, interval, unit in fields:
        value = getattr(mat, field, None)
        if value is not None and float(value) not in interval:
            shown = "" if unit == "-" else f" {unit}"
            raise AttachError(f"{what}: {field} = {value:g}{shown} is out of range: accepted "
                              f"{interval}{shown}")


def as_material(name):
    """`name` if it is a Material, else the material it names (a name or a .toml path), loaded
    here, at attach's edge; a file that does not load is an AttachError (one message)."""
    try:
        return name if isinstance(name, Material) else load_material(name)
    except MaterialError as exc:
        raise AttachError(str(exc)) from None


def add_materials(labels, stiffness_scale=1.0, kinds=None):
    """Create one YADE FrictMat per label from material files and return the Hertz-Mindlin
    Ip2 functor with restitution and friction per pair (paper Table 6) through MatchMaker.

    labels: {"ore": "copper_ore", "steel": "steel"}. stiffness_scale multiplies every Young's
    modulus, which keeps the ratios of Eq. 4. kinds: {label: YADE material class name} for labels
    that are not FrictMat (a "PolyhedraMat", a FrictMat subclass, for polyhedra: the same Ip2
    serves them). Returns (ip2, {label: Material}).
    """
    mats, ids = {}, {}
    for label, name in labels.items():
        mats[label] = as_material(name)
        frict = _frict_material(mats[label], label, stiffness_scale,
                                (kinds or {}).get(label, "FrictMat"))
        check_physical(frict, f"material '{label}' ({mats[label].source}) with stiffness_scale = "
                              f"{stiffness_scale:g}")
        ids[label] = O.materials.append(frict)
    en, es, fr = [], [], []
    for la in labels:
        for lb in labels:
            if ids[la] > ids[lb]:
                continue
            try:
                c = mats[la].contact_with(mats[lb])
            except KeyError as exc:
                raise AttachError(str(exc.args[0])) from None
            en.append((ids[la], ids[lb], c.restitution))
            es.append((ids[la], ids[lb], c.restitution))
            fr.append((ids[la], ids[lb], math.atan(c.friction)))
    ip2 = wrapper.Ip2_FrictMat_FrictMat_MindlinPhys(
        en=wrapper.MatchMaker(matches=en), es=wrapper.MatchMaker(matches=es),
        frictAngle=wrapper.MatchMaker(matches=fr))
    return ip2, mats


def rolling_friction(labels, overrides=None):
    """The rolling friction of each pair of the scene's labelled materials (paper Table 6), from
    their material files, `overrides` {(label, label): mu_r} replacing some. Call after
    add_materials(labels). Returns ({(YADE material id, id): mu_r}, {"la-lb": mu_r} for reports)."""
    overrides = {tuple(sorted(k)): float(v) for k, v in (overrides or {}).items()}
    ids = {m.label: m.id for m in O.materials}
    mats = {label: as_material(name) for label, name in labels.items()}
    by_ids, named = {}, {}
    for la in labels:
        for lb in labels:
            if ids[la] > ids[lb]:
                continue
            pair = tuple(sorted((la, lb)))
            mu = (overrides[pair] if pair in overrides
                  else mats[la].contact_with(mats[lb]).rolling_friction)
            by_ids[(ids[la], ids[lb])] = mu
            named[f"{la}-{lb}"] = mu
    return by_ids, named


#: label of the YADE material of a breakable material's dummy spheres: "<label>_dummy"
DUMMY_SUFFIX = "_dummy"


def dummy_materials(labels, factor, loop):
    """{breakable label: the YADE material of its dummy spheres} when `factor` < 1: a copy of the
    label's material with its Young's modulus times `factor`, labelled "<label>_dummy", made once
    per scene (a loaded scene has it already). The paper: the dummies "represent the fines, they
    can also be considered to be more deformable ... hence a lower value of stiffness may be
    used". Every pair table keyed by material ids gives it its parent's rows (the Ip2's
    MatchMakers in `loop`, the InteractionLoop; the rolling friction parts), so that a dummy
    differs from its parent in stiffness only. factor 1: {} (dummies keep the parent's)."""
    if factor == 1.0:
        return {}
    by_label = {m.label: m for m in O.materials}
    out = {}
    for label in labels:
        mat = by_label.get(label + DUMMY_SUFFIX)
        if mat is None:
            parent = by_label[label]
            mat = type(parent)(**{k: v for k, v in parent.dict().items() if k not in ("id", "label")})
            mat.young = parent.young * factor
            mat.label = label + DUMMY_SUFFIX
            check_physical(mat, f"dummy_stiffness = {factor:g} of material '{label}'")
            O.materials.append(mat)
            _share_pairs(loop, parent.id, mat.id)
            share_rolling_pairs(parent.id, mat.id)
        out[label] = mat
    return out


def _aliased(rows, parent, alias):
    """The rows (a, b, value) of a pair table that a material `alias` of `parent` adds."""
    new = []
    for a, b, value in rows:
        a, b = int(a), int(b)
        if a == parent and b == parent:
            new += [(alias, parent, value), (alias, alias, value)]
        elif parent in (a, b):
            new.append((alias, b if a == parent else a, value))
    return new


def _share_pairs(loop, parent, alias):
    """Each per-pair value of the loop's Ip2 functors (their MatchMakers) gets `alias` rows
    copied from `parent`'s."""
    extend_match_makers(loop, lambda rows: _aliased(rows, parent, alias))


@dataclasses.dataclass
class SceneMaterials:
    """The breakable materials by YADE label, and what the engine needs of every YADE material."""

    by_label: dict          # YADE label -> Material (breakable)
    label_by_id: dict       # YADE material id -> label, for breakable materials
    stiffness_by_id: dict   # YADE material id -> the stiffness of Eq. 4's shares: Hertz's
    #                         Y / (1 - nu^2) (Pa; inf if rigid), or the law's own (the
    #                         volumetric law's kn, N/m3: PolyhedraMat.young)
    dummy_by_label: dict    # breakable label -> YADE material of its softer dummies (if made)
    law: object             # the contact law the engine reads (a contacts.laws instance)


def check_mapping(materials):
    """attach(materials=...) checked against the scene before it changes: a {YADE material label:
    material name, path or Material} whose labels the scene has and whose materials are
    breakable. Returns {label: Material}."""
    if not isinstance(materials, Mapping) or not all(isinstance(k, str) for k in materials):
        raise AttachError(f"materials = {materials!r}: accepted a dict {{YADE material label: "
                          "material name, .toml path or Material}, e.g. {'ore': 'copper_ore'}")
    labels = {m.label for m in O.materials}
    unknown = [lab for lab in materials if lab not in labels]
    if unknown:
        raise AttachError(
            f"unknown YADE material label(s) {unknown}: the scene has "
            f"{sorted(l for l in labels if l) or 'no labelled materials'}; give each breakable "
            f"material a label (FrictMat(..., label='ore')) and map it in attach(materials=...)")
    found = {}
    for lab, name in materials.items():
        mat = as_material(name)
        if not mat.breakable:
            raise AttachError(f"material '{mat.name}' (label '{lab}') is not breakable: map only "
                              "breakable materials in attach(materials=...)")
        found[lab] = mat
    return found


#: a material whose `young` is its law's own stiffness (the volumetric law's kn, N/m3), not a
#: Young's modulus
_OWN_STIFFNESS = (("young", Interval(0.0, math.inf, lo_open=True, hi_open=True), "N/m3"),
               *_PHYSICAL[1:])


def resolve(materials, law, kappa=None, emax_ratio=None):
    """Map the checked {label: Material} (check_mapping) onto the scene's labelled YADE
    materials, with the options that override the files (Tavares materials only). `law`: the
    contact law the engine reads (scene.contact_law, a contacts.laws instance). A `kappa` that
    is a word ('batch') is the criterion's to apply (recording.criterion_for), not a number to
    write into the file."""
    kappa = None if isinstance(kappa, str) else kappa
    by_label = {lab: criterion_for(mat).overridden(kappa=kappa, emax_ratio=emax_ratio)
                for lab, mat in materials.items()}
    stiffness, label_by_id = {}, {}
    for m in O.materials:
        kn = law.young_is_stiffness(m)
        check_physical(m, f"YADE material {m.label or m.id!r}",
                       _OWN_STIFFNESS if kn else _PHYSICAL)
        young = getattr(m, "young", None)
        stiffness[m.id] = (math.inf if young is None else float(young) if kn
                           else float(model.hertz_stiffness(young, getattr(m, "poisson", 0.0))))
        if m.label in by_label:
            label_by_id[m.id] = m.label
    cut = len(DUMMY_SUFFIX)
    dummies = {m.label[:-cut]: m for m in O.materials
               if m.label.endswith(DUMMY_SUFFIX) and m.label[:-cut] in by_label}
    return SceneMaterials(by_label, label_by_id, stiffness, dummies, law)


def breakable_bodies(label_by_id):
    """state.Breakable records of the scene's bodies with a breakable material (attach only:
    a pass over every body): loose bodies of a shape that can break (engine/shapes/), whose
    `radius` is half their size (Shape.size: Eq. 3's and the t10 sieves'). Anything else with
    such a material is an error."""
    found, problems = [], []
    for b in O.bodies:
        label = label_by_id.get(b.material.id if b is not None and b.material is not None
                                else None)
        if label is None:
            continue
        shape = shape_of(b)
        if shape is None:
            names = " and ".join(s.plural for s in SHAPES.values())
            problems.append(f"body {b.id} ({type(b.shape).__name__}) has the breakable material "
                            f"'{label}' but only {names} can break: give it another material")
        elif b.isClumpMember or b.isClump:
            problems.append(f"body {b.id} is part of a clump and has the breakable material "
                            f"'{label}': clumps cannot break; use loose bodies")
        else:
            found.append(Breakable(b.id, label, b.state.mass, 0.5 * shape.size(b)))
    if problems:
        raise AttachError("; ".join(problems))
    return found

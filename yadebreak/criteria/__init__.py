"""Breakage criteria: when a body breaks and what it leaves. One class per criterion, owning its
[breakage] keys and parameters, its per-body columns, its model side (the fracture-energy
distribution, t10) and its engine side (judge, unload, breakage); base.py states what a
criterion answers, registry.py lists the criteria and reads material files with them.

    tavares.Tavares     the Tavares UFRJ model (Eqs. 1-8), breakage.model = "tavares"
    ab_t10.AbT10        Rocky's Ab-T10 (Eqs. 9.1-9.4), breakage.model = "ab_t10"
    recording.Recording attach(breakage=False): any criterion, logging events, never breaking

Adding a criterion is one module here and one line of registry.CRITERIA.
"""
from yadebreak.criteria.base import Criterion
from yadebreak.criteria.judgement import Judgement, judge_all
from yadebreak.criteria.tavares import Tavares
from yadebreak.criteria.ab_t10 import AbT10
from yadebreak.criteria.recording import Recording, criterion_for
from yadebreak.criteria.registry import CRITERIA, criterion_class, load_material, parse_material

__all__ = ["Criterion", "CRITERIA", "criterion_class", "criterion_for", "load_material",
           "parse_material", "Judgement", "judge_all", "Tavares", "AbT10", "Recording"]

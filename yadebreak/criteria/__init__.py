"""Breakage criteria: when a body breaks and what it leaves. One class per criterion, holding its
model side (the fracture-energy distribution, t10) and its engine side (judge, unload,
breakage); base.py states what a criterion answers and keeps the registry.

    tavares.Tavares     the Tavares UFRJ model (Eqs. 1-8), breakage.model = "tavares"
    ab_t10.AbT10        Rocky's Ab-T10 (Eqs. 9.1-9.4), breakage.model = "ab_t10"
    recording.Recording attach(breakage=False): any criterion, logging events, never breaking

Adding a criterion is one file here: a Criterion subclass decorated with base.register, imported
below (which registers it; `import yadebreak` imports this package).
"""
from yadebreak.criteria.base import Criterion, criterion_class, register
from yadebreak.criteria.judgement import Judgement, judge_all
from yadebreak.criteria.tavares import Tavares
from yadebreak.criteria.ab_t10 import AbT10
from yadebreak.criteria.recording import Recording, criterion_for

__all__ = ["Criterion", "register", "criterion_class", "criterion_for", "Judgement", "judge_all",
           "Tavares", "AbT10", "Recording"]

"""Mechanistic mill model: minutes of batch grinding from seconds of collision spectra.

The model layer of `python3 -m yadebreak grind` (docs/grinding.md); never imports yade. One job
per module:

- classes: the root-2 size classes and the feed.
- spectra: the spectra file (format, reader with validation, writer), the converter from a mill
  run's outputs, spectra synthesised from a documented rule.
- capture: the mass a collision captures (monolayer) and the energy each captured particle gets.
- population: the state (a discretised fracture-energy distribution per class, fines) and its
  time integration with damage (Eqs. 5-6), t10 (Eq. 8) and progeny (Eq. 10), BatchGrinder.
- grid: the fracture-energy cells of each class and Eq. 6's weakening tabulated (FractureGrid,
  DamageTable).
- progeny: where broken mass goes: t10 (Eqs. 8-9) and Eq. 10 over the classes (Progeny).
- reference: closed forms the integration is tested against (Reid's solution).
"""
from yadebreak.studies.grinding.classes import SizeClasses, feed_masses, read_psd_csv, root2_classes
from yadebreak.model.spectra import (Spectra, SpectraError, from_mill_run, read_spectra,
                                              synthetic_spectra, write_spectra)
from yadebreak.model.capture import CaptureModel
from yadebreak.studies.grinding.population import BatchGrinder, GrindingError, GrindResult
from yadebreak.studies.grinding.reference import reid_batch

__all__ = ["SizeClasses", "feed_masses", "read_psd_csv", "root2_classes", "Spectra",
           "SpectraError", "from_mill_run", "read_spectra", "synthetic_spectra", "write_spectra",
           "CaptureModel", "BatchGrinder", "GrindingError", "GrindResult", "reid_batch"]

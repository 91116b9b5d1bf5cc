"""Calibration: material parameters from laboratory data, with standard errors and 95 % intervals
(docs/calibration.md). `python3 -m yadebreak fit` is its command line.

- data: the CSV files and their checks (DataError names file, line and column);
- mle: maximum likelihood, observed information, profile-likelihood intervals;
- fracture (Eqs. 1-3), t10 (Eq. 7; Ab-T10's M), damage (gamma, Eqs. 5-6), progeny (Eq. 10),
  ab_t10 (Eqs. 9.1-9.3): one fit each;
- fit: all of them from one data set, and the bootstrap; outputs, plots: what is written;
- examples: synthetic data drawn from a material.
Model layer: never imports yade.
"""
from yadebreak.studies.calibration.data import DataError, read_table, read_tables
from yadebreak.studies.calibration.fit import Calibration, bootstrap, fit_all
from yadebreak.studies.calibration.mle import Estimate, FitError

__all__ = ["DataError", "FitError", "Estimate", "Calibration", "read_table", "read_tables",
           "fit_all", "bootstrap"]

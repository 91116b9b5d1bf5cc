"""Tools beside the engine, in plain Python (they never import yade; sweeps and trade-offs start
YADE as separate processes).

options      the scripts' options: declared once with type, range, unit and help
lifecycle    how a script's run ends: exit codes, signals, the lock on --out, checkpoints,
             partial results, finish markers, progress lines (scenes and runs use it)
sweep        yade-batch tables on Dask, from a laptop to a cluster
tradeoff     speed against accuracy on any scene, with error bars over seeds
calibration  material files from a user's laboratory data (python3 -m yadebreak fit)
grinding     minutes of grinding from a mill's collision spectra (python3 -m yadebreak grind)
"""

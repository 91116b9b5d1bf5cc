"""The jobs behind the scripts (YADE layer): each builds its scene (yadebreak.scenes), attaches
the engine (yadebreak.coupling), runs with progress and checkpoints, and writes its outputs.

bed          ball on a bed of particles (scripts/bed_impact.py)
mill         the laboratory batch ball mill (scripts/ball_mill.py)
agglomerate  a bonded agglomerate on a plane (scripts/agglomerate_impact.py)
extremes     the stability matrix (scripts/extremes.py)
paraview     ParaView time series of a running scene
"""

"""The jobs behind the scripts (YADE layer): each builds its scene (yadebreak.scenes), attaches
the engine (yadebreak.engine), and supplies its measurements and outputs to the one skeleton
that runs every job (start or resume, progress, checkpoints, stop-after, partial outputs on
failure, end reason, finish marker).

skeleton     the run skeleton: a Job's hooks, run(job); run_units for independent energies
             (how a run ends, whatever the job, is yadebreak.jobs.lifecycle's)
job_options  every script's options, declared once (no yade: tests read them in-process)
bed          ball on a bed of particles (scripts/bed_impact.py)
mill         the laboratory batch ball mill (scripts/ball_mill.py)
agglomerate  a bonded agglomerate on a plane (scripts/agglomerate_impact.py)
impacts      single and repeated impacts, drop-weight tests (scripts/single_impact.py,
             repeated_impact.py, drop_weight.py)
extremes     the stability matrix (scripts/extremes.py)
paraview     ParaView time series of a running scene

A new job: a skeleton.Job subclass here, its options in job_options.JOBS (a JobOptions: its own,
the attach() options it exposes, its overrides of their defaults with the reasons), and a script
of its options and one call (scripts/bed_impact.py is one).
"""

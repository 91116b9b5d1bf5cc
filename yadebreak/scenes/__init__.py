"""Builders of YADE scenes (YADE layer): each returns the attached engine and what the job
needs to measure. A new scene goes here; the job that runs it goes in yadebreak.jobs.

impacts     particles shot at a target, repeated impacts, the drop weight; the shared engines
queue       impact scenes as Dask tasks on any --scheduler (no yade import here)
beds        a ball on a bed of particles (lattice or poured)
poured_bed  beds poured and settled under gravity, and their cache
mill        the laboratory ball mill: drum, lifters, charge; its torque and charge state
agglomerate a bonded agglomerate dropped on a plane, its checkpoints
extremes    the stability matrix's pairs fired at each other and facet corners
view        what a job reads of the running scene and asks of the YADE process
"""
from yadebreak.scenes.beds import (BALL_DIAMETER, BALL_MASS, bed_impact_scene,  # noqa: F401
                   hex_bed_positions, hold_release)
from yadebreak.scenes.impacts import (drop_weight_scene, drop_weight_spec, hertz_engines,  # noqa: F401
                      impact_again, impact_scene, impact_spec, run_drop_weight, run_scenes,
                      on_workers, run_until_rebound, scene_counts, scene_seed, single_impacts)
from yadebreak.scenes.queue import SceneQueue  # noqa: F401

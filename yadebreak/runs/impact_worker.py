"""One worker of scenes.single_impacts(..., jobs=N), run by it as a YADE script:

    yade -n -x impact_worker.py FOLDER WORKER JOBS

runs the scenes WORKER, WORKER + JOBS, WORKER + 2 JOBS, ... of FOLDER/spec.json, appends their
events (with their scene) to FOLDER/WORKER.jsonl and keeps its tally in FOLDER/WORKER.tally.json,
rewritten after every scene (the parent reads it for progress lines and merges it at the end).
Coupling layer: imports yade.
"""
import json
import os
import signal
import sys
from pathlib import Path

# Ctrl-C reaches the whole process group: the parent stops the workers itself (and they die with
# it if it is killed: scenes._in_workers)
signal.signal(signal.SIGINT, signal.SIG_IGN)

folder, worker, jobs = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
spec = json.loads((folder / "spec.json").read_text())
sys.path.insert(0, spec["package"])             # the parent's yadebreak, wherever it lives

from yadebreak import scenes  # noqa: E402


def keep(done, total, tally):
    tmp = folder / f"{worker}.tally.tmp"
    tmp.write_text(json.dumps(tally.to_dict()))
    os.replace(tmp, folder / f"{worker}.tally.json")


try:
    scenes.run_scenes(spec, range(worker, len(spec["counts"]), jobs), folder / f"{worker}.jsonl",
                      on_scene=keep)
except BaseException:                            # the parent shows this and stops the others
    import traceback
    traceback.print_exc()
    sys.stderr.flush()
    os._exit(1)
os._exit(0)          # past YADE's own teardown (threads of its prompt servers)

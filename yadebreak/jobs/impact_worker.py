"""One worker of an impact pool (scenes/impact_pool.py), started by it as a YADE script:

    yade -n -x impact_worker.py POOL WORKER PACKAGE

takes scenes from POOL's queue until POOL/stop appears: for each, {"set": SET, "scene": k}, it
runs scene k of SET/spec.json (scenes.run_scenes), its events to SET/k.jsonl, then its tally to
SET/k.tally.json (the parent's sign that the scene is done); a spec with a "task"
("module:function") calls function(spec, k) instead and writes what it returns there.
PACKAGE is the parent's yadebreak, wherever it lives. Coupling layer: imports yade.
"""
import json
import os
import signal
import sys
import time
from pathlib import Path

# Ctrl-C reaches the whole process group: the parent stops the workers itself (and they die with
# it if it is killed: impact_pool.ImpactPool._start)
signal.signal(signal.SIGINT, signal.SIG_IGN)

pool, worker, package = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
sys.path.insert(0, package)

from yadebreak import scenes  # noqa: E402
from yadebreak.scenes.view import close_remote_access  # noqa: E402
from yadebreak.scenes.impact_pool import call_task, claim  # noqa: E402

#: how often an idle worker looks at the queue (s)
IDLE_S = 0.05


def run_one(task):
    folder, k = Path(task["set"]), int(task["scene"])
    spec = json.loads((folder / "spec.json").read_text())
    if "task" in spec:
        done = call_task(spec, k)
    else:
        done = scenes.run_scenes(spec, [k], folder / f"{k}.jsonl")[0].to_dict()
    tmp = folder / f"{k}.tally.tmp"
    tmp.write_text(json.dumps(done))
    os.replace(tmp, folder / f"{k}.tally.json")


close_remote_access()          # the launcher's prompt and XMLRPC servers: nobody else may reach a worker
try:
    while not (pool / "stop").exists():
        task = claim(pool, worker)
        if task is None:
            time.sleep(IDLE_S)
        else:
            run_one(task)
except BaseException:                            # the parent shows this and stops the others
    import traceback
    traceback.print_exc()
    sys.stderr.flush()
    os._exit(1)
os._exit(0)          # past YADE's own teardown (threads of its prompt servers)

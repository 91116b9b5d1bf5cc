"""A Dask worker's scene process (scenes/queue.SceneProcess starts it):

    python3 -m yadebreak.jobs.scene_process

reads one JSON line per task from stdin, {"spec": ..., "scenes": [k, ...]}, runs those scenes
(scenes.queue.run_here) and answers with one JSON line on stdout, until stdin closes. Whatever
else is printed (YADE's own lines) goes to stderr. Imports yade (through the scenes).
"""
import json
import os
import signal
import sys


def main():
    signal.signal(signal.SIGINT, signal.SIG_IGN)      # the worker's parent stops it, not Ctrl-C
    answers = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)                                     # stray prints: stderr, never the answers
    sys.stdout = sys.stderr
    from yadebreak.scenes.queue import run_here      # the scenes make yade importable
    for line in sys.stdin:
        task = json.loads(line)
        answers.write(json.dumps(run_here(task["spec"], task["scenes"])) + "\n")
        answers.flush()
    os._exit(0)                                       # past YADE's own teardown


if __name__ == "__main__":
    main()

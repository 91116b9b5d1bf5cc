"""The scenes of impact runs handed out as Dask tasks, on any --scheduler
(process/scheduler.py), from one queue kept for a whole command: verify's figures, or a
single-impact run's energies.

Why one queue: scenes of one set differ in cost (a cascade of 60 or 70 breakages at 3000 J/kg:
65 to 115 s), so each worker takes the next scene when it is free, and several sets queued at
once (verify's Runner.run_all) keep every worker busy up to the last scene of the last set.
Why a YADE process kept by each worker (SceneProcess): a scene of a probability point takes well
under a second, a new YADE process seconds to start; it imports yade once and runs scene after
scene (O.reset() between).

A task runs consecutive scenes of a spec (scenes.run_scenes, or a "task" spec's
function(spec, k)) and returns their tallies and events: as many as leave each worker at least
process.scheduler.TASKS_PER_WORKER tasks of a set (chunk_size), since a task costs the
scheduler, the worker and the parent a few ms and a default single-impact scene lasts 45 ms.
The parent writes each scene's events to <log>.workers/<k>.jsonl as it arrives and joins them
in scene order at the end, so workers need no shared folder, a failed run leaves the scenes done
beside its event log, and the result is that of the scenes run one after the other in one
process (tests/test_scheduler.py). A task that fails (its worker died, its scene raised) runs
again up to `retries` times, as a sweep's line does; a scene whose result has arrived never runs
again (its future is released at once).
Scenes layer: imports neither yade nor dask at load.
"""
from __future__ import annotations

import importlib
import json
import shutil
import tempfile
import time
from pathlib import Path

from yadebreak.process.scheduler import chunk_size
from yadebreak.process.signals import stop_point

#: how often the parent looks for finished scenes (s): a scene takes 0.05 s at the least
POLL_S = 0.05


class SceneQueue:
    """Scenes of impact specs as tasks of `scheduler` (a process.scheduler.Scheduler, connected
    at the first submit); close() (or the end of a `with` block) lets the workers go."""

    def __init__(self, scheduler, retries=1):
        self.scheduler, self.retries = scheduler, int(retries)
        self._client = self._closer = self._finished = None
        self._pending = {}                    # future -> (its set, scenes, attempt, place)
        self._submitted = self._done = self._tasks = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def start(self):
        """Connect now, so that a scheduler that does not answer stops the command before its
        first scene (SchedulerError); returns the queue."""
        self._connect()
        return self

    @property
    def workers(self):
        """The workers the scheduler has now (None before the first submit)."""
        if self._client is None:
            return None
        return len(self._client.scheduler_info()["workers"])

    def submit(self, spec, event_log=None):
        """Queue every scene of a run_scenes `spec` (or of a task's: {"task":
        "module:function", "counts": one entry per scene, ...}); returns the set to collect().
        Scenes submitted first start first. With an `event_log`, scenes done are kept in
        `<log>.workers` until the set is collected."""
        self._connect()
        scene_set = SceneSet(spec, event_log)
        size = chunk_size(scene_set.scenes, self.workers)
        for first in range(0, scene_set.scenes, size):
            self._send(scene_set, list(range(first, min(first + size, scene_set.scenes))), 1)
        return scene_set

    def collect(self, scene_set, on_scene=None, on_wait=None, wait_every_s=60.0):
        """Wait for a set's scenes: (reports.ImpactTally of them all, merged in scene order; of
        a task's spec, what each scene's call returned, in scene order). on_scene(scenes done,
        scenes, tally so far) as they end; on_wait(scenes done, scenes submitted), both counted
        over every set of the queue, every `wait_every_s` of waiting. A scene that fails more
        than `retries` times stops the command with its error."""
        reported, told, merged = 0, time.time(), 0.0
        while len(scene_set.done) < scene_set.scenes:
            stop_point()                    # SIGINT, SIGTERM in a script: end here
            self._harvest()
            # the merge takes every scene so far: once a second at most (a core the workers need)
            if (on_scene is not None and not scene_set.task and len(scene_set.done) > reported
                    and time.time() - merged >= 1.0):
                reported, merged = len(scene_set.done), time.time()
                on_scene(reported, scene_set.scenes, scene_set.tally())
            if on_wait is not None and time.time() - told >= wait_every_s:
                told = time.time()
                on_wait(self._done, self._submitted)
        return scene_set.finish()

    def close(self):
        if self._client is not None:
            self._client.close()
            if self._closer is not None:
                self._closer.close()
        self._client = self._closer = self._finished = None
        self._pending = {}

    def _connect(self):
        if self._client is None:
            from distributed import as_completed
            self._client, self._closer = self.scheduler.connect()
            self._finished = as_completed()   # told by the client's callbacks: no polling

    def _send(self, scene_set, scenes, attempt, place=None):
        # priority: the place in the order of submission, kept by a retry (Dask runs the higher
        # first)
        place = self._tasks if place is None else place
        future = self._client.submit(run_scenes_task, scene_set.spec, scenes, pure=False,
                                     priority=-place,
                                     key=f"yadebreak-scenes-{place}-{attempt}")
        self._pending[future] = (scene_set, scenes, attempt, place)
        self._finished.add(future)
        self._tasks += attempt == 1
        self._submitted += len(scenes) if attempt == 1 else 0

    def _harvest(self):
        """Take in every scene finished by now (or wait POLL_S)."""
        if not self._finished.has_ready():
            time.sleep(POLL_S)
            return
        for future in self._finished.next_batch(block=False):
            scene_set, scenes, attempt, place = self._pending.pop(future)
            try:
                for k, returned in zip(scenes, future.result()):
                    scene_set.keep(k, returned)
                self._done += len(scenes)
            except Exception as exc:        # a scene raised, or its worker died
                if attempt > self.retries:
                    self.close()
                    raise RuntimeError(
                        f"scenes {scenes[0]}-{scenes[-1]} failed {attempt} times (--retries "
                        f"{self.retries}); the scenes done are kept in "
                        f"{scene_set.folder or 'memory only'}: {type(exc).__name__}: {exc}") \
                        from exc
                self._send(scene_set, scenes, attempt + 1, place)
            future.release()                # its result lives here now: never computed again


class SceneSet:
    """The scenes of one spec in a queue: what each returned, kept as they arrive."""

    def __init__(self, spec, event_log):
        self.spec, self.event_log = spec, event_log
        self.scenes, self.task = len(spec["counts"]), "task" in spec
        self.done = {}
        self.folder = None
        if event_log is not None:
            self.folder = Path(event_log).with_suffix(".workers")
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder.mkdir(parents=True)

    def keep(self, k, returned):
        if self.folder is not None and "events" in returned:
            (self.folder / f"{k}.jsonl").write_text(returned["events"])
        if self.task:
            self.done[k] = returned["returned"]
        else:
            from yadebreak.analysis.reports import ImpactTally
            self.done[k] = ImpactTally.from_dict(returned["tally"])

    def tally(self):
        """The tally of the scenes done so far, merged in scene order."""
        from yadebreak.analysis.reports import ImpactTally
        tally = ImpactTally(self.spec["size"])
        for k in sorted(self.done):
            tally.merge(self.done[k])
        return tally

    def finish(self):
        if self.folder is not None:
            Path(self.event_log).write_text("".join(
                (self.folder / f"{k}.jsonl").read_text() for k in range(self.scenes)
                if (self.folder / f"{k}.jsonl").exists()))
            shutil.rmtree(self.folder)
        if self.task:
            return [self.done[k] for k in range(self.scenes)]
        return self.tally()


def run_scenes_task(spec, scenes):
    """A worker's task: the scenes `scenes` of `spec`, run by this worker's scene process
    (SceneProcess, started at its first task and kept). Why not in the worker itself: a scene's
    Python would share the GIL with the worker's event loop, and where every core is busy each
    hand-over waits for the OS (measured: 300 probability scenes on local:2, 2 cores, took 1.6 to
    2 times as long per scene as in one process)."""
    global _PROCESS
    if _PROCESS is None or not _PROCESS.alive():
        _PROCESS = SceneProcess()
    return _PROCESS.run(spec, scenes)


_PROCESS = None                             # this worker's SceneProcess


class SceneProcess:
    """A plain-Python child (jobs/scene_process.py) that imports yade once and runs the scenes
    it is sent, one line of JSON each way; it dies with its worker."""

    def __init__(self):
        import subprocess
        from yadebreak.process.children import python_module
        self._err = tempfile.TemporaryFile("w+")
        self._proc = python_module("yadebreak.jobs.scene_process", stdin=subprocess.PIPE,
                                   stdout=subprocess.PIPE, stderr=self._err, text=True)

    def alive(self):
        return self._proc.poll() is None

    def run(self, spec, scenes):
        self._proc.stdin.write(json.dumps({"spec": spec, "scenes": scenes}) + "\n")
        self._proc.stdin.flush()
        line = self._proc.stdout.readline()
        if not line:
            self._proc.wait()
            self._err.seek(0)
            raise RuntimeError(f"the scene process ended (exit {self._proc.returncode}): "
                               + self._err.read()[-1500:])
        return json.loads(line)


def run_here(spec, scenes):
    """The scenes `scenes` of `spec` in this process, one after the other: for each,
    {"returned": what a task spec's function(spec, k) returned} or {"tally": its tally as a
    dict, "events": its event lines}."""
    if "task" in spec:
        return [{"returned": call_task(spec, k)} for k in scenes]
    from yadebreak.scenes.impacts import run_scenes
    done = []
    with tempfile.TemporaryDirectory(prefix="yadebreak-scene-") as folder:
        log = Path(folder) / "events.jsonl"
        for k in scenes:
            log.write_text("")
            tally, _ = run_scenes(spec, [k], log)
            done.append({"tally": tally.to_dict(), "events": log.read_text()})
    return done


def call_task(spec, k):
    """Scene k of a task's spec: function(spec, k) for spec["task"] = "module:function" (in a
    worker, or in the process that would have queued it)."""
    module, name = spec["task"].split(":")
    return getattr(importlib.import_module(module), name)(spec, k)

"""YADE worker processes that run the scenes of single_impacts from one queue, for as long as a
job needs them (verify's figures, one --jobs N single-impact run).

Why a pool that outlives one set of impacts: a YADE process takes about 4 s to start, and verify
runs about a hundred sets, most of them seconds long (the probability points). Why a queue instead
of fixed shares: scenes of one set differ in cost (a cascade of 60 or 70 breakages at 3000 J/kg:
65 to 115 s), so with fixed shares one worker idles while the other ends its share; from a queue
each worker takes the next scene when it is free, and several sets queued at once (Runner.run_all)
keep both busy up to the last scene of the last set.

The queue is a folder: one file per scene, named so that they sort in the order submitted; a
worker claims one by renaming it (atomic: two workers never run the same scene). A worker writes
the scene's events to <set>/<k>.jsonl, then its tally to <set>/<k>.tally.json (that file says the
scene is done); the parent merges the tallies in scene order, so the result is that of the scenes
run one after the other in one process, whatever worker ran which (tests/test_high_energy.py).
Scenes layer: the workers import yade (jobs/impact_worker.py), this module does not.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

#: how often the parent looks at the sets it waits for (s)
POLL_S = 0.1


class ImpactPool:
    """`jobs` YADE processes running single_impacts scenes from a queue; started at the first
    submit, stopped by close() (or the end of a `with` block, or the parent's death)."""

    def __init__(self, jobs):
        self.jobs = int(jobs)
        self.folder = None
        self._procs, self._errors = [], []
        self._submitted = 0
        self._sets = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def submit(self, spec, event_log=None):
        """Queue every scene of a single_impacts `spec` (or of a task's: {"task":
        "module:function", "counts": one entry per scene, ...}, each scene a call of
        function(spec, k) in a worker); returns the set to collect(). With an
        `event_log`, the set's folder is `<log>.workers` (a failed run leaves its events there)."""
        self._start()
        if event_log is None:
            folder = self.folder / f"set{self._sets:05d}"
        else:
            folder = Path(event_log).with_suffix(".workers")
            shutil.rmtree(folder, ignore_errors=True)
        self._sets += 1
        folder.mkdir(parents=True)
        (folder / "spec.json").write_text(json.dumps(spec))
        for k in range(len(spec["counts"])):
            name = f"{self._submitted:09d}.json"
            self._submitted += 1
            tmp = self.folder / "queue.tmp" / name
            tmp.write_text(json.dumps({"set": str(folder), "scene": k}))
            os.replace(tmp, self.folder / "queue" / name)   # whole files only: workers list it
        return ImpactSet(folder, spec, event_log)

    def collect(self, impact_set, on_scene=None, on_wait=None, wait_every_s=60.0):
        """Wait for a set's scenes: (reports.ImpactTally of them all, merged in scene order; of a
        task's spec, what each scene's call returned, in scene order). on_scene(scenes done,
        scenes, tally so far) as they end; on_wait(scenes started, scenes submitted), both
        counted over every set, every `wait_every_s` of waiting. A failed worker stops the pool
        and raises with its last words."""
        from yadebreak.analysis.reports import ImpactTally
        n = len(impact_set.spec["counts"])
        task = "task" in impact_set.spec
        read = (lambda data: data) if task else ImpactTally.from_dict
        tallies, reported = {}, 0
        told = time.time()
        while True:
            if on_wait is not None and time.time() - told >= wait_every_s:
                told = time.time()
                on_wait(len(os.listdir(self.folder / "claimed")), self._submitted)
            self._check()
            for k in range(n):
                path = impact_set.folder / f"{k}.tally.json"
                if k not in tallies and path.exists():
                    tallies[k] = read(json.loads(path.read_text()))
            if on_scene is not None and not task and len(tallies) > reported:
                reported = len(tallies)
                on_scene(reported, n, _merged(impact_set.spec["size"], tallies))
            if len(tallies) == n:
                break
            time.sleep(POLL_S)
        if impact_set.event_log is not None:
            lines = "".join((impact_set.folder / f"{k}.jsonl").read_text() for k in range(n))
            Path(impact_set.event_log).write_text(lines)
        shutil.rmtree(impact_set.folder)
        if task:
            return [tallies[k] for k in range(n)]
        return _merged(impact_set.spec["size"], tallies)

    def close(self, keep=False):
        """Stop the workers (an idle worker sees the stop file within 0.05 s; a busy one is
        killed after 5 s) and remove the queue, unless `keep` (a failure: its files explain)."""
        if self.folder is None:
            return
        (self.folder / "stop").write_text("")
        deadline = time.time() + 5.0
        for p in self._procs:
            try:
                p.wait(timeout=max(0.0, deadline - time.time()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for f in self._errors:
            f.close()
        if not keep:
            shutil.rmtree(self.folder, ignore_errors=True)
        self.folder, self._procs, self._errors = None, [], []

    def _start(self):
        if self.folder is not None:
            return
        self.folder = Path(tempfile.mkdtemp(prefix="yadebreak-impacts-"))
        (self.folder / "queue").mkdir()
        (self.folder / "queue.tmp").mkdir()
        (self.folder / "claimed").mkdir()
        package = str(Path(__file__).resolve().parents[2])
        worker = str(Path(__file__).resolve().parents[1] / "jobs" / "impact_worker.py")
        from yadebreak.process.children import die_with_parent  # a parent killed (even -9) takes them
        self._errors = [open(self.folder / f"{j}.err", "w") for j in range(self.jobs)]
        self._procs = [subprocess.Popen(["yade", "-n", "-x", worker, str(self.folder), str(j),
                                         package],
                                        stdout=subprocess.DEVNULL, stderr=self._errors[j],
                                        preexec_fn=die_with_parent)
                       for j in range(self.jobs)]

    def _check(self):
        """Raise if a worker has ended before close(), with its last words."""
        ended = [j for j, p in enumerate(self._procs) if p.poll() is not None]
        if ended:
            j, folder = ended[0], self.folder
            code = self._procs[j].returncode
            words = (folder / f"{j}.err").read_text()[-1500:]
            self.close(keep=True)
            raise RuntimeError(f"impact worker {j} ended (exit {code}); the scenes done so far "
                               f"are in {folder} (and beside an event log): {words}")


class ImpactSet:
    """The scenes of one single_impacts spec in a pool: its folder, spec and event log."""

    def __init__(self, folder, spec, event_log):
        self.folder, self.spec, self.event_log = folder, spec, event_log


def _merged(size, tallies):
    from yadebreak.analysis.reports import ImpactTally
    tally = ImpactTally(size)
    for k in sorted(tallies):
        tally.merge(tallies[k])
    return tally


def call_task(spec, k):
    """Scene k of a task's spec: function(spec, k) for spec["task"] = "module:function" (in a
    worker, or in the process that would have queued it)."""
    import importlib
    module, name = spec["task"].split(":")
    return getattr(importlib.import_module(module), name)(spec, k)


def claim(folder, worker):
    """The next scene of the queue in `folder` for `worker`: {"set": folder, "scene": k}, or None
    if the queue is empty (the worker's side)."""
    queue = Path(folder) / "queue"
    for name in sorted(os.listdir(queue)):
        mine = Path(folder) / "claimed" / f"{name}.{worker}"
        try:
            os.rename(queue / name, mine)
        except FileNotFoundError:                # another worker was first
            continue
        return json.loads(mine.read_text())
    return None

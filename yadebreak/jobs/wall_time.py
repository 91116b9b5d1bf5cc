"""A command's wall time on N workers, predicted from its scenes' own wall times.

The scenes go to the workers in the command's queue order, in tasks of consecutive scenes
(process.scheduler.chunk_size), each task to the first worker free, in stages that wait for each
other (a single-impact command collects one energy's scenes before it queues the next). So a stage
takes at least its longest task (its critical path) and at least its scenes' sum over N;
`makespan` plays the queue exactly. No YADE.
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass

from yadebreak.process.scheduler import chunk_size

#: the worker counts a prediction is given for
WORKERS = (1, 2, 8, 32, 128)


def makespan(durations, workers):
    """Wall time (s) of scenes lasting `durations` (s, in queue order) on `workers` workers that
    each take the next scene in the queue when free."""
    free = [0.0] * min(max(int(workers), 1), max(len(durations), 1))
    for d in durations:
        heapq.heapreplace(free, free[0] + d)
    return max(free)


@dataclass
class WallTime:
    """What the scenes of a command took and would take: scenes (-), sum_s (their wall times
    added up, s), longest_s (the longest scene, s; no number of workers ends sooner), predicted_s
    ({workers: s}) and source (where the scenes' times come from)."""
    scenes: int
    sum_s: float
    longest_s: float
    predicted_s: dict
    source: str

    def line(self):
        """One line: the sum, the longest scene and the prediction on each count of workers."""
        on = ", ".join(f"{s:.0f} s on {n}" for n, s in sorted(self.predicted_s.items()))
        return (f"{self.scenes} scenes, {self.sum_s:.0f} s of scenes, the longest "
                f"{self.longest_s:.0f} s: about {on} worker(s) ({self.source})")

    def to_dict(self):
        """summary.json's wall_time (docs/outputs.md)."""
        return {"scenes": self.scenes, "sum_s": self.sum_s, "longest_s": self.longest_s,
                "predicted": [{"workers": n, "wall_s": s}
                              for n, s in sorted(self.predicted_s.items())],
                "source": self.source}


def tasks(durations, workers):
    """The wall times (s) of the tasks that scenes lasting `durations` go out in on `workers`
    workers (one on one worker: this process runs them, none go out)."""
    size = chunk_size(len(durations), workers) if workers > 1 else 1
    return [sum(durations[i:i + size]) for i in range(0, len(durations), size)]


def predict(stages, source, workers=WORKERS):
    """The WallTime of `stages` (a stage starts when the one before has ended: a list of scene
    wall times (s) in queue order, one set of scenes; or a list of such sets, queued together, as
    verify queues every figure's runs) on each count in `workers`."""
    stages = [stage if stage and isinstance(stage[0], list) else [stage] for stage in stages]
    every = [d for stage in stages for one in stage for d in one]
    predicted = {int(n): sum(makespan([t for one in stage for t in tasks(one, n)], n)
                             for stage in stages) for n in workers}
    return WallTime(len(every), float(sum(every)), float(max(every, default=0.0)), predicted,
                    source)

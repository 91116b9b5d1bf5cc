"""Where a command's tasks run: --scheduler, read once for sweep, tradeoff, verify and the
single-impact script.

    local            a Dask worker per core of this machine
    local:N          N workers on this machine (--jobs N of verify and the scripts)
    tcp://HOST:PORT  the workers of a running Dask scheduler (`dask scheduler`, `dask worker`)
    slurm[:N], pbs[:N]  N batch jobs of one worker each (dask-jobqueue; default N: 1)

Every worker runs one task at a time (one thread: YADE's scene is the process's). A local
cluster lives in a plain-Python child process (local_cluster.py): under the `yade` launcher,
multiprocessing would run the launcher again in every worker it spawns. Dask is imported when a
cluster starts; reading the option needs none.
"""
from __future__ import annotations

import os
import subprocess
import tempfile
from dataclasses import dataclass

from yadebreak.process.children import python_module

FORMS = "local, local:N (N workers), tcp://HOST:PORT, slurm[:N] or pbs[:N] (N batch jobs)"

#: a set of scenes goes out in at least this many tasks per worker (chunk_size): enough that
#: the last tasks of a set, of unequal cost, still spread over the workers
TASKS_PER_WORKER = 8


def chunk_size(scenes, workers):
    """Scenes per task of a set of `scenes` on `workers` workers (None: unknown, one each)."""
    return max(1, scenes // (TASKS_PER_WORKER * workers)) if workers else 1


class SchedulerError(ValueError):
    """A scheduler that cannot be used: one line for the user."""


@dataclass(frozen=True)
class Scheduler:
    """A parsed --scheduler: `kind` local, tcp, slurm or pbs; `workers` (local: processes,
    slurm/pbs: batch jobs; None: the cores, or the running scheduler's own); `address` (tcp)."""

    kind: str
    workers: int | None = None
    address: str = ""

    @classmethod
    def parse(cls, text, option="--scheduler"):
        text = str(text).strip()
        kind, _, count = text.partition(":")
        if text.startswith("tcp://"):
            if not text[len("tcp://"):]:
                raise SchedulerError(f"{option} = {text}: tcp:// needs HOST:PORT (accepted: "
                                     f"{FORMS})")
            return cls("tcp", None, text)
        if kind not in ("local", "slurm", "pbs"):
            raise SchedulerError(f"{option} = {text}: accepted {FORMS}")
        if count and not (count.isdigit() and int(count) >= 1):
            raise SchedulerError(f"{option} = {text}: N must be a whole number >= 1 (accepted: "
                                 f"{FORMS})")
        return cls(kind, int(count) if count else None)

    @property
    def in_process(self):
        """One local worker: the command's own process runs the tasks (no worker to start)."""
        return self.kind == "local" and self.count == 1

    @property
    def count(self):
        """The workers it will have, where known before it starts (None: a running scheduler's)."""
        if self.kind == "local":
            return self.workers or usable_cores()
        if self.kind in ("slurm", "pbs"):
            return self.workers or 1
        return None

    def __str__(self):
        if self.kind == "tcp":
            return self.address
        return self.kind + (f":{self.workers}" if self.workers else "")

    def connect(self, jobqueue_options=None):
        """A Dask Client of this scheduler, and what to close after it: (client, closer)."""
        try:
            from distributed import Client
        except ImportError:
            raise SchedulerError("--scheduler needs Dask: apt-get install python3-dask "
                                 "python3-distributed (make deps does)") from None
        if self.kind == "local":
            cluster = LocalCluster(self.count)
            return Client(cluster.address), cluster
        if self.kind == "tcp":
            try:
                return Client(self.address, timeout=30), None
            except OSError as exc:
                raise SchedulerError(f"--scheduler = {self}: no scheduler answered ({exc})") \
                    from None
        try:
            import dask_jobqueue
        except ImportError:
            raise SchedulerError(f"--scheduler = {self} needs dask-jobqueue (pip install "
                                 "dask-jobqueue on the machine that starts the command)") from None
        kind = dask_jobqueue.SLURMCluster if self.kind == "slurm" else dask_jobqueue.PBSCluster
        cluster = kind(**{"cores": 1, "processes": 1, "memory": "2GB",
                          **(jobqueue_options or {})})
        cluster.scale(jobs=self.count)
        return Client(cluster), cluster


def chosen(scheduler, jobs, default="local"):
    """The Scheduler of a command given --scheduler `scheduler` and --jobs `jobs` (None or ''
    where not given): --jobs N is local:N; both given is refused (SchedulerError)."""
    if scheduler and jobs is not None:
        raise SchedulerError(f"--scheduler = {scheduler} and --jobs = {jobs}: give one (--jobs N "
                             "is --scheduler local:N)")
    if jobs is not None:
        return Scheduler("local", int(jobs))
    return Scheduler.parse(scheduler or default)


def usable_cores():
    """The cores this process may use (its CPU affinity)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                         # no affinity on this system
        return os.cpu_count() or 1


class LocalCluster:
    """A Dask LocalCluster of `workers` single-threaded worker processes, run by a plain-Python
    child (local_cluster.py) that ends with this process or close(). Its log is kept in an
    unnamed temporary file, shown if it fails to start."""

    def __init__(self, workers):
        self._log = tempfile.TemporaryFile("w+")       # gone with it, read if it fails
        self._proc = python_module("yadebreak.process.local_cluster", str(int(workers)),
                                   stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                   stderr=self._log, text=True)
        self.address = self._proc.stdout.readline().strip()
        if not self.address.startswith("tcp://"):
            self._proc.wait()
            self._log.seek(0)
            said = self._log.read()[-800:]
            self.close()
            raise SchedulerError(f"--scheduler = local:{workers}: the cluster did not start: "
                                 + said)

    def close(self):
        if self._proc.poll() is None:
            self._proc.stdin.close()            # the child closes its cluster and ends
            try:
                self._proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        self._log.close()


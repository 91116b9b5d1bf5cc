"""A command's wall time on 1 and 2 workers against its prediction, on a local cluster and on a
running TCP scheduler with two workers (docs/performance.md, "Wall time on more workers").

    /usr/bin/python3 benchmarks/bench_wall_time.py [--command verify|single_impact]
        [--repeats 2] [--out /tmp/bench_wall_time]

First the command's defaults on --jobs 1: its scenes' wall times give the prediction on N workers
(jobs/wall_time.py). Then, alternating, --repeats runs each of --jobs 1, --jobs 2 and
--scheduler tcp://127.0.0.1:PORT (a `dask-scheduler` and two single-threaded `dask-worker`s
started here for it, worker saturation 1.0): each run's whole-process wall time (median), and its
scenes' own sum, against the prediction of the first run. Prints the CPU it ran on.
"""
import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(sys.argv[0]).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from yadebreak.jobs import wall_time  # noqa: E402


def command(which, out, placement):
    if which == "verify":
        return [sys.executable, "-m", "yadebreak", "verify", "--out", str(out), *placement]
    return ["yade", "-n", "-x", str(ROOT / "scripts" / "single_impact.py"), "--out", str(out),
            *placement]


def scene_walls(which, out):
    """The stages of scene wall times of a finished run in `out` (wall_time.predict's)."""
    if which == "verify":
        results = json.loads((out / "results.json").read_text())
        walls = results["scene_walls"]
        return [[walls[key] for key in walls]]
    summary = json.loads((out / "summary.json").read_text())
    return [r["scene_walls_s"] for r in summary["results"]]


def timed(which, out, placement):
    """Whole-process wall time (s) of one run, and its scenes' sum (s)."""
    start = time.time()
    subprocess.run(command(which, out, [*placement, "--overwrite", "1"]), check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
    wall = time.time() - start
    return wall, wall_time.predict(scene_walls(which, out), "", (1,)).sum_s


class TcpCluster:
    """A dask-scheduler on the loopback and two single-threaded dask-workers."""

    def __init__(self, workers=2):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        env = {**os.environ, "DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION": "1.0",
               "PYTHONPATH": str(ROOT)}
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
        self.procs = [subprocess.Popen(["dask-scheduler", "--host", "127.0.0.1", "--port",
                                        str(self.port), "--dashboard-address", "127.0.0.1:0"],
                                       **quiet)]
        time.sleep(2.0)
        self.procs.append(subprocess.Popen(["dask-worker", self.address, "--nthreads", "1",
                                            "--nworkers", str(workers), "--host", "127.0.0.1",
                                            "--dashboard-address", "127.0.0.1:0"], **quiet))
        from distributed import Client
        with Client(self.address, timeout=60) as client:
            client.wait_for_workers(workers, timeout=60)

    @property
    def address(self):
        return f"tcp://127.0.0.1:{self.port}"

    def close(self):
        for p in reversed(self.procs):
            p.terminate()
            p.wait(30)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--command", choices=("verify", "single_impact"), default="verify")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--out", default="/tmp/bench_wall_time")
    args = parser.parse_args()
    out = Path(args.out)
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), "?")
    print(f"{args.command} defaults on {cpu}, {os.cpu_count()} cores")
    first = out / "first"
    subprocess.run(command(args.command, first, ["--jobs", "1", "--overwrite", "1"]), check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
    predicted = wall_time.predict(scene_walls(args.command, first), "the first run",
                                  (1, 2, 4, 8, 16, 32, 128))
    print(f"prediction from a --jobs 1 run: {predicted.line()}")
    cluster = TcpCluster(2)
    try:
        settings = {"local:1": ["--jobs", "1"], "local:2": ["--jobs", "2"],
                    "tcp, 2 workers": ["--scheduler", cluster.address]}
        runs = {name: [] for name in settings}
        for _ in range(args.repeats):
            for name, placement in settings.items():
                runs[name].append(timed(args.command, out / name.split(",")[0].replace(":", ""),
                                        placement))
    finally:
        cluster.close()
    print("| workers | predicted (s) | measured, median (s) | runs (s) | scenes' sum, median (s) |")
    print("|---|---|---|---|---|")
    for name, got in runs.items():
        n = 1 if name == "local:1" else 2
        walls = [w for w, _ in got]
        print(f"| {name} | {predicted.predicted_s[n]:.1f} | {statistics.median(walls):.1f} | "
              f"{', '.join(f'{w:.1f}' for w in walls)} | "
              f"{statistics.median(s for _, s in got):.1f} |")


if __name__ == "__main__":
    main()

"""A Dask LocalCluster in its own plain-Python process (scheduler.LocalCluster starts it):

    python3 -m yadebreak.process.local_cluster N

prints the scheduler's address on stdout, then keeps N single-threaded worker processes until
its stdin closes or SIGTERM comes (its parent ended: process.children.die_with_parent); then it
closes the cluster, so its workers go too. Everything listens on the loopback only.

The scheduler hands a task to a worker only when the worker is free (worker-saturation 1.0), so
each worker takes the next task of the queue, as the wall-time prediction (jobs/wall_time.py)
plays it. A task whose worker died is not run again by the scheduler itself (allowed-failures
0): the command's own --retries decide (scenes/queue.py). A worker's statistical profiler is off:
it samples the task's stack every 10 ms, holding the GIL the scene needs.
"""
import signal
import sys


def main(workers):
    import dask
    from distributed import LocalCluster
    dask.config.set({"distributed.scheduler.worker-saturation": 1.0,
                     "distributed.scheduler.allowed-failures": 0,
                     "distributed.worker.profile.enabled": False})
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))     # closes the cluster on the way out
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      host="127.0.0.1", dashboard_address="127.0.0.1:0",
                      worker_dashboard_address="127.0.0.1:0") as cluster:
        print(cluster.scheduler_address, flush=True)
        sys.stdin.read()                    # until the parent closes it (or ends)


if __name__ == "__main__":
    main(int(sys.argv[1]))

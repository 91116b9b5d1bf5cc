"""Sweeps of yade-batch tables on Dask's distributed scheduler, from a laptop to a cluster.

    python3 -m yadebreak sweep scripts/bed_sweep.table scripts/bed_impact.py --out out/sweep
    python3 -m yadebreak sweep TABLE SCRIPT --out DIR --scheduler tcp://head:8786

The same table yade-batch takes: each line runs as `yade -n -x SCRIPT` with YADE_BATCH =
"TABLE:LINE", as yade-batch runs it, so the script reads its parameters with
readParamsFromTable exactly as under yade-batch, and writes into DIR/<description>/ (the
yadebreak scripts follow YADEBREAK_SWEEP_OUT; log.txt there holds the run's output). DIR/sweep.json
holds each line's state as tasks end; a second call runs only the lines not done; at the end every
line's summary.json is flattened into DIR/sweep.csv (gather(), also `python3 -m yadebreak gather`
for a yade-batch sweep). Workers must see TABLE, SCRIPT and DIR at the same paths (a shared file
system), and have YADE.

The table reader and the status file need no Dask; Dask is imported when a sweep starts.
"""
from __future__ import annotations

import csv
import io
import datetime
import json
import math
import os
import re
import shutil
import socket
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from yadebreak.jobs.lifecycle import write_atomic
from yadebreak.process.children import die_with_parent
from yadebreak.process.scheduler import Scheduler, SchedulerError

#: the exit code of a yadebreak script refusing its options (never retried)
USER_ERROR = 2
#: env var naming the folder a yadebreak script writes its line's outputs in (<it>/<description>)
OUT_ENV = "YADEBREAK_SWEEP_OUT"


class SweepError(SchedulerError):
    """A sweep that cannot start (bad table, folder; a scheduler's is its parent,
    SchedulerError): one line for the user."""


# -- the table ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TableLine:
    """One parameter line of a yade-batch table."""

    number: int              # its line number in the file (as an editor shows it: YADE_BATCH's)
    description: str         # the run's name and folder
    values: dict             # column -> value as written (quotes kept, as YADE reads them)
    env: dict = field(default_factory=dict)   # !NAME columns: the run's environment


def read_table(path):
    """The lines of a yade-batch table, read as yade.utils.TableParamReader reads them: '#'
    comments, the first non-empty line the headings, '=' for the previous line's value, a
    'description' column or one built from the '!'-marked columns (all columns if none), a
    repeated one suffixed with __line=N__. Columns named !NAME set the run's environment (as
    yade-batch does). Raises SweepError naming the file and line for a table that cannot run."""
    path = Path(path)
    if not path.is_file():
        raise SweepError(f"table {path}: no such file")
    raw = [""] + path.read_text().splitlines()
    text = [re.sub(r"\s*#.*", "", line) for line in raw]
    usable = [i for i, line in enumerate(text) if line.strip()]
    if len(usable) < 2:
        raise SweepError(f"table {path}: needs a line of column names and at least one line of "
                         "values")
    headings = text[usable[0]].split()
    if "description" in headings:
        described_by = None
    else:
        described_by = [h.rstrip("!") for h in headings if h.endswith("!") and
                        not h.startswith("!")] or [h.rstrip("!") for h in headings]
        headings = [h[:-1] if h.endswith("!") and not h.startswith("!") else h for h in headings]
    for k, head in enumerate(headings):
        if head in headings[:k]:          # yade-batch would take the last value: refused
            raise SweepError(f"table {path}:{usable[0]}: column {k + 1}, {head!r}, repeats column "
                             f"{headings.index(head) + 1} (each parameter once)")
    lines, previous, seen = [], None, set()
    for number in usable[1:]:
        cells = text[number].split()
        if len(cells) != len(headings):
            raise SweepError(f"table {path}:{number}: {len(cells)} values for {len(headings)} "
                             f"columns ({' '.join(headings)})")
        values = {}
        for head, cell in zip(headings, cells):
            if cell == "=":
                if previous is None:
                    raise SweepError(f"table {path}:{number}: '=' (the value above) on the first "
                                     "line of values")
                cell = previous[head]
            values[head] = cell
        previous = values
        if described_by is None:
            description = values.pop("description")
        else:
            description = ",".join(f"{h.lstrip('!').rstrip('!')}={values[h]}"
                                   for h in described_by if h in values)
            description = description.replace("'", "").replace('"', "")
            if description in seen:
                description += f"__line={number}__"
        if not description or "/" in description or description in (".", ".."):
            raise SweepError(f"table {path}:{number}: description {description!r} cannot name a "
                             "folder")
        if description in seen:
            raise SweepError(f"table {path}:{number}: description {description!r} repeats an "
                             "earlier line's (each line needs its own folder)")
        seen.add(description)
        env = {h.strip("!"): v.strip("'\"") for h, v in values.items() if h.startswith("!")}
        params = {h: v for h, v in values.items() if not h.startswith("!")}
        lines.append(TableLine(number, description, params, env))
    return lines


# -- the status file --------------------------------------------------------------------------------
class SweepStatus:
    """DIR/sweep.json: the table, the script and, per line, its state (pending, submitted, done,
    failed, interrupted), exit code, wall time (s), worker, attempts and, for a failure, its
    message. Rewritten whole (atomically) at every change, so a killed sweep leaves it readable."""

    def __init__(self, out, table, script, lines):
        self.path = Path(out) / "sweep.json"
        self.table, self.script = str(table), str(script)
        old = json.loads(self.path.read_text()) if self.path.exists() else None
        if old is not None and (old["table"], old["script"]) != (self.table, self.script):
            raise SweepError(f"--out {out} holds a sweep of {old['table']} with "
                             f"{old['script']}: choose another folder for this table or script")
        previous = {row["description"]: row for row in (old or {}).get("lines", [])}
        self.rows = {}
        for line in lines:
            row = previous.get(line.description, {})
            state = row.get("state", "pending")
            if state == "submitted":          # a sweep that died with it running
                state = "interrupted"
            self.rows[line.description] = {
                "line": line.number, "description": line.description, "state": state,
                "exit_code": row.get("exit_code"), "wall_s": row.get("wall_s"),
                "worker": row.get("worker"), "attempts": row.get("attempts", 0),
                "message": row.get("message", "")}
        self.write()

    def todo(self):
        """Descriptions of the lines to run: every line not done."""
        return [d for d, row in self.rows.items() if row["state"] != "done"]

    def count(self, state):
        return sum(row["state"] == state for row in self.rows.values())

    def update(self, description, **fields):
        self.rows[description].update(fields)
        self.write()

    def write(self):
        doc = {"table": self.table, "script": self.script,
               "updated": datetime.datetime.now().isoformat(timespec="seconds"),
               "lines": list(self.rows.values())}
        tmp = self.path.with_name(self.path.name + ".tmp")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps(doc, indent=1))
        os.replace(tmp, self.path)


# -- one run: the task a worker runs -------------------------------------------------------------
@dataclass(frozen=True)
class Job:
    """One run of a sweep: its folder's name, its table line (0 if none), its command and the
    environment it adds."""

    description: str
    number: int
    argv: tuple
    env: dict = field(default_factory=dict)


def table_job(line, table, script, out, yade="yade"):
    """The Job of a table line, run as yade-batch runs it: `yade -n -jN -x SCRIPT` with
    YADE_BATCH = TABLE:LINE, the line's !NAME columns in the environment and yade-batch's own
    columns obeyed (!THREADS or !OMP_NUM_THREADS: N, default 1; !SCRIPT; !EXEC). The yadebreak
    scripts write into OUT/<description>/ (YADEBREAK_SWEEP_OUT)."""
    env = dict(line.env)
    threads = env.pop("THREADS", env.pop("OMP_NUM_THREADS", "1"))
    script = env.pop("SCRIPT", str(script))
    yade = env.pop("EXEC", yade)
    env.update({"OMP_NUM_THREADS": str(threads), "DISPLAY": "",
                "YADE_BATCH": f"{table}:{line.number}", OUT_ENV: str(out)})
    return Job(line.description, line.number, (yade, "-n", f"-j{threads}", "-x", str(script)),
               env)


def run_job(argv, folder, env, cwd):
    """Run one job's command with `env` added, its output into FOLDER/log.txt (FOLDER made anew:
    the sweep runs a line again only when it is not done). Returns
    {exit_code, wall_s, worker, message}: message is the run's error line (the last '[yadebreak]
    error' line, else its last line) when it failed."""
    folder = Path(folder)
    if folder.exists():           # an earlier attempt of this line (failed or killed): run anew,
        shutil.rmtree(folder)     # as the script refuses a new run over an earlier one
    folder.mkdir(parents=True)
    environment = {**os.environ, "OMP_NUM_THREADS": "1", **env}
    start = time.time()
    with open(folder / "log.txt", "w") as log:
        code = subprocess.call(list(argv), stdout=log, stderr=subprocess.STDOUT,
                               stdin=subprocess.DEVNULL, env=environment, cwd=cwd,
                               preexec_fn=die_with_parent)
    wall = time.time() - start
    message = "" if code == 0 else _error_line(folder / "log.txt")
    return {"exit_code": code, "wall_s": wall, "worker": _worker_name(), "message": message}


def _worker_name():
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return socket.gethostname()


def _error_line(log):
    lines = [line.strip() for line in log.read_text(errors="replace").splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("[yadebreak] error")]
    return (errors or lines or ["(no output)"])[-1][:500]


# -- the scheduler ----------------------------------------------------------------------------------
def connect(spec, jobqueue_options=None, jobs=1):
    """A Dask Client for --scheduler `spec` (process.scheduler: local, local:N, tcp://HOST:PORT,
    slurm[:N], pbs[:N]; the sweep's --jobs is N where slurm or pbs names none), and what to close
    after it: (client, closer or None)."""
    scheduler = Scheduler.parse(spec)
    if scheduler.kind in ("slurm", "pbs") and scheduler.workers is None:
        scheduler = Scheduler(scheduler.kind, int(jobs))
    return scheduler.connect(jobqueue_options)


# -- the sweep ----------------------------------------------------------------------------------
def run_sweep(table, script, out, scheduler="local", retries=1, jobqueue_options=None, jobs=1,
              say=print, yade="yade", tell=None):
    """Run every line of `table` not done yet in `out`, as Dask tasks (run_jobs); then gather
    sweep.csv. Returns the SweepStatus. say(line): the outcome; tell(line): the progress on
    the way (default: say)."""
    table, script, out = Path(table).resolve(), Path(script).resolve(), Path(out).resolve()
    if not script.is_file():
        raise SweepError(f"script {script}: no such file")
    lines = read_table(table)
    status = run_jobs([table_job(line, table, script, out, yade) for line in lines], out,
                      (str(table), str(script)), scheduler, retries, jobqueue_options, jobs,
                      tell or say)
    gather(out, lines)
    failed = [d for d, row in status.rows.items() if row["state"] == "failed"]
    say(f"sweep: {status.count('done')} of {len(lines)} lines done, {len(failed)} failed; "
        f"wrote {out / 'sweep.csv'}")
    for description in failed:
        row = status.rows[description]
        say(f"  failed: line {row['line']} {description} (exit {row['exit_code']}): "
            f"{row['message']}")
    return status


def run_jobs(jobs, out, identity, scheduler="local", retries=1, jobqueue_options=None,
             cluster_jobs=1, say=print):
    """Run every Job not done yet in `out` (its sweep.json; `identity`: the (table, script) the
    folder belongs to) as a Dask task on `scheduler` (see connect), each into
    OUT/<description>/. A failing job is run again up to `retries` more times in this call (not
    one that exits with code 2, a script refusing its values). Ctrl-C stops it: jobs done stay
    done, the others are 'interrupted' and run at the next call. Returns the SweepStatus."""
    out = Path(out).resolve()
    if retries < 0:
        raise SweepError(f"--retries = {retries}: accepted >= 0 (extra attempts of a failing "
                         "line)")
    by_name = {job.description: job for job in jobs}
    status = SweepStatus(out, *identity, jobs)
    todo = status.todo()
    if not todo:
        say(f"sweep: all {len(jobs)} lines are done in {out}")
        return status
    client, cluster = connect(scheduler, jobqueue_options, cluster_jobs)
    try:
        say(f"sweep: {len(todo)} of {len(jobs)} lines to run ({len(jobs) - len(todo)} done "
            f"before) on {scheduler}; dashboard {client.dashboard_link}")
        _run(client, by_name, status, todo, out, retries, say)
    except KeyboardInterrupt:
        for description in status.todo():
            if status.rows[description]["state"] == "submitted":
                status.update(description, state="interrupted")
        say(f"sweep: interrupted; {status.count('done')} of {len(jobs)} lines done are kept "
            f"(run the same command again for the others)")
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return status


def _run(client, jobs, status, todo, out, retries, say):
    from distributed import as_completed
    cwd = os.getcwd()

    def submit(description):
        job = jobs[description]
        attempt = status.rows[description]["attempts"] + 1
        status.update(description, state="submitted", attempts=attempt)
        return client.submit(run_job, job.argv, str(out / description), job.env, cwd,
                             pure=False, key=f"yadebreak-{description}-{attempt}-{time.time_ns()}")

    futures = as_completed()
    owner, tries = {}, {d: 0 for d in todo}
    for description in todo:
        f = submit(description)
        owner[f.key] = description
        futures.add(f)
    start, said, finished = time.time(), 0.0, 0
    for future in futures:
        description = owner.pop(future.key)
        try:
            result = future.result()
        except Exception as exc:          # the task itself failed (a worker lost, ...)
            result = {"exit_code": None, "wall_s": None, "worker": None,
                      "message": f"{type(exc).__name__}: {exc}"}
        ok = result["exit_code"] == 0
        status.update(description, state="done" if ok else "failed", **result)
        tries[description] += 1
        # exit code 2 is a user's mistake (a bad value in the table): another try would fail alike
        if not ok and result["exit_code"] != USER_ERROR and tries[description] <= retries:
            f = submit(description)
            owner[f.key] = description
            futures.add(f)
            continue
        finished += 1
        if time.time() - said > 5.0 or not owner:
            said = time.time()
            say(_progress(status, len(todo), finished, len(owner), time.time() - start))


def _progress(status, planned, finished, running, elapsed):
    left = planned - finished
    eta = (f"about {elapsed * left / finished:.0f} s left" if finished and left
           else "time left unknown" if left else "")
    return (f"sweep: {status.count('done')} done, {min(running, left)} running or queued, "
            f"{status.count('failed')} failed, {elapsed:.0f} s{', ' + eta if eta else ''}")


# -- gathering -------------------------------------------------------------------------------------
def flatten(value, prefix=""):
    """A JSON value as {dotted name: scalar}: dicts by key, lists by index (results.0.t10)."""
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, list):
        items = enumerate(value)
    else:
        return {prefix: value}
    out = {}
    for key, item in items:
        out.update(flatten(item, f"{prefix}.{key}" if prefix else str(key)))
    return out


def gather(out, lines):
    """DIR/sweep.csv: a row per table line (`lines`: TableLines) with its description, line,
    state (from sweep.json if there is one, else from its summary.json), the table's values
    (`table.<column>`) and its summary.json flattened (dotted names); lines without a summary
    keep empty cells. Returns the path."""
    out = Path(out)
    status = {}
    if (out / "sweep.json").exists():
        status = {r["description"]: r for r in json.loads((out / "sweep.json").read_text())["lines"]}
    rows = []
    for line in lines:
        row = {"description": line.description, "line": line.number}
        known = status.get(line.description, {})
        path = out / line.description / "summary.json"
        summary = json.loads(path.read_text()) if path.exists() else None
        row["state"] = known.get("state") or ("done" if summary else "not run")
        row["wall_s"] = known.get("wall_s")
        row.update({f"table.{k}": v.strip("'\"") for k, v in line.values.items()})
        if summary is not None:
            row.update(flatten(summary))
        rows.append(row)
    columns = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    path = out / "sweep.csv"
    out.mkdir(parents=True, exist_ok=True)
    table = io.StringIO(newline="")
    writer = csv.DictWriter(table, columns, restval="")
    writer.writeheader()
    writer.writerows({k: _cell(v) for k, v in row.items()} for row in rows)
    write_atomic(path, table.getvalue())
    return path


def _cell(value):
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return "" if value is None else value


def main_exit_code(status):
    """The sweep command's exit code: 0 if every line is done, 1 otherwise."""
    return 0 if all(row["state"] == "done" for row in status.rows.values()) else 1


if __name__ == "__main__":       # pragma: no cover - python3 -m yadebreak sweep is the entry
    sys.exit("use: python3 -m yadebreak sweep TABLE SCRIPT --out DIR")

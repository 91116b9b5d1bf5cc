"""The `yade` launcher starts a Python prompt and an XMLRPC server that listen on every
interface; every script and pool worker closes both as it starts (YADE)."""
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent


def listening_ports(pid):
    """The TCP ports process `pid` listens on (its sockets in /proc/net/tcp{,6} in LISTEN)."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    ports = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(table):
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A" and fields[9] in inodes:       # 0A: LISTEN
                ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return sorted(ports)


def _started(command, cwd, until):
    """Popen `command` and read its output until a line holds `until`: (process, lines)."""
    proc = subprocess.Popen(command, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    lines = []
    deadline = time.time() + 120
    while time.time() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line)
        if until in line:
            return proc, lines
    proc.kill()
    raise AssertionError("".join(lines))


def _stop(proc):
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(60)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def test_the_launcher_listens_when_nobody_closes_it(tmp_path):
    """The check itself: a plain YADE script keeps both servers."""
    script = tmp_path / "idle.py"
    script.write_text("import time\nprint('idle', flush=True)\ntime.sleep(60)\n")
    proc, lines = _started(["yade", "-n", "-x", str(script)], tmp_path, "idle")
    try:
        assert len(listening_ports(proc.pid)) == 2, "".join(lines)
    finally:
        _stop(proc)


def test_a_script_closes_the_launchers_servers_as_it_starts(tmp_path):
    proc, lines = _started(["yade", "-n", "-x", str(ROOT / "scripts" / "bed_impact.py"),
                            "--out", str(tmp_path / "bed"), "--checkpoint-every", "-1"],
                           tmp_path, "[yadebreak]")
    try:
        assert listening_ports(proc.pid) == [], "".join(lines)
    finally:
        _stop(proc)


def test_a_pool_worker_closes_them_too(tmp_path):
    """A worker of the impact pool, started as the pool starts it, given one task whose spec is
    a named pipe: it waits there, inside its loop, while its ports are read."""
    import json
    for name in ("queue", "claimed", "set"):
        (tmp_path / name).mkdir()
    os.mkfifo(tmp_path / "set" / "spec.json")
    (tmp_path / "queue" / "0").write_text(json.dumps({"set": str(tmp_path / "set"), "scene": 0}))
    proc = subprocess.Popen(["yade", "-n", "-x",
                             str(ROOT / "yadebreak" / "jobs" / "impact_worker.py"),
                             str(tmp_path), "0", str(ROOT)], cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 120
        while not (tmp_path / "claimed" / "0.0").exists() and time.time() < deadline:
            time.sleep(0.1)
        assert (tmp_path / "claimed" / "0.0").exists()
        assert listening_ports(proc.pid) == []
    finally:
        (tmp_path / "stop").touch()
        try:                                 # lets it go (and fail) if it waits there
            pipe = os.open(tmp_path / "set" / "spec.json", os.O_WRONLY | os.O_NONBLOCK)
            os.write(pipe, b"{}")
            os.close(pipe)
        except OSError:                      # no reader: it never got there
            proc.kill()
        proc.wait(60)


def test_attach_closes_them_in_a_users_own_scene_and_says_so_once(tmp_path):
    """A user's scene under the `yade` launcher: once attach() returns nothing listens on a
    non-loopback address (nothing at all: both servers are closed), and one line says so;
    attach(remote_access=True) keeps them."""
    for keep, expected in ((False, 0), (True, 2)):
        script = tmp_path / f"scene_{keep}.py"
        script.write_text(
            f"import sys, time\nsys.path.insert(0, {str(ROOT)!r})\n"
            "from yade import O, utils\nimport yadebreak\nfrom yadebreak import scenes\n"
            "from yadebreak.engine import add_materials\n"
            "ip2, _ = add_materials({'ore': 'copper_ore'})\n"
            "O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material='ore'))\n"
            "O.engines = scenes.hertz_engines(ip2)\n"
            f"yadebreak.attach({{'ore': 'copper_ore'}}, remote_access={keep})\n"
            "print('attached', flush=True)\ntime.sleep(60)\n")
        proc, lines = _started(["yade", "-n", "-x", str(script)], tmp_path, "attached")
        try:
            assert len(listening_ports(proc.pid)) == expected, "".join(lines)
            said = [line for line in lines if "closed YADE's remote" in line]
            assert len(said) == (0 if keep else 1), "".join(lines)
        finally:
            _stop(proc)

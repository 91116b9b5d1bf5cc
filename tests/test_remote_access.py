"""The `yade` launcher starts a Python prompt and an XMLRPC server that listen on every
interface; every script closes both as it starts, and a local Dask cluster listens on the
loopback only (YADE)."""
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


def listening_addresses(pid):
    """The IPv4 addresses process `pid` listens on (dotted), from /proc/net/tcp."""
    inodes = {os.readlink(fd)[8:-1] for fd in Path(f"/proc/{pid}/fd").iterdir()
              if os.readlink(fd).startswith("socket:[")}
    found = set()
    for line in Path("/proc/net/tcp").read_text().splitlines()[1:]:
        fields = line.split()
        if fields[3] == "0A" and fields[9] in inodes:
            raw = bytes.fromhex(fields[1].split(":")[0])[::-1]     # little-endian
            found.add(".".join(str(b) for b in raw))
    return found


def test_a_local_cluster_listens_on_the_loopback_only():
    """The scheduler, its dashboard and its workers (scenes on --jobs 2): nothing another
    machine can reach; the cluster and its workers end with close() (within 10 s)."""
    from yadebreak.process.scheduler import LocalCluster
    cluster = LocalCluster(1)
    try:
        family = [cluster._proc.pid]
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                if int(stat.read_text().rsplit(")", 1)[1].split()[1]) == cluster._proc.pid:
                    family.append(int(stat.parent.name))
            except (OSError, IndexError):
                continue
        addresses = set().union(*(listening_addresses(pid) for pid in family))
        assert addresses and addresses <= {"127.0.0.1"}, addresses
    finally:
        cluster.close()
    assert cluster._proc.poll() is not None

    def alive():            # multiprocessing's resource tracker leaves after its parent's exit
        def running(pid):
            try:
                return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
            except OSError:
                return False
        return [pid for pid in family[1:] if running(pid)]
    deadline = time.time() + 10
    while alive() and time.time() < deadline:
        time.sleep(0.1)
    assert alive() == []


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

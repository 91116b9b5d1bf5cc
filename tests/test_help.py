"""--help of every `python3 -m yadebreak` command and every script in scripts/: exit code 0 and the
options listed. In-process (the scripts' options through job_options, as the scripts read them),
but for three subprocesses: the module's and tradeoff's help as users run them, and
gather_sweep.py (plain Python)."""
import subprocess
from pathlib import Path

import pytest

from yadebreak import cli as cli
from yadebreak.jobs import options as job_options

ROOT = Path(__file__).resolve().parent.parent
PYTHON = "/usr/bin/python3"
COMMANDS = [*cli.COMMANDS, "tradeoff", "fit", "verify"]


def _help(capsys, read):
    with pytest.raises(SystemExit) as end:
        read()
    assert end.value.code in (0, None)
    return capsys.readouterr().out


def test_every_script_is_covered():
    assert {p.stem for p in (ROOT / "scripts").glob("*.py")} == set(job_options.JOBS) | {
        "gather_sweep"}


@pytest.mark.parametrize("job", sorted(job_options.JOBS))
def test_script_help(capsys, job):
    doc = (ROOT / "scripts" / f"{job}.py").read_text().split('"""')[1]
    said = _help(capsys, lambda: job_options.read(job, doc, ["--help"]))
    assert "--out" in said and "--debug" in said, said
    for p in job_options.JOBS[job].params():
        assert p.flag in said


@pytest.mark.parametrize("command", COMMANDS)
def test_command_help(capsys, command):
    said = _help(capsys, lambda: cli.main([command, "--help"]))
    assert f"{command}" in said and "--" in said, said


def test_help_of_the_module_and_of_tradeoff_and_gather_sweep_as_run():
    for command in ([PYTHON, "-m", "yadebreak", "--help"],
                    [PYTHON, "-m", "yadebreak", "tradeoff", "--help"],
                    [PYTHON, str(ROOT / "scripts" / "gather_sweep.py"), "--help"]):
        proc = subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=ROOT)
        assert proc.returncode == 0 and proc.stderr == "", (command, proc.stderr[-1000:])
        assert "--" in proc.stdout
    said = subprocess.run([PYTHON, "-m", "yadebreak", "tradeoff", "--help"], capture_output=True,
                          text=True, timeout=120, cwd=ROOT).stdout
    assert "with a 95 %\ninterval" in said                 # its usage's % as written
    assert "--quiet" in said                                # progress on stderr, silenced


def test_the_yadebreak_command_runs_debians_python_whichever_comes_first(tmp_path):
    """make deps installs `yadebreak` (as root /usr/local/bin, else ~/.local/bin): it runs
    /usr/bin/python3 -m yadebreak even where another python3 comes first on PATH."""
    import os
    import shutil
    command = shutil.which("yadebreak") or os.path.expanduser("~/.local/bin/yadebreak")
    assert os.access(command, os.X_OK), "make deps writes the yadebreak command"
    fake = tmp_path / "python3"
    fake.write_text("#!/bin/sh\necho 'No module named yadebreak' >&2\nexit 1\n")
    fake.chmod(0o755)
    env = {**os.environ, "PATH": f"{tmp_path}{os.pathsep}{os.environ.get('PATH', '')}"}
    said = subprocess.run([command, "materials"], capture_output=True, text=True, env=env,
                          timeout=120)
    assert said.returncode == 0 and "copper_ore" in said.stdout, said.stderr


def _description(said):
    """The paragraph between a help's usage and its first list of arguments."""
    lines = said.split("\n\n", 1)[1].split("\n")
    kept = []
    for line in lines:
        if line.startswith(("options:", "positional arguments:")):
            break
        kept.append(line)
    return " ".join(" ".join(kept).split())


@pytest.mark.parametrize("command", ["tradeoff", "fit", "verify"])
def test_a_commands_help_is_whole_and_names_the_yadebreak_command(capsys, command):
    """A description of several lines ends its sentence (verify's stopped at "at the paper's"),
    and the program is `yadebreak` (python, python3 and `python3 -m yadebreak` are gone)."""
    said = _help(capsys, lambda: cli.main([command, "--help"]))
    text = _description(said)
    assert text.endswith((".", ")")), text[-80:]
    assert said.startswith(f"usage: yadebreak {command}") and "python" not in said, said[:300]


@pytest.mark.yade
def test_yade_imported_into_plain_python_prints_nothing():
    """YADE's package prints "Using python version: ..." when imported outside its launcher
    (extremes.py's stray line): the adapter keeps it off stdout."""
    said = subprocess.run([PYTHON, "-c", "import yadebreak.adapter.yade_api"], capture_output=True,
                          text=True, timeout=120, cwd=ROOT)
    assert said.returncode == 0 and said.stdout == "", said.stdout + said.stderr[-500:]

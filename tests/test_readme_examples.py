"""The README's library examples run as written, from a user's own folder (issue 16).

Every ```python block that follows a line `<!-- example: library -->` in README.md is run with
`yade -n -x` in a temporary folder outside the repository, with no PYTHONPATH: `import yadebreak`
has to work there after the README's set-up (`make deps` writes yadebreak.pth naming the checkout).
"""
import os
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
MARK = "<!-- example: library -->"


def library_examples():
    """The marked examples' code, in README order."""
    text = (ROOT / "README.md").read_text()
    return re.findall(re.escape(MARK) + r"\s*```python\n(.*?)^```", text, re.S | re.M)


def _user_env():
    """The environment of a user's shell: nothing pointing at this checkout."""
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "YADEBREAK_MATERIALS")}


def test_the_readme_marks_its_library_examples():
    assert library_examples(), f"README.md has no ```python block after {MARK}"


@pytest.mark.yade
@pytest.mark.parametrize("k", range(len(library_examples())))
def test_library_example_runs_in_a_users_folder(k, tmp_path):
    found = subprocess.run(["/usr/bin/python3", "-c", "import yadebreak; print(yadebreak.__file__)"],
                           cwd=tmp_path, env=_user_env(), capture_output=True, text=True)
    assert found.returncode == 0, (
        "yadebreak is not importable outside the repository: run `make deps` (it writes "
        f"yadebreak.pth into Debian's site folder)\n{found.stderr[-1000:]}")
    where = Path(found.stdout.strip()).resolve().parent.parent
    assert where == ROOT, f"yadebreak is imported from {where}, not {ROOT}: run `make deps` here"

    script = tmp_path / f"example_{k}.py"
    script.write_text(library_examples()[k])
    proc = subprocess.run(["yade", "-n", "-x", script.name], cwd=tmp_path, env=_user_env(),
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    # what the example says it writes, in the user's folder
    for name in re.findall(r'"([\w.]+\.(?:jsonl|yade\.gz))"', library_examples()[k]):
        assert (tmp_path / name).exists(), name

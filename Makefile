# yadebreak: two commands do all set-up on a fresh Debian 12 machine (as root):
#   make demo   installs what is missing and runs the main job
#   make test   installs what is missing and runs the test suite
# Everything runs under /usr/bin/python3, the interpreter Debian's YADE uses.
PY := /usr/bin/python3
OUT ?= out

.PHONY: deps demo model-demo test test-model bench

# apt-get only when something is missing, so repeated runs start at once. Then `import yadebreak`
# is made to work from any folder (a user's own scenes) under /usr/bin/python3 and yade: see
# LINK_PACKAGE.
deps:
	@if ! command -v yade >/dev/null 2>&1 || ! $(PY) -c "import pytest, numpy, scipy, matplotlib, \
		dask, distributed, xdist; from yadebreak.adapter.yadepath import ensure_yade_importable as ok; \
		assert ok()" >/dev/null 2>&1; then \
		echo "[yadebreak] installing YADE and Python packages from Debian (a few minutes, once)"; \
		apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
			yade python3-yade python3-pytest python3-numpy python3-scipy python3-matplotlib \
			python3-dask python3-distributed python3-pytest-xdist; \
	fi
	@$(PY) -c "$$LINK_PACKAGE" "$(CURDIR)"

# A one-line yadebreak.pth naming this checkout, in the site folder of /usr/bin/python3 that pip
# would use (/usr/local/lib/python3.X/dist-packages as root, the user's own site folder otherwise):
# no pip, no network, no build files in the checkout; rewritten only when it names another folder.
# And the `yadebreak` command (/usr/local/bin as root, ~/.local/bin otherwise): /usr/bin/python3
# -m yadebreak, whichever python3 (pyenv, conda) comes first on PATH.
define LINK_PACKAGE
import os, site, sys
folder = site.getsitepackages()[0] if os.geteuid() == 0 else site.getusersitepackages()
path, line = os.path.join(folder, "yadebreak.pth"), sys.argv[1] + "\n"
if not os.path.exists(path) or open(path).read() != line:
    os.makedirs(folder, exist_ok=True)
    with open(path, "w") as f:
        f.write(line)
    print(f"[yadebreak] wrote {path}: import yadebreak now works from any folder")
folder = "/usr/local/bin" if os.geteuid() == 0 else os.path.expanduser("~/.local/bin")
path = os.path.join(folder, "yadebreak")
text = ("#!/bin/sh\n# written by yadebreak's make deps: Debian's python3, whichever comes first "
        "on PATH\nexec /usr/bin/python3 -m yadebreak \"$$@\"\n")
if not os.path.exists(path) or open(path).read() != text:
    os.makedirs(folder, exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, 0o755)
    on_path = folder in os.environ.get("PATH", "").split(os.pathsep)
    print(f"[yadebreak] wrote {path}: the yadebreak command"
          + ("" if on_path else f" (add {folder} to PATH)"))
endef
export LINK_PACKAGE

demo: deps
	yade -n -x scripts/bed_impact.py --out $(OUT)/bed_impact --overwrite 1

# The model alone (no YADE): breakage probability, t10 and progeny curves of a material.
model-demo:
	$(PY) -m yadebreak demo --out $(OUT)/model_demo --overwrite 1

test: deps
	$(PY) -m pytest -q -n auto tests

# The pure model tests need only numpy, scipy and pytest (no YADE).
test-model:
	$(PY) -m pytest -q tests -m "not yade"

bench: deps
	$(PY) benchmarks/bench_families.py
	$(PY) benchmarks/bench_engine.py
	$(PY) benchmarks/bench_energy.py

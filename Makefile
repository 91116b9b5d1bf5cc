# yadebreak: two commands do all set-up on a fresh Debian 12 machine (as root):
#   make demo   installs what is missing and runs the main job
#   make test   installs what is missing and runs the test suite
# Everything runs under /usr/bin/python3, the interpreter Debian's YADE uses.
PY := /usr/bin/python3
OUT ?= out

.PHONY: deps demo model-demo test test-model bench

# apt-get only when something is missing, so repeated runs start at once.
deps:
	@if ! command -v yade >/dev/null 2>&1 || ! $(PY) -c "import pytest, numpy, scipy, matplotlib; \
		from yadebreak.yadepath import ensure_yade_importable as ok; assert ok()" >/dev/null 2>&1; then \
		echo "[yadebreak] installing YADE and Python packages from Debian (a few minutes, once)"; \
		apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
			yade python3-yade python3-pytest python3-numpy python3-scipy python3-matplotlib; \
	fi

demo: deps
	yade -n -x scripts/bed_impact.py --out $(OUT)/bed_impact

# The model alone (no YADE): breakage probability, t10 and progeny curves of a material.
model-demo:
	$(PY) -m yadebreak demo --out $(OUT)/model_demo

test: deps
	$(PY) -m pytest -q tests

# The pure model tests need only numpy, scipy and pytest (no YADE).
test-model:
	$(PY) -m pytest -q tests -m "not yade"

bench: deps
	$(PY) benchmarks/bench_families.py
	$(PY) benchmarks/bench_engine.py
	$(PY) benchmarks/bench_energy.py

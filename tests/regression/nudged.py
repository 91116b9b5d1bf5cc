"""Run a script with its initial state changed in the last bit, as another CPU would round it
(tests only: tests/regression/cases.py runs it; not part of the package).

    yade -n -x tests/regression/nudged.py SEED scripts/NAME.py [options ...]

When the script's scene is built, just before the breakage model is attached to it (each scene
builder of yadebreak/scenes/ calls attach() last), every non-zero component of every dynamic
body's position and velocity moves by one unit in the last place (np.nextafter), up or down as
drawn from numpy.random.default_rng(SEED). A position of 2.75e-3 m moves by 4e-19 m: a difference
of the size another CPU's rounding (libm, SIMD sums) makes in the first steps.
"""
import sys
from pathlib import Path

import numpy as np


def nudging(attach, seed, omega):
    """attach() that first moves every dynamic body's position and velocity by one ulp; its
    `count` lists the scenes nudged (names kept local: the script runs in this namespace)."""
    rng = np.random.default_rng(seed)

    def last_bit(vector):
        """`vector` with each non-zero component one ulp up or down (zeros stay: no denormals)."""
        x = np.array(tuple(vector), dtype=float)
        away = np.where(rng.random(3) < 0.5, -np.inf, np.inf)
        return tuple(float(v) for v in np.where(x != 0.0, np.nextafter(x, away), x))

    def nudged_attach(*args, **kwargs):
        nudged_attach.count.append(len(omega.bodies))
        for b in omega.bodies:     # the scene of this call (O.reset() makes a new one)
            if b is not None and b.dynamic:
                b.state.pos = last_bit(b.state.pos)
                b.state.vel = last_bit(b.state.vel)
        return attach(*args, **kwargs)

    nudged_attach.count = []
    return nudged_attach


def run(seed, script, *options):
    """Run `script` with `options` as yade would (in __main__'s namespace, where YADE keeps its
    engines' labels), every scene nudged; exit with a message if it built none."""
    sys.argv = [script, *options]
    sys.path.insert(0, str(Path(script).resolve().parent.parent))
    from yadebreak.scenes import beds, impacts
    from yadebreak.adapter.yade_api import O
    hook = nudging(impacts.attach, int(seed), O)
    impacts.attach = beds.attach = hook               # looked up at each call
    main = sys.modules["__main__"].__dict__
    main["__file__"] = script
    exec(compile(Path(script).read_text(), script, "exec"), main)
    if not hook.count:
        sys.exit(f"nudged.py: {script} built no scene through yadebreak.scenes: nothing nudged")


run(*sys.argv[1:])

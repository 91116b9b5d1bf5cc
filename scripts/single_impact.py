"""Single impacts on a plate: breakage probability and progeny size against the model.

The paper's Figs. 8-10 and 13-16: N particles of one material and size fired normally at a plate
at each specific energy Ek/mp = v^2/2. Writes summary.json and single_impact.png into --out.

    yade -n -x scripts/single_impact.py --material copper_ore --energies 100,200,400
    yade -n -x scripts/single_impact.py --material ab_t10_ore --energies 250,400,800 --particles 100

Each energy's particles are fired in independent scenes of --scene-particles (seeded from --seed +
the energy's index): a scene runs at the time step of its own finest fragment and ends with its
own cascade. An interrupted run continues with --resume 1, keeping the energies it finished
(out/partial.json); a run that fails leaves summary.json with the energies it finished and its
end_reason.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

from yadebreak.jobs import options as job_options  # noqa: E402

args = job_options.read("single_impact", __doc__)

from yadebreak.jobs import impacts  # noqa: E402
from yadebreak.jobs.lifecycle import run_script  # noqa: E402

brk = run_script(impacts.single, args)      # the last scene's controller, at the prompt without -x

"""Where modules of earlier versions went. `import yadebreak.tools.lifecycle` keeps working for
one release, with a DeprecationWarning naming the new module; the old name is then an alias of
the new module (the same object)."""
import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module -> module today (a package's old name maps its submodules too)
MOVED = {
    "yadebreak.model.reports": "yadebreak.analysis.reports",
    "yadebreak.coupling.yade_api": "yadebreak.adapter.yade_api",
    "yadebreak.coupling.yadepath": "yadebreak.adapter.yadepath",
    "yadebreak.coupling.controller": "yadebreak.engine.controller",
    "yadebreak.coupling.contacts": "yadebreak.engine.contacts",
    "yadebreak.coupling.judging": "yadebreak.engine.judging",
    "yadebreak.coupling.state": "yadebreak.engine.state",
    "yadebreak.coupling.replacement": "yadebreak.engine.replacement",
    "yadebreak.coupling.zeroing": "yadebreak.engine.zeroing",
    "yadebreak.coupling.stepping": "yadebreak.engine.stepping",
    "yadebreak.coupling.scene_materials": "yadebreak.engine.materials",
    "yadebreak.coupling.criteria": "yadebreak.criteria",
    "yadebreak.criteria.engine_side": "yadebreak.criteria",
    "yadebreak.coupling.config": "yadebreak.options.table",
    "yadebreak.tools.options": "yadebreak.options.flags",
    "yadebreak.tools.lifecycle": "yadebreak.jobs.lifecycle",
    "yadebreak.tools.sweep": "yadebreak.studies.sweep",
    "yadebreak.tools.tradeoff": "yadebreak.studies.tradeoff",
    "yadebreak.tools.bed_report": "yadebreak.studies.bed_report",
    "yadebreak.tools.calibration": "yadebreak.studies.calibration",
    "yadebreak.tools.grinding": "yadebreak.studies.grinding",
    "yadebreak.studies.grinding.spectra": "yadebreak.model.spectra",
    "yadebreak.studies.grinding.capture": "yadebreak.model.capture",
    "yadebreak.tools": "yadebreak.studies",
    "yadebreak.runs.verify": "yadebreak.studies.verify",
    "yadebreak.runs.job_options": "yadebreak.jobs.options",
    "yadebreak.runs": "yadebreak.jobs",
}


def today(name):
    """The module's name today, or None if it did not move."""
    for old in sorted(MOVED, key=len, reverse=True):
        if name == old or name.startswith(old + "."):
            return MOVED[old] + name[len(old):]
    return None


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old name and loads it as the module of today (no copy: one module object)."""

    def find_spec(self, name, path=None, target=None):
        new = today(name)
        return importlib.util.spec_from_loader(name, self) if new else None

    def create_module(self, spec):
        new = today(spec.name)
        warnings.warn(f"{spec.name} is now {new}; the old name goes in the next release",
                      DeprecationWarning, stacklevel=3)
        module = importlib.import_module(new)
        self._spec = module.__spec__      # the import system sets the old name's spec on it
        return module

    def exec_module(self, module):
        """The module of today is already executed: only its own spec is put back."""
        module.__spec__ = self._spec


def install():
    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.insert(0, _Alias())

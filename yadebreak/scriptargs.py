"""Parameters of scripts: `--name value` on the command line, or a yade-batch table row.

    args = script_params(dict(material="copper_ore", size=5.5e-3, out="out/x"), __doc__)

Under yade-batch (YADE_BATCH set), yade.utils.readParamsFromTable supplies the values; otherwise
argparse reads sys.argv. Types follow the defaults. Never imports yade unless yade-batch runs it.
"""
import argparse
import os
import sys


def script_params(defaults, description=None, argv=None):
    if os.environ.get("YADE_BATCH"):
        from yade import O, utils
        utils.readParamsFromTable(noTableOk=True, **defaults)
        from yade.params import table      # exists once the row has been read
        values = {k: getattr(table, k) for k in defaults}
        description = O.tags["description"] if "description" in O.tags.keys() else None
        if "out" in defaults and values["out"] == defaults["out"] and description:
            values["out"] = str(os.path.join(os.path.dirname(defaults["out"]) or ".", "sweep",
                                             description))
        return argparse.Namespace(**values)
    parser = argparse.ArgumentParser(description=description,
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    for name, value in defaults.items():
        flag = "--" + name.replace("_", "-")
        if isinstance(value, bool):
            parser.add_argument(flag, dest=name, type=lambda s: s.lower() in ("1", "true", "yes"),
                                default=value, metavar="0|1")
        else:
            parser.add_argument(flag, dest=name, type=type(value) if value is not None else str,
                                default=value)
    args = sys.argv[1:] if argv is None else argv
    return parser.parse_args(args)


class ScriptError(ValueError):
    """A user's mistake that a script reports in one line (exit code 2), e.g. a resume with other
    arguments."""


class StopRequested(Exception):
    """--stop-after: the script ends here, as if killed (tests of --resume)."""


def run_script(main, *args):
    """Run a script's main(*args): a user's mistake (a bad material file, option or resume)
    becomes one line on stderr and exit code 2, as argparse does; --stop-after ends with 0.
    The one place where scripts turn exceptions into exit codes."""
    from .coupling.config import AttachError
    from .materials import MaterialError
    try:
        return main(*args)
    except StopRequested:
        raise SystemExit(0) from None
    except MaterialError as exc:
        message = f"{exc.source}: " + "; ".join(exc.problems)
    except (ScriptError, AttachError, FileNotFoundError) as exc:
        message = str(exc)
    print(f"[yadebreak] error: {message}", file=sys.stderr, flush=True)
    raise SystemExit(2)


def progress(message):
    """One line of progress, flushed at once (long runs print these)."""
    print(f"[yadebreak] {message}", flush=True)


def resume_arguments(args):
    """The arguments that decide a run's results (not --resume, --stop-after or --out): what a
    resumed run must share with the one it continues."""
    return {k: v for k, v in sorted(vars(args).items())
            if k not in ("resume", "out", "stop_after")}


def check_resume_arguments(saved, args, path):
    """Refuse to resume, naming the arguments that differ, when `saved` (resume_arguments of the
    interrupted run, stored at `path`) are not this run's."""
    now = resume_arguments(args)
    if saved != now:
        changed = sorted(k for k in set(saved) | set(now) if saved.get(k) != now.get(k))
        raise ScriptError(f"--resume: {path} was written with other values of {changed}; run "
                          "again without --resume or with the same values")


def stop_if_asked(args, units_done):
    """--stop-after N: end the script here, as if killed, once N units are done (tests)."""
    if getattr(args, "stop_after", 0) and units_done >= args.stop_after:
        raise StopRequested()


class PartialResults:
    """Results a script has finished, kept in <out>/partial.json as it goes, so that `--resume 1`
    skips what an interrupted run completed. Each unit of work (an energy) must depend only on the
    arguments and its own seed, so that resuming gives what an uninterrupted run gives.

        partial = PartialResults(out, args)          # args.resume decides
        for k, energy in partial.todo(energies):     # the units not done yet
            partial.add(energy, compute(k, energy))  # stops here with --stop-after
        results = partial.ordered(energies)
    """

    def __init__(self, out, args):
        import json
        from pathlib import Path
        self.path = Path(out) / "partial.json"
        self.args = args
        self.done = {}
        if getattr(args, "resume", False) and self.path.exists():
            data = json.loads(self.path.read_text())
            check_resume_arguments(data["arguments"], args, self.path)
            self.done = data["done"]
            progress(f"resuming: {len(self.done)} finished unit(s) kept from {self.path}")

    def todo(self, keys):
        """(index, key) of the units not done yet, in order."""
        return [(k, key) for k, key in enumerate(keys) if str(key) not in self.done]

    def ordered(self, keys):
        """Every unit's result, in the order of `keys`."""
        return [self.done[str(key)] for key in keys]

    def add(self, key, result):
        import json
        import os
        self.done[str(key)] = result
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"arguments": resume_arguments(self.args), "done": self.done}))
        os.replace(tmp, self.path)
        stop_if_asked(self.args, len(self.done))

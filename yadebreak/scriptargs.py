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


def progress(message):
    """One line of progress, flushed at once (long runs print these)."""
    print(f"[yadebreak] {message}", flush=True)


class PartialResults:
    """Results a script has finished, kept in <out>/partial.json as it goes, so that `--resume 1`
    skips what an interrupted run completed. Each unit of work (an energy) must depend only on the
    arguments and its own seed, so that resuming gives what an uninterrupted run gives.

        partial = PartialResults(out, args)          # args.resume decides
        for energy in energies:
            result = partial.get(energy) or compute(energy)
            partial.add(energy, result)
    """

    def __init__(self, out, args):
        import json
        from pathlib import Path
        self.path = Path(out) / "partial.json"
        self.arguments = {k: v for k, v in sorted(vars(args).items())
                          if k not in ("resume", "out", "stop_after")}
        self.done = {}
        if getattr(args, "resume", False) and self.path.exists():
            data = json.loads(self.path.read_text())
            if data["arguments"] != self.arguments:
                changed = sorted(k for k in set(data["arguments"]) | set(self.arguments)
                                 if data["arguments"].get(k) != self.arguments.get(k))
                raise SystemExit(f"--resume: {self.path} was written with other values of "
                                 f"{changed}; run again without --resume or with the same values")
            self.done = data["done"]
            progress(f"resuming: {len(self.done)} finished unit(s) kept from {self.path}")

    def get(self, key):
        return self.done.get(str(key))

    def add(self, key, result):
        import json
        import os
        self.done[str(key)] = result
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"arguments": self.arguments, "done": self.done}))
        os.replace(tmp, self.path)

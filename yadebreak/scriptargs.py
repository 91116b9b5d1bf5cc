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

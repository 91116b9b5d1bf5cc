"""The one module of yadebreak that imports yade (from Debian's python3 too: see
yadebreak.adapter.yadepath). The coupling, scenes and runs take YADE's names from here."""
import contextlib
import io
import sys

from yadebreak.adapter.yadepath import ensure_yade_importable

ensure_yade_importable()

if "yade" not in sys.modules:          # imported into plain Python (jobs, tests, verify workers):
    with contextlib.redirect_stdout(io.StringIO()) as said:     # YADE's package says
        import yade                    # noqa: F401,E402  "Using python version: ..." on stdout
    sys.stdout.write("".join(line for line in said.getvalue().splitlines(True)
                             if not line.startswith("Using python version")))

import numpy as np  # noqa: E402
import yade.wrapper as wrapper  # noqa: E402
from yade import Matrix3, O, Quaternion, Vector3, geom, utils  # noqa: E402

__all__ = ["Matrix3", "O", "Quaternion", "Vector3", "close_remote_access", "current_scene", "extend_match_makers",
           "engine_time", "find_engine", "geom", "interaction_counts", "scene_folder", "table_row",
           "utils", "wrapper"]


def interaction_counts():
    """Each body's count of real interactions, by id (YADE's numIntrsOfEachBody, one pass in C++
    over every potential interaction), as a numpy array. Taken through bytes while every count
    is below 256, as a cloud's are: on 8,000 bodies a tenth of np.fromiter's 150 us; a body with
    more (a wall under a bed) falls back to fromiter."""
    real = utils.numIntrsOfEachBody()
    try:
        return np.frombuffer(bytes(real), np.uint8)
    except ValueError:
        return np.fromiter(real, np.int64, len(real))


def find_engine(label):
    """The engine of O.engines with this label, or None."""
    return next((e for e in O.engines if getattr(e, "label", "") == label), None)


class engine_time:
    """The time YADE's own engines take in a block, as YADE times them (O.timingEnabled: on for
    the block, then as it was), yadebreak's runners (PyRunners) left out; O.engines is set before
    the block. `with engine_time() as t: O.run(...)`, then t.seconds (s)."""

    def __enter__(self):
        self._was, self.seconds = O.timingEnabled, 0.0
        self._before = self._own()
        O.timingEnabled = True
        return self

    def __exit__(self, *exc):
        self.seconds = 1e-9 * (self._own() - self._before)
        O.timingEnabled = self._was
        return False

    @staticmethod
    def _own():
        return sum(e.execTime for e in O.engines if not isinstance(e, wrapper.PyRunner))


def table_row(defaults):
    """A yade-batch table row's values for these options ({name: default}; readParamsFromTable)
    and the row's description (None outside a batch)."""
    utils.readParamsFromTable(noTableOk=True, **defaults)
    from yade.params import table      # exists once the row has been read
    description = O.tags["description"] if "description" in O.tags.keys() else None
    return {k: getattr(table, k) for k in defaults}, description


def current_scene():
    """The scene YADE runs now: equal (==) to an earlier result until O.reset() or O.load()
    replaces it (a new scene, whatever its contents)."""
    return O._sceneObj


def scene_folder():
    """The folder of the file the current scene was last saved to or loaded from (absolute), or
    None for a scene never saved nor loaded: a saved run's own files are named relative to it."""
    import os
    name = O.filename
    return os.path.dirname(os.path.abspath(name)) if name else None


def close_remote_access():
    """Close the two servers that the `yade` launcher starts at every start, `yade -n` included
    (not `import yade`): a TCP Python prompt (port 9000 or up) guarded by a six-letter cookie
    printed in the log, and an XMLRPC info server (21000 or up) with no guard that can pause the
    run. The launcher says "localhost" but both listen on every interface. Returns the ports
    closed (none outside the launcher)."""
    import gc
    import socketserver
    import threading
    ports = []
    for server in [o for o in gc.get_objects() if isinstance(o, socketserver.BaseServer)]:
        stopping = threading.Thread(target=server.shutdown, daemon=True)  # waits for its loop
        stopping.start()
        stopping.join(2.0)
        server.server_close()
        ports.append(server.server_address[1])
    return sorted(ports)


def silence_polyhedra_pair_checks():
    """Silence YADE's warnings from its polyhedra geometry (the logger of Polyhedra_support.cpp,
    below ERROR, for this process): "Unhandled switch case:0, function do_intersect" comes at
    every step for every pair of polyhedra whose bounding boxes overlap without touching,
    hundreds a step in a fragment cloud (engine/contacts/volumetric.PairChecks counts them)."""
    from yade import log
    log.setLevel("Polyhedra_support.cpp", log.ERROR)


def extend_match_makers(loop, more_rows):
    """Give every MatchMaker of the InteractionLoop's Ip2 functors (per-pair values such as
    `en`, `es`) the rows `more_rows(rows)` returns for its rows [(id_a, id_b, value)]. YADE's
    MatchMaker cannot be changed in place: each is replaced by an extended one, through the
    functor's own attribute."""
    for functor in loop.physDispatcher.functors:
        for name, value in functor.dict().items():
            if isinstance(value, wrapper.MatchMaker):
                rows = [tuple(m) for m in value.matches]
                setattr(functor, name, wrapper.MatchMaker(
                    matches=rows + more_rows(rows), algo=value.algo, val=value.val))

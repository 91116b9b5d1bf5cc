"""The one module of yadebreak that imports yade (from Debian's python3 too: see
yadebreak.coupling.yadepath). The coupling, scenes and runs take YADE's names from here."""
from .yadepath import ensure_yade_importable

ensure_yade_importable()

import yade.wrapper as wrapper  # noqa: E402
from yade import O, Vector3, geom, utils  # noqa: E402

__all__ = ["O", "Vector3", "find_engine", "geom", "table_row", "utils", "wrapper"]


def find_engine(label):
    """The engine of O.engines with this label, or None."""
    return next((e for e in O.engines if getattr(e, "label", "") == label), None)


def table_row(defaults):
    """A yade-batch table row's values for these options ({name: default}; readParamsFromTable)
    and the row's description (None outside a batch)."""
    utils.readParamsFromTable(noTableOk=True, **defaults)
    from yade.params import table      # exists once the row has been read
    description = O.tags["description"] if "description" in O.tags.keys() else None
    return {k: getattr(table, k) for k in defaults}, description

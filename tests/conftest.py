import pytest

from yadebreak.adapter.yadepath import ensure_yade_importable

HAVE_YADE = ensure_yade_importable()


def pytest_collection_modifyitems(config, items):
    if HAVE_YADE:
        return
    skip = pytest.mark.skip(reason="YADE is not installed (make test installs it)")
    for item in items:
        if "yade" in item.keywords:
            item.add_marker(skip)


@pytest.fixture
def scene():
    """A fresh YADE scene (one Omega per process) and a clean yadebreak registry."""
    from yade import O
    from yadebreak import engine
    engine.forget()
    O.reset()
    yield O
    engine.forget()
    O.reset()

"""Files written whole or not at all: a full disk or a kill leaves the old content or the new,
never part of it."""
import os
from pathlib import Path


def append_whole(path, text):
    """Append `text` to `path` whole or not at all: a write that fails (a full disk) cuts the
    file back to its size before (cutting needs no space), then the error goes on."""
    path = Path(path)
    size = path.stat().st_size if path.exists() else 0
    try:
        with open(path, "a") as f:
            f.write(text)
    except OSError:
        if path.exists():
            os.truncate(path, size)
        raise


def write_atomic(path, text):
    """Write `text` to `path` whole or not at all (write_whole)."""
    write_whole(path, lambda tmp: tmp.write_text(text))


def write_whole(path, write):
    """write(tmp) to a temporary file beside `path`, then os.replace: `path` holds the old
    content or the new, never part of it (a full disk, a kill); the temporary file is removed if
    the write fails."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def save_figure(fig, path, **options):
    """fig.savefig(path, **options) whole or not at all (write_whole; the format from the
    path's suffix)."""
    path = Path(path)
    write_whole(path, lambda tmp: fig.savefig(tmp, format=path.suffix.lstrip(".") or None,
                                              **options))

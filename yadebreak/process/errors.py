"""An error in one line, as scripts and logs say it."""
import errno
import re


def first_line(exc):
    """The first line of an error's message ('' if it has none): YADE's errors run to several."""
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else ""


def error_line(exc):
    """An error in one line: a full disk as its OSError (YADE wraps an error raised in a PyRunner
    in a RuntimeError of several lines), anything else as 'Type: first line'."""
    if disk_full(exc):
        if isinstance(exc, OSError):
            return f"OSError: {exc}"
        found = re.search(r"\[Errno (?:28|122)\][^\n]*", str(exc))
        return f"OSError: {found.group(0).strip()}" if found else first_line(exc)
    return f"{type(exc).__name__}: {first_line(exc)}"


def disk_full(exc):
    """True if `exc` is a full disk or an exceeded quota (ENOSPC, EDQUOT), also when YADE has
    wrapped it in a PyRunner's RuntimeError."""
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return True
    return isinstance(exc, RuntimeError) and bool(re.search(r"\[Errno (?:28|122)\]", str(exc)))

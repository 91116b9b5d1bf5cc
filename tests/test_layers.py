"""The rooms of docs/architecture.md are the rooms the imports keep. Each room may import the rooms
named in ALLOWED (and itself); a study may reach the engine, scenes and jobs only inside a function
(verify runs scenes; sweeps and trade-offs run scripts in other processes):

    model/     the breakage model in numpy/scipy            nothing of yadebreak outside it
    criteria/  one class per criterion                      model
    options/   the option table, the flags of scripts       model, criteria
    analysis/  results against the model, plots             model, criteria
    process/   errors in one line, signals, whole files       nothing (every room may use it)
    adapter/   the one module that imports yade             nothing
    engine/    the engine and its parts in YADE's loop      model, criteria, options, analysis, adapter
    scenes/    every builder of a YADE scene                 ... and engine
    jobs/      the jobs behind scripts/, their lifecycle    ... and scenes, never adapter
    studies/   verify, calibration, grinding, sweeps        model, criteria, options, analysis, jobs
    coupling/  saved scenes' entry points, forwarding       engine
    cli.py     python3 -m yadebreak                         all but adapter
"""
import ast
import subprocess
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "yadebreak"
PURE = {"model", "criteria", "options", "analysis", "process"}
ALLOWED = {
    "process": {"process"},
    "model": {"model", "process"},
    "criteria": {"model", "criteria", "process"},
    "options": {"model", "criteria", "options", "process"},
    "analysis": {"model", "criteria", "analysis", "process"},
    "adapter": {"adapter", "process"},
    "engine": PURE | {"adapter", "engine"},
    "scenes": PURE | {"adapter", "engine", "scenes"},
    "jobs": PURE | {"engine", "scenes", "jobs"},
    "studies": PURE | {"jobs", "studies"},
    "coupling": {"engine", "coupling", "process"},
    "cli": PURE | {"engine", "scenes", "jobs", "studies", "cli"},
}
#: what a study may import inside a function (it runs scenes in its own process or others)
LATE = {"studies": {"engine", "scenes"}}
ROOMS = sorted(ALLOWED)


def _imports(path):
    """(module imported, at module level?) of every import in a file, relative ones resolved."""
    tree = ast.parse(path.read_text())
    package = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1])
    top = {id(n) for n in tree.body} | {id(c) for n in tree.body if isinstance(n, ast.Try)
                                         for c in n.body}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, id(node) in top
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            names = [f"{base}.{a.name}" for a in node.names] if base in (
                "yadebreak", *(f"yadebreak.{room}" for room in ROOMS)) else [base]
            for name in names:
                yield name, id(node) in top


def _room_of(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "yadebreak" and parts[1] in ROOMS else None


def _files(room):
    single = PACKAGE / f"{room}.py"
    return [single] if single.exists() else sorted((PACKAGE / room).rglob("*.py"))


@pytest.mark.parametrize("room", ROOMS)
def test_each_room_imports_only_the_rooms_it_may(room):
    wrong = []
    for path in _files(room):
        for module, top_level in _imports(path):
            other = _room_of(module)
            allowed = ALLOWED[room] | (set() if top_level else LATE.get(room, set()))
            if other and other not in allowed:
                wrong.append(f"{path.relative_to(PACKAGE)} imports {module}")
    assert not wrong, "\n".join(wrong)


def test_every_module_lies_in_a_room():
    loose = [p.name for p in PACKAGE.glob("*.py")
             if p.stem not in ROOMS and p.name not in ("__init__.py", "__main__.py", "_moved.py")]
    folders = [p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()
               and p.name not in ROOMS]
    assert not loose and not folders, (loose, folders)


def test_only_the_adapter_imports_yade():
    found = [f"{path.relative_to(PACKAGE)} imports {module}"
             for path in sorted(PACKAGE.rglob("*.py"))
             for module, _ in _imports(path)
             if (module == "yade" or module.startswith("yade."))
             and path != PACKAGE / "adapter" / "yade_api.py"]
    assert not found, "\n".join(found)


def test_the_pure_rooms_load_without_yade():
    """Every module of the pure rooms, the studies, the jobs' lifecycle and options, and the
    command line, imported in a fresh /usr/bin/python3, leaves yade out of sys.modules (a user's
    laptop without YADE can fit data and grind)."""
    paths = [p for room in sorted(PURE | {"studies"}) for p in _files(room)]
    paths += [PACKAGE / "jobs" / "lifecycle.py", PACKAGE / "jobs" / "options.py",
              PACKAGE / "cli.py"]
    modules = [".".join(p.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
               for p in paths]
    code = ("import importlib, sys\n"
            f"for m in {modules!r}: importlib.import_module(m)\n"
            "print(sorted(m for m in sys.modules if m == 'yade' or m.startswith('yade.')))")
    proc = subprocess.run(["/usr/bin/python3", "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=PACKAGE.parent)
    assert proc.returncode == 0, proc.stderr[-1500:]
    assert proc.stdout.strip().splitlines()[-1] == "[]"


def _sizes():
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                yield path, node, node.end_lineno - node.lineno + 1


def test_no_class_over_300_lines_and_no_function_over_80():
    big = [f"{path.relative_to(PACKAGE)}: {node.name} has {n} lines" for path, node, n in _sizes()
           if n > (300 if isinstance(node, ast.ClassDef) else 80)]
    assert not big, "\n".join(big)


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def _names(target):
    """The names an assignment's target binds (x, (x, y), *x)."""
    if isinstance(target, ast.Name):
        yield target.id
    elif isinstance(target, (ast.Tuple, ast.List)):
        for element in target.elts:
            yield from _names(element)
    elif isinstance(target, ast.Starred):
        yield from _names(target.value)


def _binds(node):
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return {node.name}
    targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
        node, (ast.AnnAssign, ast.AugAssign)) else []
    return {name for target in targets for name in _names(target)}


def _module_level(body):
    """A module's own statements, also those inside its if, try and with blocks."""
    for node in body:
        yield node
        if isinstance(node, (ast.If, ast.Try, ast.With)):
            for block in (node.body, getattr(node, "orelse", []), getattr(node, "finalbody", []),
                          *(h.body for h in getattr(node, "handlers", []))):
                yield from _module_level(block)


def _private_names(tree):
    """The _-names a module defines: its functions, classes and assignments at module level, and
    in its classes their methods, class attributes and self._x (cls._x) attributes."""
    found = {name for node in _module_level(tree.body) for name in _binds(node)}
    for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef)):
        found |= {name for node in cls.body for name in _binds(node)}
        found |= {n.attr for n in ast.walk(cls) if isinstance(n, ast.Attribute)
                  and isinstance(n.ctx, ast.Store) and isinstance(n.value, ast.Name)
                  and n.value.id in ("self", "cls")}
    return {name for name in found if _private(name)}


def _module(path):
    return ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")


def _private_crossings(path, owners):
    """Where a module imports another yadebreak module's _-name (a package's __init__ may, from
    its own package) or reaches it as obj._x (self and cls are its own; a name this module also
    defines, or no yadebreak module does, such as os._exit, is not another's)."""
    tree = ast.parse(path.read_text())
    module, where = _module(path), path.relative_to(PACKAGE.parent)
    package = ".".join(where.parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            own = path.name == "__init__.py" and (base + ".").startswith(package + ".")
            if base.split(".")[0] == "yadebreak" and not own:
                yield from (f"{where}:{node.lineno} {alias.name} (defined in {base})"
                            for alias in node.names if _private(alias.name))
        elif (isinstance(node, ast.Attribute) and _private(node.attr)
              and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            others = owners.get(node.attr, set())
            if others and module not in others:
                yield f"{where}:{node.lineno} {node.attr} (defined in {', '.join(sorted(others))})"


def test_no_private_name_crosses_modules():
    """A _-name is the business of the module that defines it: no other module imports it or
    calls it, so that module may change it without breaking another (a package's __init__ may
    re-export its own modules' names)."""
    paths = sorted(PACKAGE.rglob("*.py"))
    owners = {}
    for path in paths:
        for name in _private_names(ast.parse(path.read_text())):
            owners.setdefault(name, set()).add(_module(path))
    wrong = [line for path in paths for line in _private_crossings(path, owners)]
    assert not wrong, ("another module's _-name: give it a public spelling in the module that "
                       "defines it, or move the code that needs it into that module:\n"
                       + "\n".join(wrong))

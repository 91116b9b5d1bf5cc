"""The layers the tree shows (docs/architecture.md) are the layers the imports keep:

    model/    imports nothing of yadebreak outside model/ (and never yade)
    tools/    imports model/ and tools/ at module level; YADE only through a function that runs
              inside a yade-batch row (tools/options.py) or in separate processes
    coupling/ imports model/ and coupling/; yade only in coupling/yade_api.py
    scenes/   model/, tools/, coupling/, scenes/
    runs/     anything below it
"""
import ast
import subprocess
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "yadebreak"
LAYERS = ["model", "tools", "coupling", "scenes", "runs"]
ALLOWED = {"model": {"model"}, "tools": {"model", "tools"}, "coupling": {"model", "coupling"},
           "scenes": {"model", "tools", "coupling", "scenes"},
           "runs": {"model", "tools", "coupling", "scenes", "runs"}}


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
                "yadebreak", *(f"yadebreak.{layer}" for layer in LAYERS)) else [base]
            for name in names:
                yield name, id(node) in top


def _layer_of(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "yadebreak" and parts[1] in LAYERS else None


@pytest.mark.parametrize("layer", LAYERS)
def test_each_layer_imports_only_the_layers_below_it(layer):
    wrong = []
    for path in sorted((PACKAGE / layer).rglob("*.py")):
        for module, top_level in _imports(path):
            other = _layer_of(module)
            if other and other not in ALLOWED[layer] and (top_level or layer != "tools"):
                wrong.append(f"{path.relative_to(PACKAGE)} imports {module}")
            if layer == "model" and other not in (None, "model"):
                wrong.append(f"{path.relative_to(PACKAGE)} imports {module}")
    assert not wrong, "\n".join(wrong)


def test_only_yade_api_imports_yade():
    found = [f"{path.relative_to(PACKAGE)} imports {module}"
             for path in sorted(PACKAGE.rglob("*.py"))
             for module, _ in _imports(path)
             if (module == "yade" or module.startswith("yade."))
             and path != PACKAGE / "coupling" / "yade_api.py"]
    assert not found, "\n".join(found)


def test_the_pure_layers_load_without_yade():
    """Every module of model/ and tools/ imported in a fresh /usr/bin/python3 leaves yade out of
    sys.modules (a user's laptop without YADE can fit data and grind)."""
    modules = [".".join(p.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
               for layer in ("model", "tools") for p in sorted((PACKAGE / layer).rglob("*.py"))]
    code = ("import importlib, sys\n"
            f"for m in {modules!r}: importlib.import_module(m)\n"
            "print(sorted(m for m in sys.modules if m == 'yade' or m.startswith('yade.')))")
    proc = subprocess.run(["/usr/bin/python3", "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=PACKAGE.parent)
    assert proc.returncode == 0, proc.stderr[-1500:]
    assert proc.stdout.strip().splitlines()[-1] == "[]"

"""docs/outputs.md documents every field the scripts write (issue 16), so it cannot fall behind:
a tiny bed impact (Tavares) and a tiny single impact (Ab-T10) run as users run them, and every
name in their summary.json (as dotted paths, see the doc), every field of every event kind in
their event logs and every array of the ParaView frames must be listed in the doc's section for
it (a table row starting with the backquoted name)."""
import json
import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "outputs.md"


def sections():
    """{heading: names in the first column of its tables} of docs/outputs.md."""
    found, heading = {}, ""
    for line in DOC.read_text().splitlines():
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
            found[heading] = set()
        elif line.startswith("| `"):
            found[heading] |= set(re.findall(r"`([^`]+)`", line.split("|")[1]))
    return found


def documented(word):
    """The names of the one section whose heading contains `word`."""
    matches = [names for heading, names in sections().items() if word in heading]
    assert len(matches) == 1, f"docs/outputs.md: {len(matches)} headings contain {word!r}"
    return matches[0]


def dotted(value, path=""):
    """The leaf names of a JSON value as the doc writes them: a.b, results[].b, tN for t2...t25."""
    if isinstance(value, dict) and value:
        names = set()
        for key, item in value.items():
            if path.endswith("progeny_markers") and re.fullmatch(r"t\d+", key):
                key = "tN"
            names |= dotted(item, f"{path}.{key}" if path else key)
        return names
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return set().union(*(dotted(v, path + "[]") for v in value))
    return {path}


def test_dotted_names():
    summary = {"a": 1, "results": [{"b": [1.0], "progeny_markers": {"t2": {"model": None}}}]}
    assert dotted(summary) == {"a", "results[].b", "results[].progeny_markers.tN.model"}


def test_class_codes_are_the_engines():
    from yadebreak.engine.state import KINDS
    rows = re.findall(r"^\| (\d+) \| `(\w+)` \|", DOC.read_text(), re.M)
    assert [(int(code), kind) for code, kind in rows] == list(enumerate(KINDS))


def _run(script, out, *arguments):
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / f"{script}.py"),
                           "--out", str(out), *arguments],
                          capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads((out / "summary.json").read_text())


def _undocumented_event_fields(paths):
    common = documented("Every event")
    missing, kinds = set(), set()
    for path in paths:
        for line in path.read_text().splitlines():
            event = json.loads(line)
            kinds.add(event["kind"])
            missing |= {f"{event['kind']}: {name}" for name in event
                        if name not in common | documented(f"`{event['kind']}`")}
    return missing, kinds


@pytest.mark.yade
def test_bed_impact_outputs_are_documented(tmp_path):
    out = tmp_path / "bed"
    summary = _run("bed_impact", out, "--rings", "1", "--energy", "0.9", "--seed", "5")
    assert dotted(summary) - documented("`bed_impact.py`") == set()
    missing, kinds = _undocumented_event_fields([out / "events.jsonl"])
    assert missing == set() and {"breakage", "damage"} <= kinds
    frames = out / "paraview"
    for name in ("spheres_0000.vtp", "surfaces_0000.vtp"):
        arrays = {a.get("Name") for a in ET.parse(frames / name).getroot().iter("DataArray")}
        arrays -= {None, "connectivity", "offsets"}            # VTK's own
        assert arrays and arrays - documented("ParaView series") == set(), name


@pytest.mark.yade
def test_single_impact_outputs_are_documented(tmp_path):
    out = tmp_path / "single"
    summary = _run("single_impact", out, "--material", "ab_t10_ore", "--particles", "3",
                   "--energies", "400", "--jobs", "1")
    assert summary["results"][0]["broken_fraction"] > 0       # the progeny fields are there
    assert dotted(summary) - documented("`single_impact.py`") == set()
    missing, kinds = _undocumented_event_fields(sorted(out.glob("events_*.jsonl")))
    assert missing == set() and {"breakage", "damage"} <= kinds


@pytest.mark.yade
def test_agglomerate_impact_outputs_are_documented(tmp_path):
    out = tmp_path / "agglomerate"
    summary = _run("agglomerate_impact", out, "--particles", "60", "--duration", "6e-5",
                   "--vtk-interval", "3e-5")
    assert dotted(summary) - documented("`agglomerate_impact.py`") == set()
    arrays = {a.get("Name") for a in ET.parse(out / "paraview" / "spheres_0001.vtp").getroot()
              .iter("DataArray")} - {None, "connectivity", "offsets"}
    assert {"damage_ratio", "fragment"} <= arrays
    assert arrays - documented("ParaView series") == set()
    doc = DOC.read_text()
    for name in ("timeseries.csv", "bonds_broken.csv"):
        header = (out / name).read_text().splitlines()[0].split(",")
        assert all(f"`{field}`" in doc for field in header), name

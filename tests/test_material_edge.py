"""A job's edge: a material is resolved once (a job's options, attach()), then passed on as an
object, so a run reads each material file once; a material that cannot serve, or a bed too large
to build, is refused in one line before anything is written."""
import argparse

import pytest

from yadebreak.jobs import options as job_options
from yadebreak.model import materials


def _read(tmp_path, capsys, *argv):
    with pytest.raises(SystemExit) as ended:
        job_options.read("single_impact", argv=[*argv, "--out", str(tmp_path / "out")])
    assert ended.value.code == 2
    return capsys.readouterr().err.strip().splitlines()


def test_a_material_that_cannot_serve_is_refused_before_anything_is_written(tmp_path, capsys):
    lines = _read(tmp_path, capsys, "--material", "steel")
    assert len(lines) == 1 and lines[0].startswith("[yadebreak] error: --material = steel: not "
                                                   "breakable (breakable = false in ")
    assert "copper_ore" in lines[0]
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\nbreakable = true\n')
    lines = _read(tmp_path, capsys, "--material", str(bad))
    assert len(lines) == 1 and f"--material = {bad}: elastic: missing table [elastic]" in lines[0]
    lines = _read(tmp_path, capsys, "--target", "nosuch")
    assert len(lines) == 1 and "--target = nosuch: unknown material 'nosuch'" in lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.yade
def test_a_run_reads_each_material_file_once(tmp_path, monkeypatch, scene):
    """Two energies of single impacts, two scenes each: the particles' and the target's files are
    read once each, by the job's options; scenes and attach() take the objects."""
    from yadebreak.jobs import impacts
    read = []
    parse = materials.parse
    monkeypatch.setattr(materials, "parse", lambda doc, source, criteria: (
        read.append(str(source)), parse(doc, source, criteria))[1])
    args = job_options.read("single_impact", argv=[
        "--material", "granulite", "--target", "rubber", "--size", "4mm", "--particles", "2",
        "--energies", "50,80", "--out", str(tmp_path / "out")])
    impacts.single(args)
    assert sorted(p.rsplit("/", 1)[-1] for p in read) == ["granulite.toml", "rubber.toml"]


@pytest.mark.parametrize("layers", [1, 5])
def test_a_bed_past_the_largest_is_refused_with_its_count_and_memory(tmp_path, capsys, layers):
    """--rings past MOST_BED_PARTICLES: one line with the count, the memory and the largest
    --rings accepted, which is accepted and the next refused."""
    def read(rings):
        return job_options.read("bed_impact", argv=["--rings", str(rings), "--layers",
                                                     str(layers), "--out", str(tmp_path / "o")])
    with pytest.raises(SystemExit) as ended:
        read(3000)
    assert ended.value.code == 2
    line = capsys.readouterr().err.strip()
    count = layers * (1 + 3 * 3000 * 3001)
    assert line.startswith(f"[yadebreak] error: --rings = 3000 with --layers = {layers}: "
                           f"{count:,} particles (about ")
    largest = int(line.rsplit("--rings <= ", 1)[1].split()[0])
    assert read(largest).rings == largest
    with pytest.raises(SystemExit):
        read(largest + 1)
    assert not (tmp_path / "o").exists()


def test_a_mill_past_the_largest_charge_is_refused_with_its_count_and_memory(tmp_path, capsys):
    """A 5 m drum of 8 mm ore: one line with the balls, the ore particles and the memory, before
    anything is written; the default mill is accepted."""
    from yadebreak.model.milling import charge_counts
    argv = ["--drum-diameter", "5", "--drum-length", "5", "--out", str(tmp_path / "o")]
    with pytest.raises(SystemExit) as ended:
        job_options.read("ball_mill", argv=argv)
    assert ended.value.code == 2
    line = capsys.readouterr().err.strip()
    defaults = {p.name: p.default for p in job_options.JOBS["ball_mill"].params()}
    balls, ore = charge_counts(argparse.Namespace(**{**defaults, "drum_diameter": 5.0,
                                                     "drum_length": 5.0}))
    assert balls + ore > job_options.MOST_MILL_BODIES
    assert f"a charge of {balls:,} balls and {ore:,} ore particles (about " in line
    assert line.endswith(f"accepted at most {job_options.MOST_MILL_BODIES:,} bodies (a smaller "
                         "drum, coarser ore or balls, lower fillings)")
    assert not (tmp_path / "o").exists()


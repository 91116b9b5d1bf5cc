"""One home for each option and its default (yadebreak/options/table.py): every script's and
command's flag of an attach() option is made from the table, with the table's default or the
job's declared override (with its reason); the defaults the flags show in --help are the ones
the run gets; the jobs' code repeats no default; old checkpoints' arguments read as today's."""
import argparse
import ast
from pathlib import Path

import pytest

from yadebreak.jobs import options as job_options
from yadebreak.options.engine_flags import OPTION, Derived, engine_flag
from yadebreak.options.table import OPTIONS, Config

ROOT = Path(__file__).resolve().parent.parent
#: a job's own option named as an attach() option but meaning another thing
OWN_MEANING = {("agglomerate_impact", "time_step_fraction"):
               "the bonded scene's time step rule (bonds' time scale and Rayleigh time)"}
#: files whose attach() options with fixed values are their settings, not defaults: the stress
#: cases of extremes, the paper's figures (studies/verify), the values of old checkpoints
SETTINGS = {"jobs/extremes.py", "studies/verify/probability.py",
            "studies/verify/fragmentation.py"}


def _jobs():
    from yadebreak.studies import verify
    return {**{name: (job.params(), job.engine, job.overrides)
               for name, job in job_options.JOBS.items()},
            "verify": (verify.PARAMS, ("time_step_fraction", *verify.FRAGMENTATION),
                       verify.OVERRIDES)}


@pytest.mark.parametrize("job", sorted(_jobs()))
def test_a_flag_of_an_attach_option_takes_the_tables_default_or_a_declared_override(job):
    params, engine, overrides = _jobs()[job]
    by_name = {p.name: p for p in params}
    for name in set(by_name) & set(OPTION):
        if (job, name) in OWN_MEANING:
            assert name not in engine
            continue
        assert name in engine, f"{job}: --{name} is declared by hand, not from the table"
        flag, row, override = by_name[name], OPTION[name], overrides.get(name)
        assert flag == engine_flag(name, overrides, flag.help[:flag.help.index(row.help)])
        if override is None:
            wanted = row.token if row.default is None else row.default
        else:
            assert len(override.why) > 20, f"{job}: the override of {name} says no reason"
            value = override.value
            wanted = (value.token if isinstance(value, Derived) and value.token is not None
                      else row.token if value is None or isinstance(value, Derived) else value)
        assert flag.default == wanted, (job, name)
    for name, override in overrides.items():
        assert name in OPTION and override.why


@pytest.mark.parametrize("job", sorted(job_options.JOBS))
def test_the_run_gets_the_defaults_its_help_shows(job, capsys):
    """The attach() options of a run with no flag given: the table's, but for the job's
    overrides; each flag's --help line ends with that default (and why, for an override)."""
    declared = job_options.JOBS[job]
    args = job_options.read(job, None, [])
    options = job_options.attach_options(job, args)
    for name, value in options.items():
        override = declared.overrides.get(name)
        if override is None:
            assert value == OPTION[name].default, (job, name)
        elif isinstance(override.value, Derived):
            assert value == override.value.of(args)
        else:
            assert value == override.value
    Config.from_options(**options)                      # attach() accepts them
    with pytest.raises(SystemExit):
        job_options.read(job, None, ["--help"])
    said = " ".join(capsys.readouterr().out.split())
    for p in declared.params():
        if p.name in declared.engine:
            assert " ".join(p.help_line.replace("%%", "%").split()) in said


def test_no_job_repeats_an_attach_default_in_its_code():
    """No attach() option is passed with a fixed value in the jobs' and the verify command's
    code (their defaults live in jobs/options.py's declarations and verify's PAPER and
    OVERRIDES, with their reasons)."""
    names = {o.name for o in OPTIONS}
    found = []
    package = ROOT / "yadebreak"
    for path in [*(package / "jobs").glob("*.py"), *(package / "studies" / "verify").glob("*.py")]:
        where = str(path.relative_to(package))
        if where in SETTINGS or where == "jobs/options.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            pairs = ([(k.value, v) for k, v in zip(node.keys, node.values)
                      if isinstance(k, ast.Constant)] if isinstance(node, ast.Dict) else
                     [(node.arg, node.value)] if isinstance(node, ast.keyword) else [])
            found += [f"{where}:{node.lineno} {k}" for k, v in pairs
                      if k in names and isinstance(v, ast.Constant)]
    assert not found, found


def test_global_damping_zero_is_none_and_the_default_is_the_material_files():
    def gd(*argv):
        args = job_options.read("bed_impact", None, list(argv))
        options = job_options.attach_options("bed_impact", args)
        return options["global_damping"], options["global_damping_time"]
    assert gd() == (None, None)                                # the file's (0.3 copper ore)
    assert gd("--global-damping", "material") == (None, None)
    assert gd("--global-damping", "0") == (0.0, None)          # none
    assert gd("--global-damping", "0.3", "--global-damping-time", "0.5ms") == (0.3, 5e-4)
    flag = engine_flag("global_damping", job_options.BED_IMPACT.overrides)
    assert "0: none" in flag.help_line and "default material (each material file's" in \
        flag.help_line


def test_the_mills_dmin_is_its_declared_third_of_the_feed():
    args = job_options.read("ball_mill", None, ["--size", "9mm"])
    assert job_options.attach_options("ball_mill", args)["dmin"] == pytest.approx(3e-3)
    args = job_options.read("ball_mill", None, ["--dmin", "1mm"])
    assert job_options.attach_options("ball_mill", args)["dmin"] == 1e-3
    assert job_options.attach_options("ball_mill", args)["dummies"] == "ledger"   # no flag


def test_a_hand_made_namespace_takes_the_declared_defaults():
    options = job_options.attach_options("bed_impact", argparse.Namespace(dmin=0.0))
    assert options["dmin"] is None and options["dummies"] == "ledger"
    assert options["read_period"] == "fast" and options["outcome"] == "paper"
    assert options["break_at"] is None                     # the outcome's: 'threshold'
    assert Config.from_options(**options).criteria.break_at == "threshold"


@pytest.mark.parametrize("saved, today", [
    ({"global_damping": 0.0}, {"global_damping": "material", "global_damping_time": "forever"}),
    ({"global_damping": 0.3}, {"global_damping": 0.3, "global_damping_time": 5e-4}),
    ({"global_damping": 0.0, "global_damping_time": "forever"},
     {"global_damping": 0.0, "global_damping_time": "forever"}),
])
def test_an_old_checkpoints_arguments_read_as_todays(saved, today):
    now = {"global_damping": "x", "global_damping_time": "y", "break_at": "outcome",
           "outcome": "paper"}
    assert job_options.arguments_of_today(saved, now) == {**today, "break_at": "outcome",
                                                          "outcome": "paper"}


def test_a_checkpoint_from_before_the_outcome_option_reads_its_break_at_as_todays():
    """Before `outcome`, --break-at threshold was the default; today it is --break-at outcome
    with --outcome paper (the same run), so such a checkpoint resumes; a peak stays a peak."""
    now = {"break_at": "outcome", "outcome": "paper"}
    assert job_options.arguments_of_today({"break_at": "threshold"}, now) == now
    assert job_options.arguments_of_today({"break_at": "peak"}, now) == {**now,
                                                                         "break_at": "peak"}

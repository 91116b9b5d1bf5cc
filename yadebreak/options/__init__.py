"""Options: the engine's option table (table.py), attach()'s options as a job's flags made from
it with the job's overrides (engine_flags.py), and the command-line machinery of scripts and
tools (flags.py). Never imports yade."""

"""Options: the engine's option table (table.py) and the command-line machinery of scripts and
tools (flags.py). Never imports yade."""

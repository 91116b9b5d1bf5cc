"""`python3 -m yadebreak`: the command line (yadebreak/cli.py)."""
import sys

from yadebreak.cli import main

sys.exit(main())

"""`python -m shockcal` runs the command-line interface."""

import sys

from shockcal.cli import main

sys.exit(main())

"""`python -m lagbench`: the command line."""
import sys

from lagbench.cli import main

sys.exit(main())

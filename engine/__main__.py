"""``python -m engine``: the same command as ``colldet``."""
import sys

from engine.cli import main

sys.exit(main())

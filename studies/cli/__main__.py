"""``python -m softhand.studies.cli``."""
import sys

from softhand.studies.cli.main import main

sys.exit(main())

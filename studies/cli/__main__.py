"""``python -m softhand.studies.cli``."""
import sys

from softhand.studies.cli.main import main

if __name__ == "__main__":  # not on import (the docs' API reference imports every module)
    sys.exit(main())

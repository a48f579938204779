"""``python -m trajopt.cli``: the ``trajopt`` command."""

import sys

from trajopt.cli import main

if __name__ == "__main__":  # walk_packages imports this module too
    sys.exit(main())

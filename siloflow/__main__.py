"""``python -m siloflow``: the ``siloflow`` command (:func:`siloflow.cli.main.main`)."""

import sys

from siloflow.cli.main import main

sys.exit(main())

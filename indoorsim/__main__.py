"""``python -m indoorsim``: the same command line as the ``indoorsim`` script."""

from indoorsim.cli import main

raise SystemExit(main())

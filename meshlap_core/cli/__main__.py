"""``python -m meshlap_core.cli``."""

from . import main

raise SystemExit(main())

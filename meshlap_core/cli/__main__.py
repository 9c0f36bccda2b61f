"""``python -m meshlap_core.cli``."""

try:
    from . import main
except KeyboardInterrupt:  # interrupted while importing: one line, no traceback
    import sys

    sys.stderr.write("meshlap: interrupted\n")
    raise SystemExit(130) from None

raise SystemExit(main())

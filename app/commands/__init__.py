"""The ``meshlap`` commands that open or render the viewer (``view``, ``animate``).

The core's command line (:mod:`meshlap_core.cli`) knows nothing of the viewer: it adds every
command registered in the ``meshlap.commands`` entry-point group (``pyproject.toml``), so these
modules follow its protocol (``register(sub)`` adding a sub-parser whose ``func`` runs it).
"""

"""The meshlap viewer, installed as ``meshlap_app`` (the folder is ``app/``).

- :mod:`.state` — plain state objects, tested headless; no polyscope import anywhere in it;
  owns the vocabulary ``PANELS`` / ``FIELDS`` that ``meshlap view`` imports.
- :mod:`.camera` — pinhole projection (numpy only).
- :mod:`.scene` — structure names, offsets, colours and camera framing (imports polyscope).
- :mod:`.panels` — one module per panel (imports polyscope).
- :mod:`.viewer` — the loop: ``polyscope.init``, the frame callback, ``run`` (imports polyscope).

Importing ``meshlap_app`` or ``meshlap_app.state`` does not import polyscope; ``scene``,
``panels`` and ``viewer`` do.
"""

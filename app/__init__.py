"""The meshlap viewer, installed as ``meshlap_app`` (the folder is ``app/``).

- :mod:`.registry` — the list of panels' specs (the only module that names them all).
- :mod:`.panel_spec` — the panel contract: one ``PanelSpec`` per panel (name, title, panel
  class, state factory, settings schema, checks, animation); :mod:`.state.settings` — the
  typed settings schema everything about a setting is derived from.
- :mod:`.host` — ``Host``, what a panel may use of the program that shows it.
- :mod:`.state` — plain state objects, tested headless; no polyscope import anywhere in it:
  ``AppState`` (the one owner of the viewer's state), ``Watch`` (the one invalidation rule),
  and per panel its spec, state slice and animation declaration.
- :mod:`.panels` — one module per panel, each following ``panels.base.Panel`` and typed against
  the narrow ``host.Host`` (imports polyscope); :mod:`.setting_widgets` draws a declared
  setting's widget.
- :mod:`.viewer` — the host on polyscope's frame loop, ``run`` (imports polyscope).
- :mod:`.session` / :mod:`.animate` / :mod:`.record` — saved sessions, ``meshlap animate`` and
  the record button: loops over the registered panels.
- :mod:`.commands` — the ``meshlap view`` / ``meshlap animate`` commands, added to the core's
  command line through the ``meshlap.commands`` entry points; :mod:`.screenshots` the report's.
- :mod:`.scene`, :mod:`.camera`, :mod:`.ui` — structure names and framing, projection, the
  imgui adapter.

Importing ``meshlap_app`` or ``meshlap_app.state`` does not import polyscope; ``scene``,
``panels`` and ``viewer`` do.
"""

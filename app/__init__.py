"""The meshlap viewer: plain state objects (``app.state``, no polyscope import) and a thin
polyscope layer (``app.viewer``) that reads widgets, calls state methods and pushes arrays.

Importing ``app`` does not import polyscope; only ``app.viewer`` does.
"""

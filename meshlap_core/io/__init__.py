"""Reading and writing meshes and per-vertex scalars (OBJ, OFF, PLY, STL), atomically.

Every loader is written here (libigl's readers can crash or silently accept garbage) and ends in
:func:`meshlap_core.validate.validate_mesh`, so :func:`load_mesh` returns a
:class:`~meshlap_core.validate.Mesh` whose report lists every repair. Problems with the file
raise :class:`~meshlap_core.errors.MeshError` naming the file and, where it helps, the line,
face or vertex.

Speed: the common case (an all-triangle OBJ with ``v``/``f`` lines, an ASCII OFF/PLY with
one record per line, any binary PLY/STL) is parsed in bulk with numpy, without a Python loop
over lines; everything else (slashes, negative indices, comments inside data, polygons in OFF,
extra properties) takes a slower per-line path that gives the same result.

One tokenizer contract for every format (:mod:`._scan`): lines end at ``\\n``, ``\\r\\n`` or
``\\r`` only; numbers are ASCII decimal/exponent literals (``nan``/``inf`` reach the validator,
which refuses them); anything else in a numeric field is an error naming the line. Headers
are checked against bodies, never guessed; every file is read through
:mod:`.reader` (regular files only, a size limit per kind, bounded in size and time), which
also reads JSON (:func:`~meshlap_core.io.reader.read_json`).

Writing: :func:`save_mesh` (``.obj``, ``.off``, ``.ply``; PLY can carry a per-vertex
``quality`` scalar), :func:`save_scalars` (``.csv``, ``.npy``, ``.ply``) and the
:func:`atomic_write` context manager they use: temp file in the target's directory, fsync,
``os.replace``; an exception leaves any existing target untouched.

Modules: :mod:`.load` (``load_mesh``, ``load_vertex_scalars``: read, dispatch by extension,
validate), :mod:`.obj`, :mod:`.off`, :mod:`.ply`, :mod:`.stl` (one parser each),
:mod:`._scan` (the byte-level scanner they share), :mod:`.write` (``save_mesh``,
``save_scalars``), :mod:`.atomic` (``atomic_write``, ``check_output_path``), :mod:`.reader`
(``read_input``, ``open_input``, ``check_input``, ``read_json``: the one reader).
"""

from __future__ import annotations

from .atomic import PathLike, atomic_write, check_output_path
from .load import MESH_FORMATS, load_mesh, load_vertex_scalars
from .write import SCALAR_FORMATS, WRITE_FORMATS, save_mesh, save_scalars

__all__ = [
    "MESH_FORMATS",
    "SCALAR_FORMATS",
    "WRITE_FORMATS",
    "PathLike",
    "atomic_write",
    "check_output_path",
    "load_mesh",
    "load_vertex_scalars",
    "save_mesh",
    "save_scalars",
]

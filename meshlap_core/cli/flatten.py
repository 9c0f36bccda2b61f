"""``meshlap flatten MESH --method M --out OUT.obj``: a map of the mesh to the plane, written as
texture coordinates, and its distortion.

The mesh is first opened into a disk (:func:`meshlap_core.flatten.make_disk`: a disk as it is,
holes left free, handles cut, a sphere slit, ``--seam I,J,...`` cut first), then mapped by
Tutte's or the harmonic map (``--boundary circle|square``), LSCM, the spectral conformal map
(free boundary only) or ARAP (``--iters N``; free, circle or square). ``OUT.obj`` is the input
mesh with one ``vt`` per disk vertex (moved and scaled uniformly into ``[0, 1]²``) and faces
``f v/vt``, written atomically. ``--json`` prints one object: the map's row of the
distortion table (angle distortion ``σ₁/σ₂`` and area distortion ``|log σ₁σ₂|``, their
area-weighted means and maxima, flipped and collapsed faces, seconds) and what was cut.

Bounded work: ``--iters`` above :data:`~meshlap_core.options.MAX_FLATTEN_ITERS` is refused; an
option a method does not take (``--boundary circle`` with lscm, ``--iters`` with tutte) is an
error, not ignored.
"""

from __future__ import annotations

import argparse
from typing import Any

from ..errors import MeshError
from ..options import FLATTEN_BOUNDARIES, FLATTEN_METHODS, MAX_FLATTEN_ITERS
from ..progress import Progress
from ._common import add_json_flag, emit_json, parse_list, print_report
from ._sources import output

#: where the core's argument names point on the command line
FLAGS = {
    "method": "--method",
    "boundary": "--boundary",
    "iters": "--iters",
    "seam": "--seam",
}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "flatten",
        help="map the mesh to the plane (Tutte, harmonic, LSCM, spectral, ARAP) with distortion",
        description=(
            "Cut the mesh to a disk, map it to the plane and write it with vt texture "
            "coordinates; print the map's angle distortion s1/s2, area distortion "
            "|log s1 s2|, flipped faces and time."
        ),
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument("--method", required=True, choices=FLATTEN_METHODS, help="the map")
    p.add_argument(
        "--boundary",
        choices=FLATTEN_BOUNDARIES,
        default=None,
        help="outer boundary: circle or square (tutte, harmonic: default circle; arap: "
        "default free), free (lscm, scp)",
    )
    p.add_argument(
        "--iters", default=None, help=f"ARAP iterations, 0 to {MAX_FLATTEN_ITERS} (default 50)"
    )
    p.add_argument(
        "--seam",
        default=None,
        help="cut first along this path of vertices, e.g. 3,17,42 (0-based, after repairs)",
    )
    p.add_argument("--out", required=True, help="the mesh with texture coordinates (.obj)")
    add_json_flag(p)
    p.set_defaults(func=run)


def _iters(text: str | None) -> int | None:
    """``--iters`` as an int (range checked by the core), or ``None``."""
    if text is None:
        return None
    digits = text.strip()
    if len(digits) > 40 and digits.isascii() and digits.isdigit():  # int() refuses > 4300
        raise MeshError(f"must be at most {MAX_FLATTEN_ITERS}, got {len(digits)} digits", "--iters")
    try:
        return int(digits)
    except ValueError:
        raise MeshError(f"must be an integer, got {text!r}", "--iters") from None


def _on_flags(exc: MeshError, mesh: str) -> MeshError:
    """The core's error with its argument named as the command line spells it (the mesh's
    own problems named by the file)."""
    if exc.source is not None and exc.source.startswith("--"):
        return exc
    return MeshError(exc.problem, FLAGS.get(exc.source or "", mesh))


def _progress() -> Progress:
    return Progress(
        1.0,
        lambda p: f"meshlap flatten: {100 * p.done:3.0f}% {p.message}",
        in_place=False,
        after_s=1.0,
        every_s=1.0,
    )


def run(args: argparse.Namespace) -> int:
    from ..flatten import Flattener, check_options
    from ..io import load_mesh

    try:
        method, boundary, _ = check_options(args.method, args.boundary, _iters(args.iters))
    except MeshError as exc:
        raise _on_flags(exc, args.mesh) from None
    iters = None if method != "arap" else _iters(args.iters)
    seam = None if args.seam is None else parse_list(args.seam, int, "--seam")
    out = output(args.out, args.mesh, (".obj",), "--out")
    mesh = load_mesh(args.mesh)
    bar = _progress()
    try:
        flat = Flattener(mesh.V, mesh.F, seam)
        uvmap = flat.map(method, boundary, iters=iters, progress=bar.update)
    except MeshError as exc:
        raise _on_flags(exc, args.mesh) from None
    finally:
        bar.close()
    flat.save_obj(out, uvmap, overwrite_inputs=(args.mesh,))
    result = _result(args, flat, uvmap, mesh, out)
    print_report(args.mesh, mesh.report)
    if args.json:
        emit_json(result)
    else:
        _print_text(result)
    return 0


def _result(args: argparse.Namespace, flat: Any, uvmap: Any, mesh: Any, out: Any) -> dict:
    disk = flat.disk
    return {
        "file": str(args.mesh),
        "out": str(out),
        "n_vertices": mesh.n_vertices,
        "n_faces": mesh.n_faces,
        "disk": {
            "how": disk.how,
            "vertices": disk.n_vertices,
            "outer_loop": len(disk.outer),
            "holes": len(disk.holes),
            "cut_edges": len(disk.cut_edges),
            "seconds": flat.seconds,
            "messages": list(disk.messages),
        },
        "distortion": uvmap.summary(),
    }


def _print_text(r: dict) -> None:
    d, disk = r["distortion"], r["disk"]
    print(
        f"{d['method']} map ({d['boundary']} boundary) of {r['n_vertices']} vertices, "
        f"{r['n_faces']} faces: {d['seconds']:.3g} s"
        + (f", {d['iterations']} iterations, energy {d['energy']:.6g}" if "energy" in d else "")
    )
    for message in disk["messages"]:
        print(f"  {message}")
    print(f"  angle distortion s1/s2   mean {d['angle_mean']:.6g}  max {d['angle_max']:.6g}")
    print(f"  area distortion |log s1s2| mean {d['area_mean']:.6g}  max {d['area_max']:.6g}")
    print(f"  flipped faces {d['flipped']}, collapsed faces {d['collapsed']}")
    print(f"wrote {r['out']}")

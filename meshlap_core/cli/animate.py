"""``meshlap animate MESH --panel smoothing|spectral|surfaces ... --out OUT.gif|.mp4``: an
animation for slides, rendered headless (EGL) with the viewer's scene code
(``meshlap_app.animate``). ``--session FILE.json`` animates a view prepared in the window: its
mesh, settings and camera (an option typed on the command line wins over the session's value,
which wins over the built-in default).

Every argument, the session, the mesh and the output path are checked before the renderer
starts: a bad one is one line ``meshlap: error: ...`` and exit 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from ..errors import MeshError
from ..frames import parse_range
from ..noise import check_noise, check_seed
from ..options import LAPLACIAN_KINDS
from ..smoothing.params import check_lam

METHODS = ("explicit", "implicit", "taubin")
PANELS = ("smoothing", "spectral", "surfaces")
DEFAULTS: dict[str, Any] = {
    "method": "implicit",
    "laplacian": "uniform",
    "lam": 1.0,
    "iters": 30,
    "noise": 0.0,
    "seed": 0,
    "surface": "saddle",
    "frames": 72,
    "size": "960x540",
}
"""The built-in defaults (argparse's are ``None``, so a typed option can be told apart from a
value a session supplies)."""

SESSION_HELP = """\
--session FILE.json animates a view saved in the window (save session): its mesh (MESH is
then an error), its settings and its camera. An option typed here wins over the session's
value, which wins over the built-in default.
  panel      the session's panel; a session saved on curvature or onering needs --panel
  smoothing  method, laplacian, lambda, noise alpha and seed from the session; --iters
             defaults to the session's iteration count when it is > 0 (else 30): the frames
             are iterations 0..iters, so the last frame is the saved view
  spectral   without --k/--modes: the k sweep 1:k up to the session's k (also when the
             session showed an eigenmode: the modes are animated only with --modes); the
             basis comes from the cache as in `meshlap view --session`
  surfaces   the session's surface, resolution and (u, v); --theta is implied (--uv or
             another --surface replace the point)
  camera     the session's camera, not re-framed; the default --size is the part of the
             saved window left of meshlap's panel, and the frames show exactly that part. An
             explicit --size keeps the camera's view matrix and vertical field of view and
             widens or narrows the picture symmetrically about that part's centre. With
             --panel naming another panel than the session's (whose camera framed other
             structures) or a session without a camera, the view is framed as without
             --session.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "animate",
        help="render an animation (GIF/MP4) of smoothing, the spectral k sweep or modes, "
        "or a turning normal section",
        epilog=SESSION_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    d = DEFAULTS
    p.add_argument("mesh", nargs="?", help="mesh file (default: assets/bumpy.obj)")
    p.add_argument(
        "--panel",
        choices=PANELS,
        help="what to animate (required without --session; default: the session's panel)",
    )
    p.add_argument("--out", required=True, metavar="OUT.gif|OUT.mp4", help="the animation file")
    p.add_argument("--method", choices=METHODS, help=f"smoothing method (default {d['method']})")
    p.add_argument("--laplacian", choices=LAPLACIAN_KINDS, help=f"default {d['laplacian']}")
    p.add_argument("--lam", type=float, help=f"smoothing step λ > 0 (default {d['lam']:g})")
    p.add_argument(
        "--iters", type=int, help=f"smoothing iterations (frames: iters+1; default {d['iters']})"
    )
    p.add_argument("--noise", type=float, help=f"noise α before smoothing (default {d['noise']:g})")
    p.add_argument("--seed", type=int, help=f"noise seed (default {d['seed']})")
    p.add_argument("--k", metavar="A:B", help="spectral: reconstruct from k = A..B modes")
    p.add_argument("--modes", metavar="A:B", help="spectral: show eigenmodes A..B one by one")
    p.add_argument("--theta", action="store_true", help="surfaces: turn the normal section")
    p.add_argument("--surface", help=f"surfaces: the parametric surface (default {d['surface']})")
    p.add_argument("--uv", metavar="U,V", help="surfaces: the point (default: the surface's)")
    p.add_argument("--frames", type=int, help=f"surfaces: frames per turn (default {d['frames']})")
    p.add_argument("--fps", type=float, help="frames per second (default depends on the kind)")
    p.add_argument(
        "--size",
        metavar="WxH",
        help=f"frame size in pixels (default {d['size']}; with --session: the saved window's view)",
    )
    p.add_argument(
        "--shadow",
        action="store_true",
        help="draw the ground shadow as the viewer does (slower: a second render pass)",
    )
    p.add_argument(
        "--session",
        metavar="FILE.json",
        help="animate a saved viewer session: its mesh, settings and camera (see below)",
    )
    p.set_defaults(func=run)


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(t) for t in text.lower().split("x"))
    except ValueError:
        raise MeshError(f"expected WxH such as 960x540, got {text!r}", "--size") from None
    return w, h


def _uv(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        u, v = (float(t) for t in text.split(","))
    except ValueError:
        raise MeshError(f"expected U,V such as 0.5,1.0, got {text!r}", "--uv") from None
    if not (math.isfinite(u) and math.isfinite(v)):
        raise MeshError(f"must be finite, got {text!r}", "--uv")
    return u, v


def _check_numbers(args: argparse.Namespace) -> None:
    if args.panel == "smoothing":
        check_lam(args.lam, "--lam")
        if not 0 <= args.iters <= 5000:
            raise MeshError(f"must be 0 to 5000, got {args.iters}", "--iters")
        if not (math.isfinite(args.noise) and args.noise >= 0):
            raise MeshError(f"must be a finite number >= 0, got {args.noise}", "--noise")
        check_seed(args.seed, "--seed")
    if args.fps is not None and not (math.isfinite(args.fps) and 0.1 <= args.fps <= 120):
        raise MeshError(f"must be between 0.1 and 120, got {args.fps}", "--fps")


def _fill_defaults(args: argparse.Namespace) -> None:
    """Without a session: every option not typed takes its built-in default."""
    if args.panel is None:
        raise MeshError(
            f"choose what to animate: --panel {'|'.join(PANELS)} (or give --session FILE.json)",
            "--panel",
        )
    for name, value in DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)


def _from_session(args: argparse.Namespace) -> Any:
    """Read the session and fill every option not typed from it (then from the defaults).

    Returns the :class:`~meshlap_app.state.session.Session`.

    Raises
    ------
    MeshError
        MESH given as well, a refused session file, or a panel that cannot be animated.
    """
    if args.mesh is not None:
        raise MeshError(
            "MESH cannot be combined with --session (the session names its mesh)", "--session"
        )
    from meshlap_app.state.session import read_session  # no polyscope: pure data

    session = read_session(args.session)
    if args.panel is None:
        if session.panel not in PANELS:
            raise MeshError(
                f"the session was saved on the {session.panel} panel, which has no animation; "
                f"add --panel {'|'.join(PANELS)}",
                args.session,
            )
        args.panel = session.panel
    sm, sp, sf = (session.settings[s] for s in ("smoothing", "spectral", "surfaces"))
    if args.panel == "smoothing" and args.iters is None and sm["iterations"] > 5000:
        raise MeshError(
            f"the session's smoothing ran {sm['iterations']} iterations; an animation has at "
            "most 5000: give --iters N",
            args.session,
        )
    # the λ of every saved step, unless a λ is typed (then every frame uses that one)
    args.lam_steps = sm.get("lam_steps") if args.lam is None else None
    saved = {
        "method": sm["method"],
        "laplacian": sm["laplacian"],
        "lam": sm["lam"],
        "noise": sm["noise_alpha"],
        "seed": sm["seed"],
        "iters": sm["iterations"] or None,  # 0: the built-in default
        "surface": sf["surface"],
    }
    for name, value in saved.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    if args.panel == "spectral" and args.k is None and args.modes is None:
        args.k = f"1:{sp['k']}"  # the k sweep up to the session's k
    if args.panel == "surfaces":
        args.theta = True
        if args.uv is None and args.surface == sf["surface"]:
            args.uv = f"{sf['u']!r},{sf['v']!r}"
    if args.size is None:
        from meshlap_app.animate import session_size

        size = session_size(session, args.session)
        args.size = f"{size[0]}x{size[1]}" if size is not None else None
    _fill_defaults(args)
    return session


def run(args: argparse.Namespace) -> int:
    session = _from_session(args) if args.session is not None else None
    if session is None:
        _fill_defaults(args)
    k = parse_range(args.k, "--k", lo=1) if args.k is not None else None
    modes = parse_range(args.modes, "--modes", lo=0) if args.modes is not None else None
    _check_numbers(args)
    from meshlap_app.animate import (  # the CLI imports the GUI only here
        AnimationSpec,
        check_spec,
        load_mesh_state,
        render,
    )

    spec = AnimationSpec(
        panel=args.panel,
        out=Path(args.out),
        mesh=session.mesh if session is not None else Path(args.mesh) if args.mesh else None,
        method=args.method,
        laplacian=args.laplacian,
        lam=args.lam,
        lam_steps=getattr(args, "lam_steps", None),
        iters=args.iters,
        noise=args.noise,
        seed=args.seed,
        k=k,
        modes=modes,
        theta=args.theta,
        surface=args.surface,
        uv=_uv(args.uv),
        frames=args.frames,
        fps=args.fps,
        size=_size(args.size),
        shadow=args.shadow,
        session=session,
        session_file=Path(args.session) if session is not None else None,
    )
    check_spec(spec, None)  # options and output path first: a doomed run fails in a second
    mesh = load_mesh_state(spec) if spec.panel != "surfaces" or session is not None else None
    check_spec(spec, mesh)
    if mesh is not None and spec.panel == "smoothing" and args.noise:
        check_noise(mesh.V, args.noise, "--noise")  # before the renderer: it names --noise
    if mesh is None:
        from meshlap_app.state.mesh import MeshState

        mesh = MeshState()
        mesh.load(None)  # the surfaces panel does not use it; the viewer needs one
    out = render(spec, mesh, progress=True)
    sys.stdout.write(f"wrote {out}\n")
    return 0

"""``meshlap animate MESH --panel P ... --out OUT.gif|.mp4``: an animation for slides,
rendered headless (EGL) with the viewer's scene code (:mod:`..animate`). ``--session
FILE.json`` animates a view prepared in the window: its mesh, settings and camera (an option
typed on the command line wins over the session's value, which wins over the built-in default).

The animatable panels and their options come from the panels' specs (the registry): each
setting's ``animate`` flag (its type, range and help from the settings schema) and the
animation's own options; this module names none of them. Every argument, the session, the
mesh and the output path are checked before the renderer starts: a bad one is one line
``meshlap: error: ...`` and exit 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from meshlap_core.errors import MeshError, printable

from ..panel_spec import PanelSpec
from ..registry import animated

DEFAULT_SIZE = "960x540"

SESSION_HELP = """\
--session FILE.json animates a view saved in the window (save session): its mesh (MESH is
then an error), its settings and its camera. An option typed here wins over the session's
value, which wins over the built-in default.
  panel      the session's panel; a session saved on a panel without an animation needs
             --panel
{sections}
  camera     the session's camera, not re-framed; the default --size is the part of the
             saved window left of meshlap's panel, and the frames show exactly that part. An
             explicit --size keeps the camera's view matrix and vertical field of view and
             widens or narrows the picture symmetrically about that part's centre. With
             --panel naming another panel than the session's (whose camera framed other
             structures) or a session without a camera, the view is framed as without
             --session.
"""


def register(sub: argparse._SubParsersAction) -> None:
    kinds = animated()
    p = sub.add_parser(
        "animate",
        help="render an animation (GIF/MP4): "
        + "; ".join(s.animation_declared().summary for s in kinds.values()),
        description="Render an animation for slides, headless.\n"
        + "\n".join(f"  --panel {n}: {s.animation_declared().summary}" for n, s in kinds.items()),
        epilog=SESSION_HELP.format(
            sections="\n".join(
                "  " + s.animation_declared().session_help
                for s in kinds.values()
                if s.animation_declared().session_help
            )
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("mesh", nargs="?", help="mesh file (default: assets/bumpy.obj)")
    p.add_argument(
        "--panel",
        choices=tuple(kinds),
        help="what to animate (required without --session; default: the session's panel)",
    )
    p.add_argument("--out", required=True, metavar="OUT.gif|OUT.mp4", help="the animation file")
    for spec in kinds.values():
        add_flags(p, spec)
    p.add_argument("--fps", type=float, help="frames per second (default depends on the kind)")
    p.add_argument(
        "--size",
        metavar="WxH",
        help=f"frame size in pixels (default {DEFAULT_SIZE}; with --session: the saved window's "
        "view)",
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


def add_flags(p: argparse.ArgumentParser, spec: PanelSpec) -> None:
    """The flags of ``spec``'s animation: each setting's (typed text, checked by the setting
    when the command runs, so a bad value is one ``meshlap: error`` line naming the flag) and
    the animation's own options."""
    for setting, flag in spec.flags("animate"):
        p.add_argument(
            flag.name,
            dest=flag.dest,
            metavar=setting.metavar(),
            help=setting.flag_help(flag, spec.name),
        )
    for opt in spec.animation_declared().options:
        if opt.store_true:
            p.add_argument(opt.flag, action="store_true", default=None, help=opt.help)
        else:
            p.add_argument(
                opt.flag, type=opt.type, choices=opt.choices, metavar=opt.metavar, help=opt.help
            )


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(t) for t in text.lower().split("x"))
    except ValueError:
        raise MeshError(f"expected WxH such as 960x540, got {text!r}", "--size") from None
    return w, h


def _choose(args: argparse.Namespace, session: Any) -> tuple[str, PanelSpec]:
    """The animated panel (typed, else the session's) and its spec."""
    kinds = animated()
    if args.panel is None and session is not None:
        if session.panel not in kinds:
            raise MeshError(
                f"the session was saved on the {session.panel} panel, which has no animation; "
                f"add --panel {'|'.join(kinds)}",
                args.session,
            )
        args.panel = session.panel
    if args.panel is None:
        raise MeshError(
            f"choose what to animate: --panel {'|'.join(kinds)} (or give --session FILE.json)",
            "--panel",
        )
    return args.panel, kinds[args.panel]


def _read_session(args: argparse.Namespace) -> Any:
    """The session file, refused with MESH beside it."""
    if args.mesh is not None:
        raise MeshError(
            "MESH cannot be combined with --session (the session names its mesh)", "--session"
        )
    from ..state.session import read_session  # no polyscope: pure data

    return read_session(args.session)


def _refuse_other_options(args: argparse.Namespace, panel: str, spec: PanelSpec) -> None:
    """An option of another panel's animation, typed beside this panel, is refused (it would
    be ignored without a word)."""
    own = set(spec.animation_options({}))
    for name, other in animated().items():
        flags = [(f.name, f.dest) for _, f in other.flags("animate")]
        flags += [(o.flag, o.dest) for o in other.animation_declared().options]
        for flag, dest in flags:
            if dest not in own and getattr(args, dest, None) is not None:
                raise MeshError(
                    f"{flag} is an option of --panel {name}, not of --panel {panel}", flag
                )


def run(args: argparse.Namespace) -> int:
    session = _read_session(args) if args.session is not None else None
    panel, declared = _choose(args, session)
    anim = declared.animation_declared()
    _refuse_other_options(args, panel, declared)
    options = declared.animation_options(vars(args))
    saved = session.settings[panel] if session is not None else None
    declared.fill_options(options, saved, args.session)
    if session is not None and args.size is None:
        from ..animate import session_size

        size = session_size(session, args.session)
        args.size = f"{size[0]}x{size[1]}" if size is not None else None
    if args.fps is not None and not (math.isfinite(args.fps) and 0.1 <= args.fps <= 120):
        raise MeshError(f"must be between 0.1 and 120, got {args.fps}", "--fps")
    from ..animate import AnimationSpec, check_spec, load_mesh_state, render

    spec = AnimationSpec(
        panel=panel,
        out=Path(args.out),
        mesh=session.mesh if session is not None else Path(args.mesh) if args.mesh else None,
        options=options,
        fps=args.fps,
        size=_size(args.size or DEFAULT_SIZE),
        shadow=args.shadow,
        session=session,
        session_file=Path(args.session) if session is not None else None,
    )
    check_spec(spec, None)  # options and output path first: a doomed run fails in a second
    mesh = load_mesh_state(spec) if anim.uses_mesh or session is not None else None
    check_spec(spec, mesh)
    if mesh is None:
        from ..state.mesh import MeshState

        mesh = MeshState()
        mesh.load(None)  # the frames do not show it; the viewer needs one
    out = render(spec, mesh, progress=True)
    sys.stdout.write(f"wrote {printable(str(out))}\n")
    return 0

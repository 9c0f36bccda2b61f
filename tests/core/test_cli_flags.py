"""One flag name per option across the commands: ``--area`` is the area kind everywhere,
``--mass-update`` is smoothing's frozen / recompute; the old ``--mass`` of ``spectral`` and of
``smooth`` (two meanings) is refused for one release with a line naming each command's new flag."""

import json

import pytest

from meshlap_core.cli import build_parser, main
from meshlap_core.io import save_mesh
from meshlap_core.primitives import icosphere


@pytest.fixture
def sphere(tmp_path):
    path = tmp_path / "s.obj"
    save_mesh(path, *icosphere(1))
    return str(path)


@pytest.mark.parametrize(
    ("command", "new"),
    [
        (["spectral", "--k", "3"], "use --area (the area kind"),
        (["smooth"], "use --mass-update (frozen|recompute)"),
    ],
)
@pytest.mark.parametrize("value", [["voronoi"], ["frozen"], []])
def test_the_old_mass_flag_names_the_new_one(sphere, capsys, command, new, value):
    with pytest.raises(SystemExit) as e:  # an argument error: argparse exits, as for any flag
        main([command[0], sphere, *command[1:], "--mass", *value])
    out, err = capsys.readouterr()
    assert e.value.code == 2
    assert out == "" and err.count("\n") == 1
    assert err.startswith("meshlap: error: --mass: renamed; ") and new in err


def test_the_console_script_exits_2_on_the_old_flag(sphere):
    import subprocess
    import sys

    res = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", "spectral", sphere, "--k", "3", "--mass", "x"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 2 and res.stdout == ""
    assert res.stderr.startswith("meshlap: error: --mass: renamed; use --area")


def test_spectral_takes_the_area_kind_as_area(sphere, capsys):
    for area in ("barycentric", "voronoi"):
        assert main(["spectral", sphere, "--k", "3", "--area", area, "--no-cache", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["mass"] == area


def test_smooth_takes_the_mass_handling_as_mass_update(sphere, capsys):
    args = ["smooth", sphere, "--laplacian", "cotan", "--lam", "0.001", "--iters", "2", "--json"]
    for mode in ("frozen", "recompute"):
        assert main([*args, "--mass-update", mode, "--area", "barycentric"]) == 0
        assert json.loads(capsys.readouterr().out)["mass"] == mode


def test_every_command_spells_the_area_kind_area():
    """No command has an option (other than the refused old spelling) whose choices are the
    area kinds but whose name is not ``--area``."""
    from meshlap_core.options import AREA_KINDS

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name, p in sub.choices.items():
        for action in p._actions:
            if action.choices is not None and tuple(action.choices) == AREA_KINDS:
                assert action.option_strings == ["--area"], (name, action.option_strings)

"""The panel contract: every registered panel is one typed spec, and what the specs declare is
what the program does. Every table here is derived from the specs (no panel or setting is
listed by hand), so a new panel is covered by adding it to the registry:

- each spec loads its panel class; a spec lacking a part fails at import, naming the panel;
- a session with every declared setting at a non-default value is saved, reopened and equal,
  on disk and through the window's panels (configure / restore, then capture);
- a fresh window's panels capture exactly the declared defaults (the state's defaults are the
  schema's);
- every bad value of every setting (wrong type, out of range, NaN, an integer too large for a
  float) is refused with ``section.key`` in one line, never an internal error;
- every setting's flag is in ``meshlap view --help`` / ``meshlap animate --help`` and refuses
  bad values naming the flag; ``meshlap view --help`` imports no polyscope;
- Diffusion sources are kept once each and bounded by the mesh.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from typing import Any

import numpy as np
import pytest
from meshlap_app.panel_spec import PanelSpec, SpecError
from meshlap_app.registry import REGISTRY, VIEWS
from meshlap_app.state.session import (
    Session,
    default_settings,
    from_dict,
    read_session,
    schema,
    write_session,
)
from meshlap_app.state.settings import (
    MAX_INT,
    UNSET,
    Choice,
    Custom,
    Flag,
    Integer,
    Number,
    Settings,
    Toggle,
)

from meshlap_core.cli import main
from meshlap_core.errors import MeshError

WITH_SETTINGS = [spec for spec in REGISTRY if len(spec.settings)]
SETTINGS = [(spec, s) for spec in WITH_SETTINGS for s in spec.settings]
BAD = [(spec, s, bad) for spec, s in SETTINGS for bad in s.bad_values()]
FLAGS = [
    (command, spec, s, flag)
    for command in ("view", "animate")
    for spec in REGISTRY
    for s, flag in spec.flags(command)
]


def _id(x: Any) -> str:
    if isinstance(x, PanelSpec):
        return x.name
    if isinstance(x, Flag):
        return x.name
    if hasattr(x, "key"):
        return x.key
    text = repr(x)
    return text if len(text) < 24 else text[:20] + "..."


# ---------------------------------------------------------------- the specs themselves
@pytest.mark.parametrize("spec", REGISTRY, ids=_id)
def test_each_spec_is_its_panels_module_and_loads_its_class(spec):
    import importlib

    from meshlap_app.panels.base import Panel

    assert importlib.import_module(f"meshlap_app.state.{spec.name}").SPEC is spec
    cls = spec.panel_class()
    assert issubclass(cls, Panel) and cls.__module__ == f"meshlap_app.panels.{spec.name}"
    assert spec.view == (spec.name in VIEWS)


@pytest.mark.parametrize("missing", ["title", "summary", "panel"])
def test_a_spec_lacking_a_part_fails_naming_the_panel(missing):
    parts = {"name": "sketch", "title": "Sketch", "summary": "draws", "panel": "SketchPanel"}
    del parts[missing]
    with pytest.raises(SpecError, match=rf"panel 'sketch': its spec lacks its {missing}"):
        PanelSpec(**parts)
    with pytest.raises(SpecError, match="needs a name"):
        PanelSpec(title="Sketch", summary="draws", panel="SketchPanel")


def test_a_spec_that_contradicts_itself_fails_naming_the_panel():
    base = {"name": "sketch", "title": "Sketch", "summary": "draws", "panel": "SketchPanel"}
    flagged = Settings(Integer("n", 1, lo=1, hi=9, label="n", animate=Flag("--n")))
    with pytest.raises(SpecError, match="'sketch': animate flags without an animation"):
        PanelSpec(**base, settings=flagged)
    with pytest.raises(SpecError, match="'sketch': a section"):
        PanelSpec(
            **base, view=False, settings=Settings(Toggle("t", False, label="t", view=Flag("--t")))
        )
    with pytest.raises(SpecError, match="'sketch': settings must be a Settings"):
        PanelSpec(**base, settings=[Toggle("t", False, label="t")])  # type: ignore[arg-type]
    with pytest.raises(SpecError, match=r"panels\.help:Nope is not a class"):
        PanelSpec(**{**base, "name": "help", "panel": "Nope"}).panel_class()


def test_a_setting_that_contradicts_itself_fails_naming_its_key():
    with pytest.raises(ValueError, match="n: its default must be an integer 1 to 9"):
        Integer("n", 0, lo=1, hi=9, label="n")
    with pytest.raises(ValueError, match="overflow the widgets"):
        Integer("n", 1, lo=1, hi=MAX_INT + 1, label="n")
    with pytest.raises(ValueError, match="finite bounds"):
        Number("x", 0.0, lo=0.0, hi=math.inf, label="x")
    with pytest.raises(ValueError, match="a label names its widget"):
        Toggle("t", False)
    with pytest.raises(ValueError, match="declared twice"):
        Settings(Toggle("t", False, label="t"), Toggle("t", True, label="u"))
    with pytest.raises(ValueError, match="structured setting has no flag"):
        Custom("c", [], check=lambda x: None, view=Flag("--c"))


@pytest.mark.parametrize(("spec", "setting"), SETTINGS, ids=_id)
def test_every_number_a_user_can_type_has_both_bounds(spec, setting):
    """Integers within 32 bits (imgui's widgets), floats finite; a sample inside them."""
    if isinstance(setting, Integer):
        assert -MAX_INT <= setting.lo < setting.hi <= MAX_INT
    if isinstance(setting, Number):
        assert math.isfinite(setting.lo) and math.isfinite(setting.hi)
    assert setting.problem(setting.default) is None
    assert setting.problem(setting.sample()) is None
    assert setting.sample() != setting.default
    if setting.quiet is not UNSET:
        assert setting.problem(setting.quiet) is None


def test_no_module_looks_a_panel_hook_up_by_name():
    """The contract is the spec: no module of the viewer wing finds a module global by a
    constant name (``getattr(module, "SESSION", None)`` switched a feature off silently when
    the name was misspelt)."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "app"
    old = {"make_state", "check_section", "check_session", "check_view_options"}
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.Call) and getattr(node.func, "id", "") == "getattr"):
                continue
            name = node.args[1] if len(node.args) > 1 else None
            if isinstance(name, ast.Constant) and isinstance(name.value, str):
                if name.value.isupper() or name.value in old:
                    found.append(f"{path.relative_to(root)}:{node.lineno} {name.value}")
    assert not found, found


# ---------------------------------------------------------------- sessions, on disk
@pytest.mark.parametrize("spec", WITH_SETTINGS, ids=_id)
def test_every_setting_changed_is_saved_and_reopened(spec, tmp_path, sphere):
    """Every declared setting of the panel at its sample value (not its default): the file
    written reads back equal, each value as it was."""
    s = Session(mesh=sphere.resolve(), panel=spec.name if spec.view else VIEWS[0])
    s.settings[spec.name] = spec.settings.samples()
    for key, value in s.settings[spec.name].items():
        assert value != spec.settings.default(key), f"{spec.name}.{key}"
    path = write_session(tmp_path / f"{spec.name}.json", s)
    back = read_session(path)
    assert back == s
    assert back.settings[spec.name] == spec.settings.samples()
    assert json.loads(path.read_text())[spec.name] == json.loads(json.dumps(s.settings[spec.name]))


def test_missing_sections_and_keys_take_the_declared_defaults():
    s = from_dict({"format": "meshlap-session", "version": 1}, "s.json")
    assert s.settings == default_settings()
    assert set(s.settings) == {spec.name for spec in WITH_SETTINGS} == set(schema())
    for spec in WITH_SETTINGS:
        assert s.settings[spec.name] == {x.key: x.default for x in spec.settings}


@pytest.mark.parametrize(("spec", "setting", "bad"), BAD, ids=_id)
def test_every_bad_value_is_refused_naming_section_and_key(spec, setting, bad):
    data = Session().to_dict()
    data[spec.name] = {setting.key: bad}
    with pytest.raises(MeshError) as err:
        from_dict(data, "s.json")
    text = str(err.value)
    assert text.startswith(f's.json: "{spec.name}.{setting.key}" ') and "\n" not in text
    assert len(text) < 400  # a huge integer is named by its size, not printed


def test_a_huge_json_integer_is_one_clear_error_not_an_internal_one(tmp_path, sphere, capsys):
    """``math.isfinite(10**400)`` raised OverflowError in the session checks: exit 1, a
    traceback's last line. Every float setting of every panel, through the CLI: exit 2."""
    numbers = [(spec, s) for spec, s in SETTINGS if isinstance(s, Number)]
    assert numbers
    for spec, setting in numbers:
        data = Session(mesh=sphere).to_dict()
        data[spec.name] = {setting.key: 10**400}  # written as its 401 digits
        path = tmp_path / "huge.json"
        path.write_text(json.dumps(data))
        assert main(["view", "--session", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f'"{spec.name}.{setting.key}" must be' in err, err


# ---------------------------------------------------------------- command-line flags
def _help(command: str, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        main([command, "--help"])
    assert e.value.code == 0
    return " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize(("command", "spec", "setting", "flag"), FLAGS, ids=_id)
def test_every_declared_flag_is_in_the_commands_help(command, spec, setting, flag, capsys):
    text = _help(command, capsys)
    assert flag.name in text
    assert f"{spec.name}: {flag.help or setting.label}" in text  # its help, derived


def test_every_view_is_in_view_help(capsys):
    text = _help("view", capsys)
    for spec in REGISTRY:
        if spec.view:
            assert f"{spec.name}: {' '.join(spec.summary.split())}" in text


def test_every_animation_option_is_in_animate_help(capsys):
    text = _help("animate", capsys)
    for spec in REGISTRY:
        if spec.animation is not None:
            assert f"--panel {spec.name}: {spec.animation.summary}" in text
            assert " ".join(spec.animation.session_help.split()) in text
            for opt in spec.animation.options:
                assert opt.flag in text


@pytest.mark.parametrize(("command", "spec", "setting", "flag"), FLAGS, ids=_id)
def test_every_flag_refuses_bad_values_naming_it(command, spec, setting, flag):
    for bad in setting.bad_values():
        if isinstance(bad, bool) or bad is None or isinstance(bad, dict | list):
            continue  # not something a command line can type
        if isinstance(bad, str) and not isinstance(setting, Choice):
            continue  # a number as a JSON string: typed, it is that number
        with pytest.raises(MeshError) as err:
            setting.from_flag(bad if isinstance(bad, str) else repr(bad), flag.name)
        assert str(err.value).startswith(f"{flag.name}: ")
    assert setting.from_flag(str(setting.sample()), flag.name) == setting.sample()


def test_flags_are_refused_in_one_line_by_both_commands(tmp_path, sphere, capsys):
    """A typed value out of a setting's range, or a huge integer: exit 2, naming the flag,
    before any window or renderer."""
    for command, spec, setting, flag in FLAGS:
        if not isinstance(setting, Integer | Number):
            continue
        out = tmp_path / ("a.gif" if command == "animate" else "a.png")
        target = ["--out", str(out)] if command == "animate" else ["--screenshot", str(out)]
        argv = [command, str(sphere), "--panel", spec.name, *target, flag.name, "1" + "0" * 400]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"meshlap: error: {flag.name}: "), err
        assert not out.exists()


def test_view_help_imports_no_polyscope():
    code = (
        "import sys\n"
        "from meshlap_core.cli import main\n"
        "try:\n"
        "    main(['view', '--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "assert 'polyscope' not in sys.modules, 'polyscope imported'\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert "--panel" in res.stdout


# ---------------------------------------------------------------- Diffusion sources
def test_repeated_sources_are_one_source_and_bounded_by_the_mesh(tmp_path, sphere):
    """``[0, 0, 0]`` was three units of heat at vertex 0, and a source repeated a million
    times cost minutes: sources are kept once each, and each must be a vertex of the mesh
    (so there are at most as many as it has vertices)."""
    from meshlap_app.state.mesh import MeshState
    from meshlap_app.state.session import check_session_mesh

    spec = next(s for s in REGISTRY if "sources" in s.settings)
    s = Session(mesh=sphere)
    s.settings[spec.name]["sources"] = [7, 0, 7, 0, 0]
    back = read_session(write_session(tmp_path / "s.json", s))
    assert back.settings[spec.name]["sources"] == [7, 0]
    data = s.to_dict()
    data[spec.name]["sources"] = [3] * 1_000_000
    assert from_dict(data, "s.json").settings[spec.name]["sources"] == [3]
    mesh = MeshState()
    assert mesh.load(sphere)
    n = len(mesh.V)
    data[spec.name]["sources"] = list(range(n + 1))  # one more than the mesh has
    with pytest.raises(MeshError, match=rf'"{spec.name}.sources" has {n}; vertices are 0..'):
        check_session_mesh(from_dict(data, "s.json"), mesh, "s.json")


# ---------------------------------------------------------------- through the window's panels
ps = pytest.importorskip("polyscope")


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def _applied(viewer, spec: PanelSpec, values: dict[str, Any]) -> dict[str, Any]:
    """``values`` as the panel's section of a session applied to ``viewer`` (that panel the
    session's view), then captured back."""
    from meshlap_app import session

    s = session.capture(viewer)
    s.settings[spec.name] = dict(values)
    s.panel = spec.name if spec.view else VIEWS[0]
    s.camera = None
    session.apply(viewer, s, "s.json")
    for _ in range(3):
        ps.frame_tick()
    assert viewer.state.jobs.wait(timeout=120)
    ps.frame_tick()
    return session.capture(viewer).settings[spec.name]


def test_a_fresh_window_captures_the_declared_defaults(mock, viewer):
    from meshlap_app import session

    ps.frame_tick()
    assert session.capture(viewer).settings == default_settings()


@pytest.mark.parametrize("spec", WITH_SETTINGS, ids=_id)
def test_every_setting_changed_comes_back_through_the_panel(mock, viewer, spec):
    """Each declared setting at its sample, restored by the panel (configure / restore) and
    captured back: a panel that forgets a key, or keeps one its own way, fails here. Settings
    that would start work on restore (a basis read, a run replayed, a student's file run)
    take their declared quiet value."""
    values = {**spec.settings.samples(), **spec.settings.quiet()}
    assert _applied(viewer, spec, values) == values
    for key in spec.settings.keys():  # and back to every default
        assert key in values
    assert _applied(viewer, spec, spec.settings.defaults()) == spec.settings.defaults()


def test_repeated_sources_heat_as_one(mock, viewer):
    """The heat of a session with the source ``[0, 0, 0]`` is the heat of ``[0]`` (it was three
    times it)."""
    spec = next(s for s in REGISTRY if "sources" in s.settings)
    heats = []
    for sources in ([0], [0, 0, 0]):
        values = {**spec.settings.defaults(), "show": "heat", "sources": sources}
        s = Session(mesh=viewer.state.mesh.path, panel=spec.name)
        s.settings[spec.name] = values
        data = json.loads(json.dumps(s.to_dict()))
        _applied(viewer, spec, from_dict(data, "s.json").settings[spec.name])
        st = viewer.panels[spec.name].state
        assert st.sources == [0]
        heats.append(np.array(st.heat["euler"]))
    np.testing.assert_allclose(heats[1], heats[0])

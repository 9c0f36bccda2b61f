"""The return types of ``polyscope.imgui`` / ``implot`` calls the UI adapter was written for,
checked on every call (an API change fails loudly, naming the call)."""

from __future__ import annotations

from typing import Any

# the return types the adapter was written for (polyscope 2.6.x; pyproject pins the range)
EXPECTED: dict[str, tuple[type, ...]] = {
    "Combo": (bool, int),
    "Selectable": (bool,),
    "BeginCombo": (bool,),
    "Checkbox": (bool, bool),
    "Button": (bool,),
    "CollapsingHeader": (bool,),
    "SliderFloat": (bool, float),
    "SliderInt": (bool, int),
    "InputFloat": (bool, float),
    "InputInt": (bool, int),
    "InputText": (bool, str),
    "BeginPlot": (bool,),
    "DragPoint": (bool, float, float),
    "BeginTable": (bool,),
}


class UIApiMismatch(TypeError):
    """polyscope's imgui returned a type this adapter does not expect (its API changed)."""


def check_return(name: str, result: Any) -> Any:
    """Check ``result`` of ``polyscope.imgui.<name>`` against :data:`EXPECTED`.

    Raises
    ------
    UIApiMismatch
        When the shape or the element types differ (e.g. ``Selectable`` returning a tuple).
    """
    want = EXPECTED[name]
    got = result if len(want) > 1 else (result,)
    ok = isinstance(got, tuple) and len(got) == len(want)
    ok = ok and all(
        isinstance(g, w) and (w is not int or not isinstance(g, bool))
        for g, w in zip(got, want, strict=False)
    )
    if not ok:
        shape = " ".join(t.__name__ for t in want)
        raise UIApiMismatch(
            f"polyscope.imgui.{name} returned {result!r} ({type(result).__name__}); this viewer "
            f"expects ({shape}): the installed polyscope differs from the tested range"
        )
    return result

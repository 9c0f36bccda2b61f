"""The one progress line (``meshlap_core.progress.Progress``) as each of its users draws it."""

from __future__ import annotations

import io

from meshlap_core.progress import ERASE_LINE, Progress, bar


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_fills_the_given_count():
    assert bar(3, 10) == "###......."
    assert bar(12, 4, "#", "-") == "####" and bar(-1, 3) == "..."


def test_frames_are_redrawn_in_place_on_any_stream_and_the_line_ends():
    from meshlap_core.io.animation import frame_progress

    s = io.StringIO()
    p = frame_progress(4, stream=s)
    for i in range(1, 5):
        p.update(i)
    p.close()
    text = s.getvalue()
    assert text.count("\r") == 4 and text.endswith("] 4/4 frames\n")
    assert text.startswith("\rmeshlap: animate [#######.......................] 1/4 frames")


def test_separate_lines_off_a_terminal_and_one_erased_line_on_it():
    now = [0.0]

    def line(p: Progress) -> str:
        return f"{p.label} {p.done}/{p.total} {p.message}"

    s = io.StringIO()
    p = Progress(3, line, "work", stream=s, clock=lambda: now[0])
    for _ in range(3):
        p.step("x")
    p.close()
    assert s.getvalue() == "work 1/3 x\nwork 2/3 x\nwork 3/3 x\n"
    t = _Tty()
    p = Progress(3, line, "work", stream=t, erase=True, clock=lambda: now[0])
    p.step()
    p.close()
    assert t.getvalue() == "\rwork 1/3 " + ERASE_LINE + "\r" + ERASE_LINE


def test_the_pace_keeps_short_runs_silent_and_restart_starts_again():
    now = [0.0]
    s = io.StringIO()
    p = Progress(
        1.0, lambda p: f"{p.done:.1f}", stream=s, after_s=1.0, every_s=1.0, clock=lambda: now[0]
    )
    for t in (0.5, 1.0, 1.5, 2.2, 2.5):
        now[0] = t
        p.update(t / 10)
    assert s.getvalue().split() == ["0.1", "0.2"]
    p.restart(5, "again")
    p.update(1)
    assert p.label == "again" and s.getvalue().split() == ["0.1", "0.2"]  # the pace restarted


def test_no_stream_writes_nothing():
    p = Progress(2, lambda p: "never", stream=None)
    p.step()
    p.close()
    assert p.drawn is False

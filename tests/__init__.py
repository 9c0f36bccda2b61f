"""meshlap's tests, by subject: ``core/`` (the headless core and its command line), ``app/``
(the viewer headless, on polyscope's ``openGL_mock`` and with EGL pixels), ``window/`` (the real
window under Xvfb + xdotool, marked ``window``), ``robustness/`` (hostile input, faults, stress),
``project/`` (the repository's promises: architecture, README, docs and CI, examples, lessons,
public API).

Every folder is a package, so pytest imports a test file as ``tests.<folder>.<module>`` with the
checkout on ``sys.path`` (its default ``prepend`` import mode); the helpers the tests share live
in :mod:`tests.support` and no test module imports another. ``exercises/`` is data: the student
files the exercises checker is tested with.
"""

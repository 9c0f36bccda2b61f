"""Helpers the tests share, imported as ``tests.support.<module>`` (no test module imports
another): the hostile-input corpus, the scripted UI adapter and polyscope's quantity ledger, the
widget drivers of every panel (:mod:`tests.support.drivers`), the real-window harness (Xvfb,
xdotool, screenshots read by layout) and small shared pieces (meshes, the window page's keys,
student files, whether EGL starts)."""

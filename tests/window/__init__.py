"""The viewer in a real window: ``meshlap view`` under Xvfb, driven with xdotool like a user.
Every test that opens one is marked ``window`` (``pytest -m "not window"`` leaves them out)."""

"""Hostile input as a test tier: the hostile corpus through every command, faults injected
around every writer, resource limits, one test per cause found, and stress."""

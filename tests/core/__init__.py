"""Tests of the headless core (``meshlap_core``) and its command line."""

"""Tests of the viewer (``meshlap_app``): its state headless, its widgets driven through the
scripted UI adapter on polyscope's ``openGL_mock`` backend, and real pixels with EGL."""

"""Package list for setuptools (metadata is in pyproject.toml).

The viewer's folder ``app/`` is installed under the unambiguous import name ``meshlap_app``
(``package_dir`` mapping; ``import app`` does not work once installed). ``find_packages`` keeps
finding every sub-package of both, so new sub-packages need no edit here.
"""

from setuptools import find_packages, setup

core = find_packages(include=["meshlap_core", "meshlap_core.*"])
viewer = ["meshlap_app", *(f"meshlap_app.{p}" for p in find_packages("app"))]
setup(packages=core + viewer, package_dir={"meshlap_app": "app"})

"""Compatibility name: the report lives in :mod:`meshlap_core.study` (``meshlap report``)."""

from __future__ import annotations

from .study import (
    ASSETS_DIR,
    COURSE_EIGEN_SECONDS,
    PACKAGE_ROOT,
    SECTION_TITLES,
    SECTIONS,
    Progress,
    ReportResult,
    build_report,
    default_meshes_dir,
    parse_sections,
)

__all__ = [
    "ASSETS_DIR",
    "COURSE_EIGEN_SECONDS",
    "PACKAGE_ROOT",
    "SECTIONS",
    "SECTION_TITLES",
    "Progress",
    "ReportResult",
    "build_report",
    "default_meshes_dir",
    "parse_sections",
]

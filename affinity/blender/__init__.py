"""Lint the mesh being edited in Blender: conversion, findings, and the extension's UI.

``mesh_from_object(obj)`` and ``findings(obj, **settings)`` are the public entry
points (design.md, "Blender"). Importing this package does not import ``bpy``;
only :mod:`affinity.blender.addon` (the extension's panel and operators) does,
and nothing outside this package imports that. Version-specific API lives in
:mod:`affinity.blender.compat`.
"""

from .check import findings
from .convert import mesh_from_object

__all__ = ["findings", "mesh_from_object"]

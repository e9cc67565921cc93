"""Collection of the packages' doctests (``--doctest-modules``): the Blender integration is
imported only where Blender's ``bpy`` module is installed (CI runs it in a venv of its own)."""

import importlib.util

collect_ignore_glob = [] if importlib.util.find_spec("bpy") else ["affinity/blender/*"]

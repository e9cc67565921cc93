"""Collection of the packages' doctests (``--doctest-modules``): the Blender integration is
imported only where Blender's ``bpy`` module is installed (CI runs it in a venv of its own).

The USD plug-in module registers its validators with USD when it is imported, which only USD's
plug-in system can make it do (tests/test_usd_validators.py runs it so, through
``PXR_PLUGINPATH_NAME``); the NVIDIA rules need usd-validation-nvidia (the dev extra)."""

import importlib.util

collect_ignore_glob = [] if importlib.util.find_spec("bpy") else ["affinity/blender/*"]
collect_ignore = ["affinity/usd/validators.py"]
if importlib.util.find_spec("usd_validation_nvidia") is None:
    collect_ignore.append("affinity/usd/nvidia.py")

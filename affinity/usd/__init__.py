"""quad-affinity inside USD's validators: a UsdValidation plug-in and a usd-validation-nvidia rule set.

- :mod:`affinity.usd.validators` is the plug-in module that ``plugin/plugInfo.json``
  names: imported by USD's plug-in registry (found through ``PXR_PLUGINPATH_NAME``,
  the folder ``affinity usd-plugin`` prints), it registers one validator per rule
  family (:func:`affinity.usd.families.families`) under the keyword ``quad-affinity``.
  Registration happens there and only there: importing :mod:`affinity` or this
  package costs nothing (no ``pxr``).
- :mod:`affinity.usd.nvidia` is the ``usd_validation_nvidia`` entry point: one rule
  class per family in the category ``quad-affinity``.
- :mod:`affinity.usd.stage` checks an open stage as ``affinity check`` checks its file
  (same loader, settings, lint and sharing of referenced geometry);
  :mod:`affinity.usd.fixing` writes ``affinity fix``'s refinement of a prim to an edit target
  (through ``affinity fix``'s USD writer, :mod:`affinity.fix.usdlayer`).

Both need usd-core 26.11 or newer (Python validators and constructible fixers):
:func:`usd_too_old` says so on older ones, where ``affinity check`` keeps reading stages.
"""

from __future__ import annotations

from pathlib import Path

#: The folder holding ``plugInfo.json``, for ``PXR_PLUGINPATH_NAME``.
PLUGIN_FOLDER = Path(__file__).resolve().parent / "plugin"
#: The oldest usd-core whose UsdValidation registers Python validators with fixers, as ``Usd.GetVersion()``.
REQUIRED_USD = (0, 26, 11)
#: The keyword every validator and rule answers to.
KEYWORD = "quad-affinity"


def usd_too_old() -> str | None:
    """One line saying what is missing when the installed usd-core cannot host the plug-in, else None."""
    try:
        from pxr import Usd
    except ImportError:
        return "the USD plug-in needs usd-core 26.11 or newer: pip install 'quad-affinity[usd]'"
    version = tuple(Usd.GetVersion())
    if version < REQUIRED_USD:
        found = ".".join(map(str, version[1:]))
        return f"the USD plug-in needs usd-core 26.11 or newer (found {found}): pip install -U 'quad-affinity[usd]'"
    return None

"""``affinity usd-plugin``: print the folder of the USD plug-in's ``plugInfo.json``.

Add it to ``PXR_PLUGINPATH_NAME`` and every USD application (``usdchecker``, a DCC,
a Python ``UsdValidation.ValidationContext``) finds the validators of the keyword
``quad-affinity``: ``export PXR_PLUGINPATH_NAME=$(affinity usd-plugin)``. Where the
installed usd-core cannot host them (older than 26.11, or missing) it says so on
stderr and exits 2, printing nothing a shell would put on the path.
"""

from __future__ import annotations

import sys

from . import EXIT_CLEAN, EXIT_ERROR


def add_parser(sub) -> None:
    p = sub.add_parser(
        "usd-plugin", help="print the folder to add to PXR_PLUGINPATH_NAME for the USD validators",
        description="Print the folder holding quad-affinity's UsdValidation plugInfo.json. "
                    "export PXR_PLUGINPATH_NAME=$(affinity usd-plugin) makes usdchecker and every USD "
                    "application find the validators of the keyword quad-affinity (usd-core 26.11 or newer).",
    )
    p.set_defaults(run=run)


def run(args) -> int:
    from ..usd import PLUGIN_FOLDER, usd_too_old

    problem = usd_too_old()
    if problem is not None:
        sys.stderr.write(f"affinity usd-plugin: error: {problem}\n")
        return EXIT_ERROR
    sys.stdout.write(f"{PLUGIN_FOLDER}\n")
    return EXIT_CLEAN

"""File names as a terminal shows them (:func:`affinity.loaders.names.printable`), where the formats import them.

The function lives in the core's ``loaders`` package, whose ``__init__`` imports no rule: a rule naming a file
(Q902) escapes it without importing this package, whose ``__init__`` imports the rules.
"""

from ..loaders.names import printable

__all__ = ["printable"]

"""Shared command-line plumbing."""

import pytest

from affinity.commands import require
from affinity.errors import UsageError


def test_require_names_the_missing_module_and_the_extra():
    require(("numpy",), "report")  # present: no error
    with pytest.raises(UsageError,
                       match=r"needs no_such_module_q, the report extra: pip install 'quad-affinity\[report\]'"):
        require(("numpy", "no_such_module_q"), "report")

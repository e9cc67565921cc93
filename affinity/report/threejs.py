"""three.js for the report's 3-D view, as one classic script the page can inline.

The page is self-contained and its Content-Security-Policy allows inline
scripts only, so ES modules (which import by URL) cannot be loaded as they are.
The vendored build is two modules, ``three.core.min.js`` and
``three.module.min.js`` (the second imports the first); each becomes a function
body whose ``import`` is a destructuring of the first's result and whose
``export`` list is its return value. The vendored files stay byte-for-byte the
npm package's.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

VENDOR = Path(__file__).parent / "vendor"
CORE, MODULE = "three.core.min.js", "three.module.min.js"
#: ``import{A as b,C}from"./three.core.min.js";`` and ``export{A as b,C}from"...";`` / ``export{A as b,C};``.
IMPORT = re.compile(r'import\{([^}]*)\}from"\./([^"]+)";')
RE_EXPORT = re.compile(r'export\{[^}]*\}from"\./[^"]+";')
EXPORT = re.compile(r"export\{([^}]*)\};?\s*$")


def _pairs(names: str) -> list[tuple[str, str]]:
    """``"A as b,C"`` -> ``[("A", "b"), ("C", "C")]``: the names before and after ``as`` (an import's are
    (exported, local), an export's (local, exported))."""
    pairs = []
    for item in filter(None, (part.strip() for part in names.split(","))):
        before, _, after = item.partition(" as ")
        pairs.append((before.strip(), (after or before).strip()))
    return pairs


def module_as_function(text: str, modules: dict[str, str]) -> str:
    """The ES module ``text`` as a function expression ``function(){...; return {exports}}``.

    ``modules`` maps an imported file name to the JavaScript expression holding
    its exports (already evaluated). Re-exports (``export{...}from``) are dropped:
    the caller merges the imported module's exports itself. Raises ValueError on a
    module shape this does not handle (another three.js build layout).
    """
    def destructure(match: re.Match) -> str:
        if match.group(2) not in modules:
            raise ValueError(f"three.js: unexpected import of {match.group(2)}")
        pairs = ",".join(f"{exported}:{local}" for exported, local in _pairs(match.group(1)))
        return "const{" + pairs + "}=" + modules[match.group(2)] + ";"

    body = RE_EXPORT.sub("", IMPORT.sub(destructure, text))
    exports = EXPORT.search(body)
    if exports is None or "import{" in body[:200] or "export{" in body[: exports.start()]:
        raise ValueError("three.js: the module's exports are not one final export list")
    returned = ",".join(f"{exported}:{local}" for local, exported in _pairs(exports.group(1)))
    return f'function(){{"use strict";{body[: exports.start()]}\nreturn{{{returned}}};}}'


@functools.cache
def three_script() -> str:
    """A classic script defining the global ``THREE`` (every export of the vendored build)."""
    core = module_as_function((VENDOR / CORE).read_text(encoding="utf-8"), {})
    module = module_as_function((VENDOR / MODULE).read_text(encoding="utf-8"), {CORE: "core"})
    return f"var THREE=(function(){{const core=({core})();return Object.assign({{}},core,({module})());}})();"

"""usd-core's diagnostics while a stage opens, as notes: never printed raw (design.md, Clarifications).

usd-core posts a warning per composed prim for the same problem (a look layer's
reference to a ``.mtlx`` document, which it cannot compose, is one warning for each
piece that references the look). :func:`captured_diagnostics` traps them with
``Tf.DiagnosticTrap`` (usd-core 26.x) and turns them into one note per distinct
problem, naming the layer and the asset. Errors are not trapped: usd-core raises them
as ``Tf.ErrorException``, which the loader reports as Q901.
"""

from __future__ import annotations

import os
import re
from contextlib import contextmanager

_UNOPENED = re.compile(r"Could not open asset @(?P<asset>[^@]*)@ for (?P<arc>\w+) introduced by "
                       r"@(?P<layer>[^@]*)@(?:<(?P<prim>[^>]*)>)? -- (?P<reason>.*?)(?: for @[^@]*@)?\.?$")
_CONTEXT = re.compile(r"^In <[^>]*>: |\s*\(instantiating stage on stage @[^@]*@ <0x[0-9a-f]+>\)|"
                      r"pxrInternal_v\w+?__pxrReserved__::")


@contextmanager
def captured_diagnostics(folder: str, notes: list[str]):
    """Trap usd-core's warnings and status messages inside the block and append one note per distinct problem
    to ``notes`` (paths relative to ``folder``: the working directory's, so that every file of a run that composes
    the same layer says the same note); without ``pxr`` the block runs as it is."""
    try:
        from pxr import Tf
    except ImportError:
        yield
        return
    with Tf.DiagnosticTrap() as trap:
        try:
            yield
        finally:
            said = [diagnostic.commentary for diagnostic in (*trap.GetWarnings(), *trap.GetStatuses())]
            trap.ClearWarnings()
            trap.ClearStatuses()
            for note in diagnostic_notes(said, folder):
                if note not in notes:
                    notes.append(note)


def diagnostic_notes(commentaries: list[str], folder: str) -> list[str]:
    """One note per distinct problem of usd-core's diagnostic ``commentaries``, in the order first said.

    >>> said = ("In </Set/A/Materials>: Could not open asset @/s/a/x.mtlx@ for reference introduced by "
    ...         "@/s/a/look.usd@</X/Materials> -- Cannot determine file format for @/s/a/x.mtlx:SDF_FORMAT_ARGS:"
    ...         "target=usd@. (instantiating stage on stage @/s/set.usda@ <0x5560>)")
    >>> notes = diagnostic_notes([said, said.replace("/Set/A/", "/Set/B/")], "/s")
    >>> len(notes), notes[0][:70]
    (1, 'a/look.usd references a/x.mtlx (at </X/Materials>), which usd-core can')
    """
    notes = []
    for commentary in commentaries:
        text = " ".join(_CONTEXT.sub("", commentary).split())
        match = _UNOPENED.search(text)
        if match is not None:
            note = _unopened_note(match, folder)
        else:
            note = f"usd-core: {text}"
        if note not in notes:
            notes.append(note)
    return notes


def _unopened_note(match, folder: str) -> str:
    """The note of an arc usd-core could not open: which layer names which asset, and what becomes of it."""
    layer, asset = (_shown(match.group(name), folder) for name in ("layer", "asset"))
    at = f" (at <{match.group('prim')}>)" if match.group("prim") else ""
    reason = match.group("reason").rstrip(".")
    reason = reason[:1].lower() + reason[1:]
    if asset.lower().endswith(".mtlx"):
        return (f"{layer} references {asset}{at}, which usd-core cannot compose ({reason}): its materials are read "
                "from its MaterialX XML")
    return f"{layer}: the {match.group('arc')} to {asset}{at} cannot be opened ({reason}): not composed"


def _shown(path: str, folder: str) -> str:
    """``path`` relative to ``folder`` where it lies inside it, else as it is (a relative path: as the working
    directory resolves it)."""
    path = os.path.abspath(path)
    if folder:
        relative = os.path.relpath(path, folder)
        if not relative.startswith(os.pardir):
            return relative
    return path

"""The rule registry: one :class:`Rule` record per code carries everything that varies by rule.

Lint (:mod:`affinity.lint`), the report, routing by lint, the SARIF rule
descriptions, ``affinity rules``/``affinity rule`` and the README's rule table all
read :data:`RULES`; nothing else lists rules. A rule is its check, decorated with
its facts; the check's docstring is the rule's page (as ruff keeps a rule's doc
and check in one file).

Every check has one signature, ``check(context) -> Measured``: the context holds
the ``mesh``, the ``settings`` and the ``faces`` the check measures (a batch of
the mesh's quads for a rule of scope ``"quad"``, with what several rules share
computed once: :class:`affinity.lint.QuadBatch`; the file itself, face -1, for
a rule of scope ``"mesh"``: :class:`affinity.lint.WholeMesh`), and the check
returns its values on some of those faces (:class:`Measured`). A check measures;
it never reads its own threshold: lint compares the values with it. Adding a
rule is one decorated function (tests/test_rule_registry.py runs this one)::

    import numpy as np

    from affinity.rules import Measured, rule


    @rule(code="Q999", name="long-edge", unit="units", default_threshold=1.0, family="QuadShape")
    def long_edge(context) -> Measured:
        '''A quad has an edge longer than the threshold.

        What it does:
            Measures each quad's longest edge, in the mesh's units.
        Why it matters:
            A long edge spans many texels.
        Example:
            # a 2 by 1 rectangle
            v 0 0 0
            v 2 0 0
            v 2 1 0
            v 0 1 0
            f 1 2 3 4
        Prints:
            example.obj:6:1: Q999 warning long-edge: a quad has an edge longer than the threshold (2 vs 1 units) [face 0]
        Use instead:
            # the rectangle cut into two unit squares
            v 0 0 0
            v 1 0 0
            v 2 0 0
            v 2 1 0
            v 1 1 0
            v 0 1 0
            f 1 2 5 6
            f 2 3 4 5
        References:
            None: an example.
        How to fix:
            Subdivide the quad.
        '''
        return Measured(slice(None), np.asarray(context.planar.size))

Codes never change; names are kebab-case.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

LEVELS = ("error", "warning", "info")


@dataclass(frozen=True)
class Measured:
    """What every check returns: its values on some of its context's faces.

    Attributes
    ----------
    rows : (n,) int64 positions in ``context.faces``, or a slice (every face of the context)
    values : (n,) float64 in the rule's unit, whatever the threshold (lint compares them with it)
    lines : (n,) int64 source line of each value where it is not its face's (a finding on the file,
        face -1, sits on the statement that caused it: Q902's ``mtllib`` line); None: the faces' lines
    details : one remark per value, said after the rule's summary (Q902 names the resource); None: none
    """

    rows: np.ndarray | slice
    values: np.ndarray
    lines: np.ndarray | None = None
    details: list[str | None] | None = None

    @classmethod
    def nothing(cls) -> Measured:
        """No value: the check found nothing to measure."""
        return cls(np.zeros(0, dtype=np.int64), np.zeros(0))


@dataclass(frozen=True, kw_only=True)
class Rule:
    """Everything about one rule.

    Attributes
    ----------
    code, name : ``"Q101"``, ``"uv-disaffine"``
    summary : one line: what a finding means
    level : ``"error"``, ``"warning"`` or ``"info"`` (overridable per rule)
    unit : the unit of the measured values (``"texels"``, ``"1/255"``, ``"degrees"``)
    default_threshold : the threshold in ``unit``; None for a rule without one
    visible_threshold : the visibility threshold in ``unit``: a finding above it is an ``error``
        (the crease is plainly visible), one between ``default_threshold`` and it gets ``level``;
        None: every finding gets ``level``
    flags : ``"above"`` (values above the threshold are flagged) or ``"at-or-below"``
    worst : ``"highest"`` or ``"lowest"``: which end of the values is the worst
    attribute : the Mesh field read besides the positions (``"texcoords"``,
        ``"colors"``, ``"normals"``), or None
    scored : the rule is an affinity score of its attribute: every quad gets a value
        (the report's histograms, the hybrid's ``--route lint``)
    readings : measure -> (unit, default threshold) where a ``--measure`` reading
        changes them (Q101's dimensionless barycentric score)
    visible_reading : its findings on quads that bind a readable texture are read through it: C, with the
        shift kept beside it (design.md, "The visible reading"; Q101)
    mirroring : a finding is a texture mirrored against the surface: its report close-up draws an
        asymmetric glyph in texture space (a symmetric pattern looks the same mirrored)
    folding : a finding is the split folding along its diagonal: its report close-up draws the shaded surface,
        lit across the fold, with the diagonal (texture lines are affine on either triangle and show no fold)
    family : the validator family that reports the rule inside USD (:data:`FAMILIES`: one UsdValidation
        validator and one NVIDIA rule each, :mod:`affinity.usd.families`)
    masks : the attributes (Mesh fields) whose scored rules this rule's defect takes over: where
        ``unmeasurable`` holds, they are not measured (design.md, "One finding per defect")
    unmeasurable : ``unmeasurable(context) -> (Q,) bool``, with ``masks``: the quads of a batch whose
        defect makes the masked scores meaningless; run whether or not the rule is selected
    cause : with ``masks``: what a finding of this rule says where it took the scored rules' place
        (``"it has no area"``, then ``", so Q101 is not measured on it"``)
    fix_leaves : the reason ``affinity fix`` gives for a flagged quad this rule also flags and that it leaves
        (``"degenerate"``); "": fix does not look at this rule
    fix_precedence : where several ``fix_leaves`` rules flag one quad, the lowest precedence names the reason
    fix_uncut : a quad this rule flags is never cut to meet a refined neighbour (a cut of its bilinear patch
        would fold, or each of its pieces would carry the finding again: a uv-degenerate quad's pieces are all
        uv-degenerate): it keeps its line and the neighbour's refinement closes to it
    scope : the faces a check's context holds: ``"quad"``, a batch of the mesh's quads
        (:class:`affinity.lint.QuadBatch`); ``"mesh"``, the file itself as face -1
        (:class:`affinity.lint.WholeMesh`: Q205, Q902)
    check : ``check(context) -> Measured``, the measure, vectorized over the context's faces
    bound : ``bound(context) -> (Q,) float64``, optional and cheap: a bound on each quad's value on the side the
        rule flags (above: a value is at most its bound), so that a quad whose bound is not flagged cannot be.
        Lint measures only the quads whose bound is flagged at the threshold; a scored rule measures every
        quad. The check itself never reads its threshold (Q203: no reflex corner, so at most 180 degrees)
    what, why, fix : the page's *What it does*, *Why it matters*, *How to fix*
    example : a 4- to 8-line OBJ that triggers this rule and no other
    example_output : the text lines ``affinity check`` prints for ``example``
        saved as ``example.obj`` (a test lints it and compares)
    example_flags : the command-line flags the example is checked with (Q106: ``--subdivision limit``, an OBJ
        is a cage otherwise); its page shows them
    use_instead : ``example`` fixed the way ``fix`` says: an input ``affinity check`` finds clean
        (ruff's second half of a rule's page; a test lints it)
    references : the paper and section the rule comes from
    """

    code: str
    name: str
    summary: str
    level: str = "warning"
    unit: str = ""
    default_threshold: float | None = None
    visible_threshold: float | None = None
    flags: str = "above"
    worst: str = "highest"
    attribute: str | None = None
    scored: bool = False
    visible_reading: bool = False
    mirroring: bool = False
    folding: bool = False
    readings: Mapping[str, tuple[str, float]] = field(default_factory=dict)
    family: str = ""
    masks: tuple[str, ...] = ()
    unmeasurable: Callable | None = None
    cause: str = ""
    fix_leaves: str = ""
    fix_precedence: int = 0
    fix_uncut: bool = False
    scope: str = "quad"
    check: Callable | None = None
    bound: Callable | None = None
    what: str
    why: str
    example: str
    example_output: str = ""
    example_flags: tuple[str, ...] = ()
    use_instead: str = ""
    fix: str
    references: str = ""

    @property
    def has_threshold(self) -> bool:
        return self.default_threshold is not None

    def unit_for(self, measure: str) -> str:
        """The unit of the values under the ``measure`` reading."""
        return self.readings.get(measure, (self.unit, None))[0]

    def default_for(self, measure: str) -> float | None:
        """The default threshold under the ``measure`` reading."""
        return self.readings.get(measure, (None, self.default_threshold))[1]

    def visible_for(self, measure: str) -> float | None:
        """The default visibility threshold under the ``measure`` reading (None where the reading
        changes the unit: the barycentric score has no calibrated visibility threshold)."""
        return None if measure in self.readings else self.visible_threshold

    def flagged(self, values: np.ndarray, threshold: float) -> np.ndarray:
        """(n,) bool: which of ``values`` (n,) the rule flags at ``threshold``."""
        return values <= threshold if self.flags == "at-or-below" else values > threshold


#: Every lint rule by code, in code order.
RULES: dict[str, Rule] = {}
#: The validator families by name, in the order they were registered: name -> their one-line doc (what their
#: rules find, after the codes: :func:`family_doc`). Every rule names one (:attr:`Rule.family`).
FAMILIES: dict[str, str] = {}


def register_family(name: str, doc: str) -> str:
    """Add validator family ``name`` (a UsdValidation validator's name, ``UvAffinity``) with its ``doc``."""
    if name in FAMILIES:
        raise ValueError(f"family {name} is registered already")
    FAMILIES[name] = doc
    return name


def family_codes(name: str) -> tuple[str, ...]:
    """The codes of the rules of family ``name``, in code order."""
    return tuple(code for code, rule in RULES.items() if rule.family == name)


def family_doc(name: str) -> str:
    """``quad-affinity Q201-Q205, Q902: <doc>``: the family's codes (:func:`code_spans`) and its doc."""
    return f"quad-affinity {code_spans(family_codes(name))}: {FAMILIES[name]}"


def code_spans(codes) -> str:
    """``codes`` (in code order) as text, runs of consecutive codes as ranges: ``Q201-Q205, Q902``."""
    runs: list[list[str]] = []
    for code in codes:
        if runs and code[0] == runs[-1][-1][0] and int(code[1:]) == int(runs[-1][-1][1:]) + 1:
            runs[-1].append(code)
        else:
            runs.append([code])
    return ", ".join(run[0] if len(run) == 1 else f"{run[0]}-{run[-1]}" for run in runs)


def fix_left_rules() -> list[Rule]:
    """The rules whose flagged quads ``affinity fix`` leaves (:attr:`Rule.fix_leaves`), the one that names the
    reason first (:attr:`Rule.fix_precedence`)."""
    return sorted((rule for rule in RULES.values() if rule.fix_leaves), key=lambda rule: rule.fix_precedence)


def fix_uncut_rules() -> list[Rule]:
    """The rules whose flagged quads a refined neighbour never cuts (:attr:`Rule.fix_uncut`), in code order."""
    return [rule for rule in RULES.values() if rule.fix_uncut]


def masking_rules(attribute: str | None = None) -> list[Rule]:
    """The rules whose defect takes over scored rules (:attr:`Rule.masks`), in code order: those masking
    ``attribute`` where given."""
    return [rule for rule in RULES.values() if rule.masks and (attribute is None or attribute in rule.masks)]


def register(rule: Rule) -> Rule:
    """Add ``rule`` to :data:`RULES` (kept in code order); a code is registered once."""
    if rule.code in RULES:
        raise ValueError(f"rule {rule.code} is registered already")
    if rule.level not in LEVELS or rule.scope not in ("quad", "mesh") or rule.flags not in ("above", "at-or-below"):
        raise ValueError(f"rule {rule.code}: level, scope or flags out of range")
    if rule.family not in FAMILIES:
        raise ValueError(f"rule {rule.code}: family {rule.family!r} is not registered (register_family)")
    if bool(rule.masks) != (rule.unmeasurable is not None) or (rule.masks and not rule.cause):
        raise ValueError(f"rule {rule.code}: masks, unmeasurable and cause go together")
    RULES[rule.code] = rule
    ordered = sorted(RULES.items())
    RULES.clear()
    RULES.update(ordered)
    return rule


#: The page's headings in a check's docstring -> the Rule field each fills.
PAGE_HEADINGS = {
    "What it does": "what", "Why it matters": "why", "Example": "example", "Prints": "example_output",
    "Use instead": "use_instead", "References": "references", "How to fix": "fix",
}
#: Sections kept line by line (files and output); the others are prose, joined into one paragraph.
VERBATIM = frozenset({"example", "example_output", "use_instead"})


def page_fields(doc: str) -> dict[str, str]:
    r"""The Rule fields a rule's page gives: ``summary`` (the first line, as a message reads
    it: lower-case start, no full stop) and one field per heading of :data:`PAGE_HEADINGS`.

    >>> page = page_fields('''Two triangles disagree.
    ...
    ...     What it does:
    ...         Measures the
    ...         disagreement.
    ...     Example:
    ...         v 0 0 0
    ...         f 1 1 1
    ...     ''')
    >>> page["summary"], page["what"], page["example"]
    ('two triangles disagree', 'Measures the disagreement.', 'v 0 0 0\nf 1 1 1\n')
    """
    import inspect

    first, *rest = inspect.cleandoc(doc).splitlines()
    fields: dict[str, list[str]] = {}
    current = None
    for line in rest:
        heading = line.strip().rstrip(":")
        if line and not line.startswith(" ") and heading in PAGE_HEADINGS:
            current = PAGE_HEADINGS[heading]
            fields[current] = []
        elif current is not None:
            fields[current].append(line[4:] if line.startswith("    ") else line.strip())
    page = {"summary": first[:1].lower() + first[1:].rstrip(".")}
    for name, lines in fields.items():
        while lines and not lines[-1].strip():
            lines.pop()
        page[name] = "\n".join(lines) + "\n" if name in VERBATIM else " ".join(x.strip() for x in lines if x.strip())
    return page


def rule(**facts) -> Callable[[Callable], Callable]:
    """Register the decorated check as a rule: ``facts`` are the Rule's fields, the check's
    docstring its page (:func:`page_fields`); a field given in ``facts`` wins over the page."""

    def register_check(check: Callable) -> Callable:
        register(Rule(**{**page_fields(check.__doc__ or ""), **facts, "check": check}))
        return check

    return register_check


def unregister(code: str) -> None:
    """Remove a rule registered at run time (tests, plug-ins)."""
    del RULES[code]


def resolve_codes(select: list[str] | None, ignore: list[str] | None) -> list[str]:
    """Rule codes enabled by ``select``/``ignore`` prefixes (``"Q1"``, ``"Q101"``, ``"ALL"``)."""

    def matches(code: str, prefixes: list[str]) -> bool:
        return any(p == "ALL" or code.startswith(p.upper()) for p in prefixes)

    codes = [c for c in RULES if select is None or matches(c, select)]
    return [c for c in codes if not (ignore and matches(c, ignore))]

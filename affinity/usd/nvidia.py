"""quad-affinity as rules of ``usd-validation-nvidia`` (``nvidia_usd_validate``).

The package's ``usd_validation_nvidia`` entry point is :class:`QuadAffinityPlugin`;
its ``on_startup`` registers one rule class per family of
:func:`affinity.usd.families.families` (``UvAffinityChecker``, ...) in the category
``quad-affinity`` (``nvidia_usd_validate -c quad-affinity``). A rule reports each
finding at its mesh prim (for a mesh several prims take from one geometry layer, the
first of them; the message names the layer and every referencing prim) through
``_AddError``, ``_AddWarning`` or ``_AddInfo`` by the finding's level, with the message
of the UsdValidation plug-in. Errors and warnings
of the affinity families carry a ``Suggestion`` that writes ``affinity fix``'s
refinement of the prim (of every referencing prim) to the edit target the fixer
chooses (``--fix``): NVIDIA's fixer picks the strongest layer with an opinion on the
prim and saves it in place.
"""

from __future__ import annotations

from usd_validation_nvidia import BaseRuleChecker, Suggestion, register_rule, unregister_rule

from . import KEYWORD
from .families import Family, families

CATEGORY = KEYWORD


class _FamilyChecker(BaseRuleChecker):
    """A quad-affinity family as a rule; subclasses set :attr:`family`."""

    family: Family

    def CheckPrim(self, prim) -> None:
        from pxr import UsdGeom

        from ..rules.wording import unreadable_line
        from .stage import exception_reason, family_findings, finding_message

        if not prim.IsA(UsdGeom.Mesh):
            return
        try:
            said = family_findings(self.family, prim)
        except Exception as error:  # the validator's run goes on: one error naming the prim
            self._AddError(message=unreadable_line(str(prim.GetPath()), exception_reason(error)), at=prim)
            return
        for note in said.notes:
            self._AddInfo(message=f"note: {note}", at=prim)
        if said.unreadable is not None:
            self._AddError(message=unreadable_line(str(prim.GetPath()), said.unreadable), at=prim)
        for f in said.findings:
            if f.level == "info":
                self._AddInfo(message=finding_message(f), at=prim)
                continue
            suggestion = _refinement(f.code, f.prims or [str(prim.GetPath())]) if self.family.fixable else None
            add = self._AddError if f.level == "error" else self._AddWarning
            add(message=finding_message(f), at=prim, suggestion=suggestion)


def _refinement(code: str, prim_paths: list[str]) -> Suggestion:
    """The Suggestion that refines the quads rule ``code`` flags on ``prim_paths`` (every prim referencing
    a shared mesh: the issue is sited at the first, as NVIDIA's fixer takes one site per issue)."""

    def refine(stage, at) -> None:
        from .fixing import refine_prims

        refine_prims(stage, prim_paths, code, stage.GetEditTarget())

    return Suggestion(callable=refine, message=f"Refine the quads {code} flags (affinity fix)")


def _checker(family: Family) -> type:
    """The rule class of ``family``, documented by the family's line."""
    return type(f"{family.name}Checker", (_FamilyChecker,), {"family": family, "__doc__": family.doc,
                                                              "__module__": __name__})


CHECKERS = tuple(_checker(family) for family in families())


class QuadAffinityPlugin:
    """The ``usd_validation_nvidia`` entry point: registers (and unregisters) the family rules."""

    def on_startup(self) -> None:
        for checker in CHECKERS:
            register_rule(CATEGORY)(checker)

    def on_shutdown(self) -> None:
        for checker in CHECKERS:
            unregister_rule(checker)

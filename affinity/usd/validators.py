"""The UsdValidation plug-in module: importing it registers quad-affinity's validators.

USD's plug-in registry imports this module (``plugin/plugInfo.json`` names it) the
first time a validator of ours is asked for. Each family of
:func:`affinity.usd.families.families` becomes the prim validator
``affinity.usd.validators:<Family>`` for ``UsdGeomMesh`` prims, with the keyword
``quad-affinity``. It runs on the stage as ``affinity check`` runs on its file
(:mod:`affinity.usd.stage`: the same loader, the settings that govern the root
layer's file, one report per geometry layer that several prims reference) and
returns one ``ValidationError`` per finding:

- name: the rule's name (``uv-disaffine``); type: ``Error``, ``Warn`` or ``Info`` from the
  finding's level;
- sites: the prim (or, for a mesh several prims reference, every one of them and the
  geometry layer with the prim path there);
- message: ``/prim face F: CODE name: message (value vs threshold unit)``, as a line
  of ``affinity check``.

The affinity families carry a fixer, ``RefineQuads``, that writes ``affinity fix``'s
refinement of the finding's prims to the edit target (:mod:`affinity.usd.fixing`, with
``affinity fix``'s own USD writer); ``ApplyFix`` then saves that layer. Problems never reach the host application as
exceptions: a prim that cannot be read is one ``Error`` (``unreadable``, from
``QuadShape``), naming the prim and why. The loader's notes (e.g. that the numbers
are for the subdivision cage) are ``Info`` errors named ``note`` on the stage's first
mesh prim, from ``UvAffinity``.
"""

from __future__ import annotations

from pxr import Sdf, UsdValidation

from ..rules.wording import unreadable_line
from . import KEYWORD, usd_too_old
from .families import Family, families
from .stage import exception_reason

MODULE = __name__
#: The finding's level -> the error's type.
ERROR_TYPES = {"error": UsdValidation.ValidationErrorType.Error, "warning": UsdValidation.ValidationErrorType.Warn,
               "info": UsdValidation.ValidationErrorType.Info}
FIXER = "RefineQuads"
FIXER_DOC = ("Refine the flagged quads of the prim (affinity fix: each into n x n pieces on its own bilinear "
             "surface, neighbours re-cut without T-junctions) and write the mesh to the edit target.")


def _site(stage, prim_path: str):
    return UsdValidation.ValidationErrorSite(stage, Sdf.Path(prim_path))


def _finding_error(stage, finding):
    """The ValidationError of one finding (see the module docstring)."""
    from .stage import finding_message

    sites = [_site(stage, prim) for prim in finding.prims or [finding.prim or finding.group]]
    layer = Sdf.Layer.Find(finding.layer) if finding.layer else None
    if layer is not None:
        sites.append(UsdValidation.ValidationErrorSite(layer, Sdf.Path(finding.layer_prim)))
    return UsdValidation.ValidationError(finding.name, ERROR_TYPES[finding.level], sites, finding_message(finding))


def family_errors(family: Family, prim) -> list:
    """The errors of ``family`` on ``prim`` (:func:`affinity.usd.stage.family_findings`)."""
    from .stage import family_findings

    stage, path = prim.GetStage(), str(prim.GetPath())
    said = family_findings(family, prim)
    errors = [UsdValidation.ValidationError("note", UsdValidation.ValidationErrorType.Info, [_site(stage, path)],
                                            f"note: {note}") for note in said.notes]
    if said.unreadable is not None:
        errors.append(_unreadable(stage, path, said.unreadable))
    return errors + [_finding_error(stage, f) for f in said.findings]


def _unreadable(stage, path: str, reason: str):
    return UsdValidation.ValidationError("unreadable", UsdValidation.ValidationErrorType.Error, [_site(stage, path)],
                                         unreadable_line(path, reason))


def _validator(family: Family):
    """``fn(prim, timeRange)`` for the registry: :func:`family_errors`, an exception turned into one error."""

    def validate(prim, time_range):
        try:
            return family_errors(family, prim)
        except Exception as error:  # a host application must get an error, never an exception
            return [_unreadable(prim.GetStage(), str(prim.GetPath()), exception_reason(error))]

    return validate


def _fixer(family: Family):
    """The ``RefineQuads`` fixer of an affinity family, tied to its rule's error name."""
    from ..rules import RULES

    [code] = family.codes
    error_name = RULES[code].name

    def sites(error) -> tuple:
        prims = [site for site in error.GetSites() if site.GetPrim()]
        return prims[0].GetStage(), [str(site.GetPrim().GetPath()) for site in prims]

    def apply(error, edit_target, time_code) -> bool:
        from .fixing import refine_prims

        try:
            return error.GetName() == error_name and refine_prims(*sites(error), code, edit_target)
        except Exception:  # a failed fix, not an exception in the host
            return False

    def can_apply(error, edit_target, time_code) -> bool:
        from .fixing import can_refine

        try:  # ApplyFix saves the target's layer: one in memory cannot take the fix
            return (error.GetName() == error_name and edit_target.IsValid() and not edit_target.GetLayer().anonymous
                    and can_refine(*sites(error), code))
        except Exception:
            return False

    return UsdValidation.ValidationFixer(FIXER, FIXER_DOC, apply, can_apply, [KEYWORD], error_name)


def register() -> None:
    """Register every family's validator (and fixer) under ``affinity.usd.validators:<Family>``."""
    registry = UsdValidation.ValidationRegistry()
    for family in families():
        fixers = [_fixer(family)] if family.fixable else []
        registry.RegisterPluginPrimValidator(f"{MODULE}:{family.name}", _validator(family), fixers)


if usd_too_old() is not None:
    raise ImportError(usd_too_old())
register()

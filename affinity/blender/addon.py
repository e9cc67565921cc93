"""The Blender extension: a sidebar panel, Check / Fix / Select / Next operators, the results list.

This is the only module of the project that imports ``bpy`` at import time; it is
imported by the extension's ``__init__.py`` (written by
:mod:`affinity.blender.build`) inside Blender, and by nothing in ``affinity``.

Flow: **Check** converts every selected mesh object (:mod:`.convert`), lints it
(:mod:`.check`) and fills the results list with one row per object and rule:
count, worst value and unit. **Select** (a row's button) selects that row's
faces in Edit Mode; **Next** selects and frames the row's next worst face. With
*Write affinity_error* on, Check also stores the per-face error as the float face
attribute ``affinity_error`` and paints it into the colour attribute
``affinity_error_color`` that the viewport's Attribute colouring shows. **Fix**
refines the selected flagged faces of the active object as ``affinity fix`` does
(:mod:`.fix`), all its flagged faces when none is selected.
"""

from __future__ import annotations

import bpy
import numpy as np
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from ..rules import LEVELS, RULES, number_text, with_unit
from ..settings import DIAGONALS, MEASURES, Settings
from . import compat
from .check import check_object, face_error, severity
from .convert import ERROR_ATTRIBUTE, ERROR_COLOR, polygon_corners
from .fix import fix_object
from .materials import material_images

#: Rules the panel offers: the per-face and per-mesh ones (Q9xx are about files).
PANEL_RULES = [code for code in RULES if not code.startswith("Q9")]
THRESHOLDED = [code for code in PANEL_RULES if RULES[code].default_threshold is not None]
#: The affinity scores: what the Measure reading and the Fix button apply to.
SCORED = [code for code in PANEL_RULES if RULES[code].scored]

#: (object name, rule code) -> (faces of the object's original mesh, worst first).
#: Kept in Python: face lists have no fitting property type. A reload of the
#: extension empties it; Select and Next then ask for a new Check.
_FLAGGED: dict[tuple[str, str], np.ndarray] = {}


def _settings_annotations() -> dict:
    defaults = Settings()
    fields = {
        "measure": EnumProperty(
            name="Measure", default=defaults.measure,
            items=[(m, m.capitalize(), f"{', '.join(SCORED)} reading: {m}") for m in MEASURES],
        ),
        "diagonal": EnumProperty(
            name="Diagonal", default=defaults.diagonal,
            items=[(d, d, f"split diagonal measured: {d}") for d in DIAGONALS],
        ),
        "texture_size": IntProperty(
            name="Texture size", default=0, min=0, soft_max=16384,
            description="Pixels for the texel unit of faces whose material reads no image "
                        f"(0: {defaults.texture_size})",
        ),
        "use_modifiers": BoolProperty(
            name="With modifiers", default=False,
            description="Lint the evaluated mesh; findings map back to the original faces",
        ),
        "uv_layer": StringProperty(name="UV map", description="UV map to lint; empty takes the active one"),
        "write_error": BoolProperty(
            name=f"Write {ERROR_ATTRIBUTE}", default=False,
            description=f"Store the per-face error as the face attribute {ERROR_ATTRIBUTE} and show it "
                        f"as the colour attribute {ERROR_COLOR}",
        ),
        "fix_level": EnumProperty(
            name="Fix level", default="warning",
            items=[(level, level.capitalize(), f"Fix {', '.join(SCORED)} findings at {level} and above")
                   for level in reversed(LEVELS)],
        ),
        "max_refine": IntProperty(
            name="Max refine", default=8, min=2, soft_max=32,
            description="Refine a face into at most N x N faces; one that needs more is left (re-UV it)",
        ),
        "results": CollectionProperty(type=AFFINITY_PG_result),
        "results_index": IntProperty(name="Result"),
        "notes": StringProperty(name="Notes"),
        "checked": IntProperty(name="Checked", description="Objects the last Check linted"),
    }
    for code in PANEL_RULES:
        rule = RULES[code]
        fields["use_" + code] = BoolProperty(name=code, default=True, description=rule.summary)
        if code in THRESHOLDED:
            fields["threshold_" + code] = FloatProperty(
                name=rule.unit or "score", default=rule.default_threshold, min=-1.0, precision=3,
                description=f"{code} {rule.name}: flag beyond this value ({rule.unit or 'dimensionless'})",
            )
    return fields


class AFFINITY_PG_result(bpy.types.PropertyGroup):
    object_name: StringProperty(name="Object")
    code: StringProperty(name="Rule")
    rule_name: StringProperty(name="Name")
    count: IntProperty(name="Count")
    worst: FloatProperty(name="Worst")
    unit: StringProperty(name="Unit")
    selectable: BoolProperty(name="Selectable", default=True)
    cursor: IntProperty(name="Next", default=-1, description="The face Next showed last")


AFFINITY_PG_settings = type(
    "AFFINITY_PG_settings", (bpy.types.PropertyGroup,), {"__annotations__": _settings_annotations()}
)


def lint_options(props) -> dict:
    """The panel's properties as keyword arguments of :func:`.check.check_object`."""
    options = {
        "select": [code for code in PANEL_RULES if getattr(props, "use_" + code)],
        "thresholds": {code: getattr(props, "threshold_" + code) for code in THRESHOLDED},
        "measure": props.measure,
        "diagonal": props.diagonal,
        "evaluated": props.use_modifiers,
        "uv_layer": props.uv_layer or None,
    }
    for code in THRESHOLDED:
        if reading_changes_unit(code, props.measure):
            # The panel's threshold is in the rule's own unit (texels), meaningless for this reading's
            # (the dimensionless barycentric score): the reading keeps its own default.
            del options["thresholds"][code]
    if props.texture_size > 0:
        options["texture_size"] = props.texture_size
    return options


def reading_changes_unit(code: str, measure: str) -> bool:
    """Whether rule ``code`` reads ``measure`` in a unit of its own (the rule registry's ``readings``)."""
    return measure in RULES[code].readings


def worst_text(row) -> str:
    """A results row's worst value with its unit, as ``affinity check`` writes a value: ``3.2 texels``,
    ``12/255``."""
    return with_unit(number_text(row.worst), row.unit)


def selected_meshes(context) -> list:
    return [obj for obj in context.selected_objects if obj.type == "MESH"]


def _ensure_mode(context, mode: str) -> None:
    if context.mode != ("EDIT_MESH" if mode == "EDIT" else "OBJECT"):
        bpy.ops.object.mode_set(mode=mode)


def _error_colors(error: np.ndarray) -> np.ndarray:
    """(F, 4) float32 sRGB: grey for 0, yellow at the limit (1.0) to red at 4x and beyond."""
    t = np.clip(np.log2(np.maximum(error, 1.0)) / 2.0, 0.0, 1.0)
    rgba = np.empty((len(error), 4), dtype=np.float32)
    rgba[:] = (0.8, 0.8, 0.8, 1.0)
    flagged = error > 0
    rgba[flagged, 0] = 1.0
    rgba[flagged, 1] = 0.85 * (1.0 - t[flagged])
    rgba[flagged, 2] = 0.0
    return rgba


def write_error_attribute(mesh, error: np.ndarray) -> None:
    """Store ``error`` (F,) as the face attribute and its colours on the corners, made active.

    Parameters
    ----------
    mesh : bpy.types.Mesh in Object Mode
    error : (F,) float32, see :func:`.check.face_error`
    """
    attribute = mesh.attributes.get(ERROR_ATTRIBUTE) or mesh.attributes.new(ERROR_ATTRIBUTE, "FLOAT", "FACE")
    attribute.data.foreach_set("value", error)
    color = mesh.color_attributes.get(ERROR_COLOR) or mesh.color_attributes.new(ERROR_COLOR, "BYTE_COLOR", "CORNER")
    face_start, loops = polygon_corners(mesh)
    face_of_loop = np.empty(len(loops), dtype=np.int64)
    face_of_loop[loops] = np.repeat(np.arange(len(face_start) - 1), np.diff(face_start))
    color.data.foreach_set("color_srgb", _error_colors(error)[face_of_loop].ravel())
    mesh.color_attributes.active_color = color
    mesh.update()


def select_faces(context, obj, faces: np.ndarray) -> None:
    """Select exactly ``faces`` (polygon indices of ``obj``) and nothing else, in Edit Mode (face select)."""
    view_layer = context.view_layer
    _ensure_mode(context, "OBJECT")
    view_layer.objects.active = obj
    obj.select_set(True)
    mesh = obj.data
    face = np.zeros(len(mesh.polygons), dtype=bool)
    face[faces] = True
    face_start, loops = polygon_corners(mesh)
    selected_loops = loops[np.repeat(face, np.diff(face_start))]
    vertex = np.zeros(len(mesh.vertices), dtype=bool)
    vertex[compat.read_ints(mesh.loops, "vertex_index")[selected_loops]] = True
    edge = np.zeros(len(mesh.edges), dtype=bool)
    edge[compat.read_ints(mesh.loops, "edge_index")[selected_loops]] = True
    mesh.vertices.foreach_set("select", vertex)
    mesh.edges.foreach_set("select", edge)
    mesh.polygons.foreach_set("select", face)
    context.tool_settings.mesh_select_mode = (False, False, True)
    bpy.ops.object.mode_set(mode="EDIT")


class AFFINITY_OT_check(bpy.types.Operator):
    """Lint the selected mesh objects for quad affinity and shape problems"""

    bl_idname = "affinity.check"
    bl_label = "Check"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a set)

    @classmethod
    def poll(cls, context):
        return bool(selected_meshes(context))

    def execute(self, context):
        props = context.scene.affinity
        objects = selected_meshes(context)
        was_edit = context.mode == "EDIT_MESH"
        _ensure_mode(context, "OBJECT")
        props.results.clear()
        notes, total = [], 0
        for key in [k for k in _FLAGGED if k[0] in {o.name for o in objects}]:
            del _FLAGGED[key]
        for obj in objects:
            try:
                result = check_object(obj, **lint_options(props))
            except ValueError as error:
                notes.append(str(error))
                continue
            mapping = result.conversion.original_face
            notes.extend(f"{obj.name}: {note}" for note in result.notes)
            for hits in result.hits:
                rank = severity(hits)
                order = np.argsort(-rank, kind="stable")
                row = props.results.add()
                row.object_name, row.code, row.rule_name = obj.name, hits.code, RULES[hits.code].name
                row.count, row.worst = len(hits), float(hits.values[order[0]])
                row.unit = hits.units()[order[0]]
                row.selectable = bool(mapping is not None and hits.faces[0] >= 0)
                if row.selectable:
                    faces = mapping[hits.faces[order]]
                    faces = faces[faces >= 0]
                    _, first = np.unique(faces, return_index=True)  # a subdivided face once, at its worst
                    _FLAGGED[obj.name, hits.code] = faces[np.sort(first)]
                total += len(hits)
            if props.write_error and mapping is not None:
                write_error_attribute(obj.data, face_error(result.hits, mapping, len(obj.data.polygons)))
        props.notes = "\n".join(notes)
        props.checked = len(objects)
        props.results_index = 0
        if was_edit:
            bpy.ops.object.mode_set(mode="EDIT")
        self.report({"INFO"}, f"{total} findings in {len(objects)} object(s)")
        return {"FINISHED"}


class AFFINITY_OT_fix(bpy.types.Operator):
    """Refine the selected flagged faces (all flagged faces when none is selected) until their crease is
    gone; the faces beside them are re-cut so nothing cracks"""

    bl_idname = "affinity.fix"
    bl_label = "Fix"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a set)

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def execute(self, context):
        props = context.scene.affinity
        obj = context.active_object
        was_edit = context.mode == "EDIT_MESH"
        _ensure_mode(context, "OBJECT")
        selected = np.zeros(len(obj.data.polygons), dtype=bool)
        obj.data.polygons.foreach_get("select", selected)
        faces = np.flatnonzero(selected) if was_edit and selected.any() else None
        try:
            plan = fix_object(obj, faces, level=props.fix_level, max_refine=props.max_refine, **lint_options(props))
        except ValueError as error:
            self.report({"WARNING"}, str(error))
            return {"CANCELLED"}
        if was_edit:
            bpy.ops.object.mode_set(mode="EDIT")
        left = ", ".join(f"{count} {reason}" for reason, count in zip(*np.unique(plan.left_reasons,
                                                                                  return_counts=True)))
        self.report({"INFO"}, f"{len(plan.refine_faces)} faces refined, {len(plan.transition_faces)} re-cut, "
                              f"{plan.faces_added:+d} faces" + (f"; left: {left}" if left else ""))
        return {"FINISHED"}


def _row(context, index: int):
    props = context.scene.affinity
    index = props.results_index if index < 0 else index
    return props.results[index] if 0 <= index < len(props.results) else None


def _flagged_faces(operator, row):
    """The row's faces (worst first), or None after telling the user why there are none."""
    if row is None:
        operator.report({"WARNING"}, "No result row: run Check first")
        return None
    if not row.selectable:
        operator.report({"WARNING"}, f"{row.code} on {row.object_name}: no faces to select")
        return None
    faces = _FLAGGED.get((row.object_name, row.code))
    obj = bpy.data.objects.get(row.object_name)
    if faces is None or obj is None:
        operator.report({"WARNING"}, "Results are out of date: run Check again")
        return None
    return obj, faces


class _RowOperator:
    """Mixin of the operators that act on one results row's faces."""

    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a set)

    index: IntProperty(name="Row", default=-1, description="Results row; -1 takes the active one")

    def execute(self, context):
        row = _row(context, self.index)
        found = _flagged_faces(self, row)
        if found is None:
            return {"CANCELLED"}
        self.act(context, row, *found)
        return {"FINISHED"}


class AFFINITY_OT_select(_RowOperator, bpy.types.Operator):
    """Select the faces this rule flagged, in Edit Mode"""

    bl_idname = "affinity.select"
    bl_label = "Select Flagged"

    def act(self, context, row, obj, faces):
        select_faces(context, obj, faces)
        self.report({"INFO"}, f"{len(faces)} faces selected on {obj.name}")


class AFFINITY_OT_next(_RowOperator, bpy.types.Operator):
    """Select the next worst face this rule flagged and frame it in the view"""

    bl_idname = "affinity.next"
    bl_label = "Next"

    def act(self, context, row, obj, faces):
        row.cursor = (row.cursor + 1) % len(faces)
        select_faces(context, obj, faces[row.cursor : row.cursor + 1])
        if context.area is not None and context.area.type == "VIEW_3D":
            bpy.ops.view3d.view_selected()
        self.report({"INFO"}, f"{row.code} on {obj.name}: face {faces[row.cursor]} "
                              f"({row.cursor + 1} of {len(faces)})")


class AFFINITY_UL_results(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        row.label(text=f"{item.code} {item.rule_name}")
        row.label(text=f"{item.count}")
        row.label(text=worst_text(item))
        row.label(text=item.object_name)
        button = row.row(align=True)
        button.enabled = item.selectable
        button.operator(AFFINITY_OT_select.bl_idname, text="", icon="RESTRICT_SELECT_OFF").index = index
        button.operator(AFFINITY_OT_next.bl_idname, text="", icon="VIEWZOOM").index = index


def texture_line(obj, props) -> str:
    """What the panel says about the texel unit of the active object's active material.

    As in ``affinity check``, an image the material reads sets the unit (its size, as a file's
    header does; Blender reads it, file, packed, generated or UDIM alike); the size set here
    counts only where no image is read.
    """
    material = obj.active_material if obj is not None and obj.type == "MESH" else None
    image = next((use.image for use in material_images(material)), None) if material is not None else None
    if image is not None and image.source == "TILED":
        return f"Texture: {image.name}, {len(image.tiles)} UDIM tiles (read by Blender)"
    if image is not None:
        return f"Texture: {image.name} {image.size[0]} x {image.size[1]} px (read by Blender)"
    if props.texture_size > 0:
        return f"Texture size: {props.texture_size} px (set here)"
    return f"Texture size: {Settings().texture_size} px (no image)"


class AFFINITY_PT_panel(bpy.types.Panel):
    bl_label = "Quad Affinity"
    bl_idname = "AFFINITY_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Affinity"

    def draw(self, context):
        layout = self.layout
        props = context.scene.affinity
        rules = layout.box()
        rules.label(text="Rules")
        for code in PANEL_RULES:
            row = rules.row(align=True)
            row.prop(props, "use_" + code, text=f"{code} {RULES[code].name}")
            if code in THRESHOLDED:
                sub = row.row(align=True)
                sub.enabled = getattr(props, "use_" + code) and not reading_changes_unit(code, props.measure)
                sub.prop(props, "threshold_" + code, text="")
        layout.prop(props, "measure")
        layout.prop(props, "diagonal")
        layout.prop(props, "texture_size")
        layout.label(text=texture_line(context.active_object, props))
        obj = context.active_object
        if obj is not None and obj.type == "MESH":
            layout.prop_search(props, "uv_layer", obj.data, "uv_layers", text="UV map")
        layout.prop(props, "use_modifiers")
        layout.prop(props, "write_error")
        layout.operator(AFFINITY_OT_check.bl_idname)
        row = layout.row(align=True)
        row.prop(props, "fix_level", text="")
        row.prop(props, "max_refine")
        row.operator(AFFINITY_OT_fix.bl_idname)
        for line in filter(None, props.notes.split("\n")):
            layout.label(text=line, icon="INFO")
        if len(props.results):
            layout.template_list("AFFINITY_UL_results", "", props, "results", props, "results_index", rows=4)
            row = layout.row(align=True)
            row.operator(AFFINITY_OT_select.bl_idname)
            row.operator(AFFINITY_OT_next.bl_idname)
        elif props.checked:
            layout.label(text=f"No findings in {props.checked} object(s)")


CLASSES = (
    AFFINITY_PG_result,
    AFFINITY_PG_settings,
    AFFINITY_OT_check,
    AFFINITY_OT_fix,
    AFFINITY_OT_select,
    AFFINITY_OT_next,
    AFFINITY_UL_results,
    AFFINITY_PT_panel,
)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.affinity = PointerProperty(type=AFFINITY_PG_settings)


def unregister():
    del bpy.types.Scene.affinity
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
    _FLAGGED.clear()

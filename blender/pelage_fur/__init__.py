"""pelage fur for Blender: "Grow pelage fur" on the active mesh.

Reads the active object's evaluated mesh (with its active UV map), grows a
pelage groom on it (a groom file, or the panel's count, length, clump,
curl and noise), and fills a native hair Curves object parented to the
mesh (the same one on every grow), bound to it for Blender's Deform Curves on Surface. The panel lives
in the 3D Viewport's sidebar (N), tab "pelage"; "Export USD" and "Export
Alembic" write the same groom with pelage's own writers.
"""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)
from bpy_extras.io_utils import ExportHelper, ImportHelper

from pelage import PelageError

from . import fur, stack


#: The panel's presets: settings, with lengths and widths as fractions of
#: the object's largest dimension (so a preset suits a mouse or a bear).
PRESETS = {
    "SHORT": dict(count=200_000, guides=300, length=0.03, width=0.0004, gravity=0.2, points=8,
                  clump=0.3, curl=0.0, noise=0.1),
    "LONG": dict(count=120_000, guides=400, length=0.12, width=0.0008, gravity=0.6, points=16,
                 clump=0.6, curl=0.0, noise=0.15),
    "CURLY": dict(count=120_000, guides=300, length=0.06, width=0.0006, gravity=0.2, points=24,
                  clump=0.4, curl=0.6, noise=0.05),
    "STUBBLE": dict(count=300_000, guides=200, length=0.008, width=0.0002, gravity=0.0, points=4,
                    clump=0.0, curl=0.0, noise=0.2),
}
SIZED = ("length", "width")


def _sized(settings, context):
    """Marks Length and Width as the user's own (a first grow no longer sizes
    them to the object), then regrows live fur."""
    settings.sized = True
    _setting_changed(settings, context)


def apply_preset(settings, context):
    """Fills the panel from the chosen preset, its lengths and widths scaled by
    the active object's size."""
    values = PRESETS.get(settings.preset)
    obj = context.active_object if context is not None else None
    if values is None or obj is None:
        return
    size = max(obj.dimensions) or 1.0
    for name, value in values.items():
        setattr(settings, name, value * size if name in SIZED else value)


def _setting_changed(settings, context):
    """Any panel setting's update: schedules a whole regrow of live fur."""
    fur.on_setting_change(settings, context)


def _live_toggled(settings, context):
    """Live ticked or unticked: arms the surface's grown fur (without a
    Grow) or stops following the guides."""
    fur.on_live_toggled(settings, context)


class PelageOpSetting(bpy.types.PropertyGroup):
    """One setting of a stacked operator: its name, and its value as the
    groom file writes it."""

    value: StringProperty(
        name="Value",
        update=_setting_changed,
        description="A number, a list ([0.3, 0.2, 0.1]) or a map: vertex:GROUP (a vertex group or "
                    "attribute), image:NAME:r (a Blender image, saved or not), file.png:r, "
                    "noise:frequency=8; empty: pelage's default",
    )


class PelageOp(bpy.types.PropertyGroup):
    """An operator of the stack: its name and its settings."""

    kind: StringProperty(name="Operator")
    enabled: BoolProperty(name="Enabled", description="Apply this operator", default=True,
                          update=_setting_changed)
    settings: CollectionProperty(type=PelageOpSetting)


class PelageFurSettings(bpy.types.PropertyGroup):
    """What the panel grows (per object)."""

    preset: EnumProperty(
        name="Preset",
        description="Fill the settings below for a kind of fur, sized to the object",
        items=[
            ("CUSTOM", "Custom", "The settings as they are"),
            ("SHORT", "Short fur", "Dense short fur, lightly clumped"),
            ("LONG", "Long fur", "Long clumped fur that hangs"),
            ("CURLY", "Curly", "Curled locks"),
            ("STUBBLE", "Stubble", "Very short, very dense, straight"),
        ],
        default="CUSTOM",
        update=apply_preset,
    )
    groom_file: StringProperty(
        name="Groom file",
        description="A pelage groom file (.toml); its [mesh] is replaced by this object. Empty: use the settings below",
        subtype="FILE_PATH",
    )
    guides_object: PointerProperty(
        type=bpy.types.Object,
        name="Guides",
        description="A hair Curves object on this surface whose curves shape the fur "
                    "(Add › Curves › Empty Hair, sculpted with Blender's brushes); empty: guides grown here",
        poll=lambda _settings, obj: obj.type == "CURVES",
    )
    density_group: StringProperty(
        update=_setting_changed,
        name="Density",
        description="A vertex group, a float attribute or a colour attribute (NAME, or one channel: "
                    "NAME:r, NAME:g, NAME:b, NAME:a), or a Blender image over the UV map "
                    "(image:NAME:r), whose values scale where hairs grow; empty: evenly",
    )
    parting: EnumProperty(
        update=_setting_changed,
        name="Parting",
        description="Regions whose hairs take no shape or clumps from one another's guides",
        items=[
            ("NONE", "None", "One region: every guide shapes every hair near it"),
            ("FACE_SETS", "Face sets", "Each sculpt face set a region"),
            ("MATERIALS", "Material slots", "Each material slot a region"),
            ("ATTRIBUTE", "Face attribute", "Each value of an integer face attribute a region"),
        ],
        default="NONE",
    )
    parting_attribute: StringProperty(
        update=_setting_changed,
        name="Attribute",
        description="The integer face attribute whose values are the parting's regions",
    )
    live: BoolProperty(
        update=_live_toggled,
        name="Live",
        description="Regrow the fur as the guides object is sculpted: the hairs near the stroke only",
        default=False,
    )
    display_fraction: FloatProperty(
        update=_setting_changed,
        name="Display Fraction",
        description="Share of the hairs a live groom shows (the same hairs as the whole groom); "
                    "exports write them all",
        default=1.0, min=0.01, max=1.0,
    )
    last_grow: StringProperty(
        name="Last grow",
        description="What the last grow made (filled by Grow pelage fur)",
        options={"SKIP_SAVE"},
    )
    count: IntProperty(update=_setting_changed, name="Count", description="Hairs", default=20_000, min=1, soft_max=2_000_000)
    guides: IntProperty(update=_setting_changed, name="Guides", description="Guide curves grown on the surface", default=200, min=1, soft_max=5_000)
    length: FloatProperty(update=_sized, name="Length", description="Guide length (first grow: 4% of the object's size)", default=0.05, min=1e-5, soft_max=1.0, subtype="DISTANCE")
    width: FloatProperty(update=_sized, name="Width", description="Hair width at the root (first grow: 0.06% of the object's size)", default=0.002, min=0.0, soft_max=0.01, subtype="DISTANCE", precision=4)
    gravity: FloatProperty(update=_setting_changed, name="Gravity", description="Pull of the guides downward (world -Z)", default=0.3, min=0.0, max=1.0)
    points: IntProperty(update=_setting_changed, name="Points", description="Points per hair", default=12, min=2, max=64)
    clump: FloatProperty(update=_setting_changed, name="Clump", description="How far hairs pull toward clump centres (0: off)", default=0.4, min=0.0, max=1.0)
    curl: FloatProperty(update=_setting_changed, name="Curl", description="Curl radius, relative to the length (0: off)", default=0.0, min=0.0, max=2.0)
    noise: FloatProperty(update=_setting_changed, name="Noise", description="Noise amplitude, relative to the length (0: off)", default=0.1, min=0.0, max=2.0)
    seed: IntProperty(update=_setting_changed, name="Seed", default=1, min=0)
    sized: BoolProperty(
        name="Sized", description="Length and Width were set (by hand, a preset, or sized to the object)",
        default=False, options={"HIDDEN"},
    )
    interpolation: EnumProperty(
        update=_setting_changed,
        name="Interpolation",
        description="How guides shape the hairs between them",
        items=[
            ("SHEPARD", "Nearest guides", "The k nearest guide roots, weighted by 1/d² (Sik)"),
            ("STYLE_MESH", "Style mesh", "Over the surface (Furtility): thin parts do not borrow guides "
                                         "from their other side"),
        ],
        default="SHEPARD",
    )
    interpolation_k: IntProperty(
        update=_setting_changed, name="Guides a Hair", description="Nearest guides that shape a hair",
        default=4, min=1, max=32,
    )
    outside_skin: BoolProperty(
        update=_setting_changed, name="Out of the Skin",
        description="Push every hair point that noise, curl or a guide put under the skin back out, "
                    "keeping lengths (pelage's [finish] outside_skin; slower)",
        default=False,
    )
    ops: CollectionProperty(
        type=PelageOp, name="Operators",
        description="Every pelage operator, applied top to bottom; when it has any, it replaces "
                    "Clump, Curl and Noise",
    )
    active_op: IntProperty(name="Active operator", default=0)
    # Animated export: how the fur moves over the scene's frames.
    animation_mode: EnumProperty(
        name="Motion",
        description="How exported animated fur moves with the surface",
        items=[
            ("DEFORM", "Deform", "Grown once at the first frame and carried by the surface: fast, nothing swims"),
            ("SIMULATE", "Simulate", "The guides simulated on the moving surface (the scene's gravity, "
                                     "inertia, collisions with the body), the fur regrown from them every frame"),
        ],
        default="DEFORM",
    )
    sim_follow: FloatProperty(name="Follow", description="Pull toward the groomed shape, 0 to 1 a 60th of a second",
                              default=0.05, min=0.0, max=1.0)
    sim_bend: FloatProperty(name="Stiffness", description="Bending stiffness, 0 to 1 a 60th of a second",
                            default=0.3, min=0.0, max=1.0)
    sim_damping: FloatProperty(name="Damping", description="Velocity decay per second", default=1.0, min=0.0,
                               soft_max=20.0)
    sim_collide: BoolProperty(name="Collide", description="Keep the guides out of the surface", default=True)
    sim_preroll: IntProperty(name="Pre-roll", description="Frames simulated at the first frame's pose before it",
                             default=12, min=0, soft_max=100)
    # The look: Principled Hair BSDF (Chiang) values, Cycles' defaults.
    melanin: FloatProperty(update=_setting_changed, name="Melanin", description="Hair pigment, 0 white to 1 black", default=0.8, min=0.0, max=1.0)
    melanin_redness: FloatProperty(update=_setting_changed, name="Redness", description="Share of red pheomelanin in the pigment", default=1.0, min=0.0, max=1.0)
    roughness: FloatProperty(update=_setting_changed, name="Roughness", description="Longitudinal roughness: how far highlights spread along hairs", default=0.3, min=0.0, max=1.0)
    radial_roughness: FloatProperty(update=_setting_changed, name="Radial Roughness", description="Azimuthal roughness: how far light spreads around hairs", default=0.3, min=0.0, max=1.0)
    look_jitter: FloatProperty(update=_setting_changed, name="Variation", description="Per-hair variation of pigment and roughness, a fraction", default=0.1, min=0.0, max=1.0)
    skin_color: BoolProperty(update=_setting_changed, name="Colour from Skin",
                             description="When the mesh's material takes its Base Color from an image, the fur takes "
                                         "its colour there at each root, and its pigment from that colour (the look's "
                                         "melanin and redness are not used)", default=True)


def surface_of(context):
    """The active object when it is a mesh (the surface fur grows on), else
    None."""
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


class PELAGE_OT_grow_fur(bpy.types.Operator):
    """Grow pelage fur on the active mesh as a hair Curves object (Esc cancels a long grow)"""

    bl_idname = "pelage.grow_fur"
    bl_label = "Grow pelage fur"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        """Grows on a mesh only."""
        return surface_of(context) is not None

    def execute(self, context):
        """Grows on this thread to the end (scripts), with the window manager's
        progress."""
        # Scripts: on this thread, to the end.
        surface = surface_of(context)
        settings = surface.pelage_fur
        wm = context.window_manager
        wm.progress_begin(0, 1)
        try:
            obj, grown, warnings = fur.grow_on_object(
                context, surface, settings, progress=lambda done, total: wm.progress_update(done / total)
            )
        except PelageError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        return self.done(surface, grown, warnings)

    def done(self, surface, grown, warnings):
        """Reports the grow: the guides left out as warnings, then the counts."""
        for warning in warnings:
            self.report({"WARNING"}, f"pelage: {warning}")
        self.report({"INFO"}, f"pelage: {grown.curve_count:,} hairs, {grown.point_count:,} points on {surface.name}")
        return {"FINISHED"}

    def invoke(self, context, _event):
        """Starts the grow on a worker thread and watches it from a timer (the
        panel's button)."""
        # The panel's button: pelage grows on a worker thread (it lets go
        # of Python while it works), Blender stays responsive, the status
        # bar shows the parts done, and Esc stops it between parts with
        # nothing changed.
        import threading

        surface = surface_of(context)
        try:
            self._prepared = fur.PreparedGrow(context, surface, surface.pelage_fur)
        except PelageError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self._surface_name = surface.name
        self._state = {"done": 0, "total": 1, "result": None, "error": None, "cancel": False}

        def progress(done, total):
            """The worker's progress: counts the parts done, and stops between
            parts once Esc was pressed."""
            self._state["done"], self._state["total"] = done, total
            if self._state["cancel"]:
                raise fur.Cancelled()

        def work():
            """The worker thread: grows the curves, keeping any error for the
            main thread to report."""
            try:
                self._state["result"] = fur.grow_curves(self._prepared, progress)
            except BaseException as error:  # reported on the main thread
                self._state["error"] = error

        self._thread = threading.Thread(target=work, daemon=True)
        self._thread.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        """Each timer tick: the status bar's progress, Esc's cancel, and the
        fur put in place when the worker is done."""
        if event.type == "ESC":
            self._state["cancel"] = True
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            # The viewport and the panel keep working while pelage grows.
            return {"PASS_THROUGH"}
        state = self._state
        if self._thread.is_alive():
            context.workspace.status_text_set(
                f"pelage: growing, part {state['done']} of {state['total']} (Esc cancels)")
            return {"RUNNING_MODAL"}
        context.window_manager.event_timer_remove(self._timer)
        context.workspace.status_text_set(None)
        error = state["error"]
        if isinstance(error, fur.Cancelled):
            self.report({"WARNING"}, "pelage: grow cancelled; the fur is as it was")
            return {"CANCELLED"}
        if isinstance(error, PelageError):
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        if error is not None:
            raise error
        surface = bpy.data.objects.get(self._surface_name)
        if surface is None:
            self.report({"ERROR"}, "pelage: the mesh was deleted while its fur grew")
            return {"CANCELLED"}
        grown, session = state["result"]
        _, warnings = fur.finish_grow(surface, surface.pelage_fur, self._prepared, grown, session)
        return self.done(surface, grown, warnings)


_OPERATOR_ITEMS = []


def operator_items(_self, _context):
    """The library's operators, for the Add menu (kept referenced: Blender
    reads the strings after the call)."""
    if not _OPERATOR_ITEMS:
        _OPERATOR_ITEMS.extend((op["name"], op["name"].replace("_", " ").title(), op["summary"])
                               for op in stack.schema())
    return _OPERATOR_ITEMS


class PELAGE_OT_op_add(bpy.types.Operator):
    """Add a pelage operator to the end of the stack"""

    bl_idname = "pelage.op_add"
    bl_label = "Add operator"
    bl_options = {"REGISTER", "UNDO"}
    bl_property = "kind"

    kind: EnumProperty(name="Operator", items=operator_items)

    @classmethod
    def poll(cls, context):
        """Needs a mesh whose stack to add to."""
        return surface_of(context) is not None

    def invoke(self, context, _event):
        """Opens a search over the library's operators."""
        context.window_manager.invoke_search_popup(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        """Appends the chosen operator with its schema's starting values and
        makes it active."""
        surface = surface_of(context)
        settings = surface.pelage_fur
        stack.add_entry(settings.ops, self.kind, max(surface.dimensions) or 1.0)
        settings.active_op = len(settings.ops) - 1
        return {"FINISHED"}


class PELAGE_OT_op_remove(bpy.types.Operator):
    """Remove the active operator from the stack"""

    bl_idname = "pelage.op_remove"
    bl_label = "Remove operator"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        """Needs a stack with an entry to remove."""
        surface = surface_of(context)
        return surface is not None and len(surface.pelage_fur.ops) > 0

    def execute(self, context):
        """Removes the active entry; the one after it (or the last) becomes
        active."""
        settings = surface_of(context).pelage_fur
        settings.ops.remove(settings.active_op)
        settings.active_op = min(settings.active_op, max(0, len(settings.ops) - 1))
        return {"FINISHED"}


class PELAGE_OT_op_move(bpy.types.Operator):
    """Move the active operator up or down the stack (operators apply top to bottom)"""

    bl_idname = "pelage.op_move"
    bl_label = "Move operator"
    bl_options = {"REGISTER", "UNDO"}

    direction: EnumProperty(items=[("UP", "Up", ""), ("DOWN", "Down", "")])

    @classmethod
    def poll(cls, context):
        """Needs a stack of two entries or more."""
        surface = surface_of(context)
        return surface is not None and len(surface.pelage_fur.ops) > 1

    def execute(self, context):
        """Swaps the active entry with its neighbour above or below; it stays
        active."""
        settings = surface_of(context).pelage_fur
        at = settings.active_op
        to = at - 1 if self.direction == "UP" else at + 1
        if 0 <= to < len(settings.ops):
            settings.ops.move(at, to)
            settings.active_op = to
        return {"FINISHED"}


class PELAGE_OT_load_groom(bpy.types.Operator, ImportHelper):
    """Fill the panel from a pelage groom file: roots, grown guides, finish, look and the operator stack"""

    bl_idname = "pelage.load_groom"
    bl_label = "Load groom file into panel"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        """Needs a mesh whose panel to fill."""
        return surface_of(context) is not None

    def execute(self, context):
        """Reads the groom file into the panel, warning about what the panel
        has no place for."""
        surface = surface_of(context)
        try:
            left = stack.load_into(surface.pelage_fur, self.filepath, max(surface.dimensions) or 1.0)
        except (OSError, ValueError) as error:
            self.report({"ERROR"}, f"{self.filepath}: {error}")
            return {"CANCELLED"}
        surface.pelage_fur.groom_file = ""
        if left:
            self.report({"WARNING"}, f"pelage: the panel has no place for {', '.join(left)}; "
                                     "set the file as Groom file to use them")
        self.report({"INFO"}, f"pelage: loaded {self.filepath}, {len(surface.pelage_fur.ops)} operators")
        return {"FINISHED"}


class PELAGE_OT_save_groom(bpy.types.Operator, ExportHelper):
    """Save the panel as a pelage groom file (the guides object's curves beside it, as usdc)"""

    bl_idname = "pelage.save_groom"
    bl_label = "Save panel as groom file"
    bl_options = {"REGISTER"}
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        """Needs a mesh whose panel is the groom (not a Groom file)."""
        surface = surface_of(context)
        return surface is not None and not surface.pelage_fur.groom_file

    def execute(self, context):
        """Writes the groom file, its maps and the guides beside it, and names
        them."""
        surface = surface_of(context)
        try:
            written = fur.save_groom_file(context, surface, surface.pelage_fur, self.filepath)
        except (PelageError, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"pelage: wrote {', '.join(written)}")
        return {"FINISHED"}


class PELAGE_UL_ops(bpy.types.UIList):
    """The operator stack, one row an operator."""

    def draw_item(self, _context, layout, _data, item, _icon, _active_data, _active_property, _index=0):
        """One operator's row: enabled, its name, the settings given, and a
        mask icon when masked."""
        row = layout.row(align=True)
        row.prop(item, "enabled", text="")
        row.label(text=item.kind.replace("_", " ").title())
        filled = [s.name for s in item.settings if s.value.strip() and s.name != "mask"]
        row.label(text=", ".join(filled))
        if any(s.name == "mask" and s.value.strip() for s in item.settings):
            row.label(text="", icon="MOD_MASK")


class PELAGE_OT_shade_hair(bpy.types.Operator):
    """Give the selected hair curves that carry pelage's per-hair look (a
    pelage USD file imported by Blender's USD importer) the pelage hair
    material, which reads it"""

    bl_idname = "pelage.shade_hair"
    bl_label = "Shade with pelage hair"
    bl_options = {"REGISTER", "UNDO"}

    @staticmethod
    def shadeable(context):
        """The selected curves objects that carry pelage's per-hair look."""
        return [o for o in context.selected_objects
                if o.type == "CURVES" and fur.SHADING_FLOATS[0] in o.data.attributes]

    @classmethod
    def poll(cls, context):
        """Needs a selected curves object carrying the look."""
        return bool(cls.shadeable(context))

    def execute(self, context):
        """Gives each such object the pelage hair material in place of its own."""
        material = fur.hair_material()
        objects = self.shadeable(context)
        for obj in objects:
            obj.data.materials.clear()
            obj.data.materials.append(material)
        self.report({"INFO"}, f"pelage: {len(objects)} curves objects shaded with {material.name!r}")
        return {"FINISHED"}


class _PelageExport(ExportHelper):
    """Writes the active mesh's fur as the viewport shows it, with
    pelage's writer: grown where the fur was grown, carried to this
    frame."""

    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        """Exports the fur of a mesh only."""
        return surface_of(context) is not None

    def execute(self, context):
        """Writes the groom as the viewport shows it, reporting guides left out
        and the count written."""
        surface = surface_of(context)
        try:
            groom = fur.export_groom_for(context, surface, surface.pelage_fur)
            summary = groom.write(self.filepath)
        except (PelageError, ValueError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        if summary["report"] is not None:
            for warning in fur.guide_warnings(summary["report"]):
                self.report({"WARNING"}, f"pelage: {warning}")
        self.report({"INFO"}, f"pelage: wrote {summary['hairs']:,} hairs to {summary['path']}")
        return {"FINISHED"}


class _PelageAnimatedExport(_PelageExport):
    """Grows the active mesh's groom over the scene's frame range and
    writes it with a time sample a frame."""

    def execute(self, context):
        """Grows over the scene's frames (deformed or simulated) and writes a
        sample a frame, with progress."""
        surface = surface_of(context)
        settings = surface.pelage_fur
        wm = context.window_manager
        wm.progress_begin(0, 2)
        try:
            groom = fur.animated_groom_for(
                context, surface, settings, progress=lambda done, total: wm.progress_update(done / total)
            )
            summary = groom.write(self.filepath, progress=lambda done, total: wm.progress_update(1 + done / total))
        except (PelageError, ValueError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        scene = context.scene
        self.report({"INFO"}, f"pelage: wrote {summary['hairs']:,} hairs over frames "
                              f"{scene.frame_start}-{scene.frame_end} to {summary['path']}")
        return {"FINISHED"}


class PELAGE_OT_export_animated_usd(_PelageAnimatedExport, bpy.types.Operator):
    """Grow the active mesh's pelage fur over the scene's frames (deformed or simulated) and write it as binary USD with a time sample a frame"""

    bl_idname = "pelage.export_animated_usd"
    bl_label = "Export animated USD"
    filename_ext = ".usdc"
    filter_glob: StringProperty(default="*.usdc;*.usd", options={"HIDDEN"})


class PELAGE_OT_export_animated_alembic(_PelageAnimatedExport, bpy.types.Operator):
    """Grow the active mesh's pelage fur over the scene's frames (deformed or simulated) and write it as Alembic with a sample a frame"""

    bl_idname = "pelage.export_animated_alembic"
    bl_label = "Export animated Alembic"
    filename_ext = ".abc"
    filter_glob: StringProperty(default="*.abc", options={"HIDDEN"})


class PELAGE_OT_export_usd(_PelageExport, bpy.types.Operator):
    """Grow the active mesh's pelage fur and write it as binary USD"""

    bl_idname = "pelage.export_usd"
    bl_label = "Export USD"
    filename_ext = ".usdc"
    filter_glob: StringProperty(default="*.usdc;*.usda;*.usd", options={"HIDDEN"})


class PELAGE_OT_export_alembic(_PelageExport, bpy.types.Operator):
    """Grow the active mesh's pelage fur and write it as Alembic"""

    bl_idname = "pelage.export_alembic"
    bl_label = "Export Alembic"
    filename_ext = ".abc"
    filter_glob: StringProperty(default="*.abc", options={"HIDDEN"})


class PELAGE_PT_fur(bpy.types.Panel):
    """The pelage fur panel in the 3D view's sidebar: the groom's settings, its
    operator stack, grow, live, load, save and export."""
    bl_label = "pelage fur"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "pelage"

    @classmethod
    def poll(cls, context):
        """Shown for a mesh only."""
        return surface_of(context) is not None

    def draw(self, context):
        """Lays the panel out: groom file or the panel's own settings, the
        stack, and the actions."""
        layout = self.layout
        settings = surface_of(context).pelage_fur
        layout.prop(settings, "groom_file")
        column = layout.column(align=True)
        column.enabled = not settings.groom_file
        column.prop(settings, "preset")
        column.prop(settings, "guides_object")
        live = column.row(align=True)
        live.enabled = settings.guides_object is not None
        live.prop(settings, "live")
        live.prop(settings, "display_fraction", text="Display")
        column.prop_search(settings, "density_group", surface_of(context), "vertex_groups")
        column.prop(settings, "parting")
        if settings.parting == "ATTRIBUTE":
            column.prop_search(settings, "parting_attribute", surface_of(context).data, "attributes")
        column.prop(settings, "interpolation")
        if settings.interpolation == "SHEPARD":
            column.prop(settings, "interpolation_k")
        grown_guides = settings.guides_object is None
        for name in ("count", "guides", "length", "width", "gravity", "points", "clump", "curl", "noise", "seed",
                     "outside_skin"):
            row = column.row()
            # Length, gravity and the guide count shape grown guides only.
            row.enabled = grown_guides or name not in ("guides", "length", "gravity")
            row.prop(settings, name)
        ops = layout.column(align=True)
        ops.enabled = not settings.groom_file
        ops.label(text="Operators (replace Clump, Curl, Noise)" if len(settings.ops) else "Operators")
        row = ops.row()
        row.template_list("PELAGE_UL_ops", "", settings, "ops", settings, "active_op", rows=3)
        buttons = row.column(align=True)
        buttons.operator(PELAGE_OT_op_add.bl_idname, text="", icon="ADD")
        buttons.operator(PELAGE_OT_op_remove.bl_idname, text="", icon="REMOVE")
        buttons.operator(PELAGE_OT_op_move.bl_idname, text="", icon="TRIA_UP").direction = "UP"
        buttons.operator(PELAGE_OT_op_move.bl_idname, text="", icon="TRIA_DOWN").direction = "DOWN"
        if 0 <= settings.active_op < len(settings.ops):
            active = settings.ops[settings.active_op]
            for setting in active.settings:
                ops.prop(setting, "value", text=setting.name)
        files = layout.row(align=True)
        files.operator(PELAGE_OT_load_groom.bl_idname, text="Load groom", icon="IMPORT")
        files.operator(PELAGE_OT_save_groom.bl_idname, text="Save groom", icon="EXPORT")
        look = layout.column(align=True)
        look.enabled = not settings.groom_file
        look.label(text="Look (Principled Hair BSDF)")
        skin_image = fur.skin_color_image(surface_of(context))
        if skin_image is not None:
            look.prop(settings, "skin_color", text=f"Colour from Skin ({skin_image})")
        from_skin = skin_image is not None and settings.skin_color
        for name in ("melanin", "melanin_redness", "roughness", "radial_roughness", "look_jitter"):
            row = look.row()
            row.enabled = not from_skin
            row.prop(settings, name)
        if not surface_of(context).data.uv_layers:
            # Pelage grows without UVs (object-space noise, vertex maps);
            # Blender's deformer is what needs them.
            layout.label(text="No UV map: the fur will not follow deformation", icon="INFO")
        layout.operator(PELAGE_OT_grow_fur.bl_idname, icon="CURVES")
        if settings.last_grow:
            report = layout.box().column(align=True)
            for line in settings.last_grow.split("\n"):
                report.label(text=line)
        row = layout.row(align=True)
        row.operator(PELAGE_OT_export_usd.bl_idname)
        row.operator(PELAGE_OT_export_alembic.bl_idname)
        motion = layout.box().column(align=True)
        scene = context.scene
        motion.label(text=f"Animated: frames {scene.frame_start}-{scene.frame_end}")
        motion.prop(settings, "animation_mode")
        if settings.animation_mode == "SIMULATE":
            for name in ("sim_follow", "sim_bend", "sim_damping", "sim_collide", "sim_preroll"):
                motion.prop(settings, name)
        row = motion.row(align=True)
        row.operator(PELAGE_OT_export_animated_usd.bl_idname, text="USD")
        row.operator(PELAGE_OT_export_animated_alembic.bl_idname, text="Alembic")


CLASSES = (
    PelageOpSetting,
    PelageOp,
    PelageFurSettings,
    PELAGE_OT_grow_fur,
    PELAGE_OT_shade_hair,
    PELAGE_OT_op_add,
    PELAGE_OT_op_remove,
    PELAGE_OT_op_move,
    PELAGE_OT_load_groom,
    PELAGE_OT_save_groom,
    PELAGE_UL_ops,
    PELAGE_OT_export_usd,
    PELAGE_OT_export_alembic,
    PELAGE_OT_export_animated_usd,
    PELAGE_OT_export_animated_alembic,
    PELAGE_PT_fur,
)


def menu_entry(self, context):
    """The Object menu's pelage entries: Grow pelage fur and Shade with pelage
    hair."""
    self.layout.operator(PELAGE_OT_grow_fur.bl_idname, icon="CURVES")
    self.layout.operator(PELAGE_OT_shade_hair.bl_idname, icon="MATERIAL")


def register():
    """Registers the add-on's classes, the surface's settings, the menu entries
    and the live-regrowth handler."""
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Object.pelage_fur = PointerProperty(type=PelageFurSettings)
    bpy.types.VIEW3D_MT_object.append(menu_entry)
    bpy.app.handlers.depsgraph_update_post.append(fur.on_depsgraph_update)


def unregister():
    """Undoes ``register``, forgetting every live groom."""
    if fur.on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(fur.on_depsgraph_update)
    fur.LIVE.clear()
    bpy.types.VIEW3D_MT_object.remove(menu_entry)
    del bpy.types.Object.pelage_fur
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

"""The TOYRT panel in Render Properties, and Blender's standard panels opened to TOYRT."""
import sys
import textwrap

import bpy

from . import cryptomatte

# Blender's own panels that work unchanged with TOYRT (as Blender's custom-engine example does).
COMPATIBLE_PANELS = (
    "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output", "RENDER_PT_encoding",
    "RENDER_PT_color_management", "RENDER_PT_color_management_curves", "RENDER_PT_post_processing",
    "DATA_PT_camera", "DATA_PT_lens", "DATA_PT_camera_display", "DATA_PT_context_camera",
    "DATA_PT_light", "DATA_PT_EEVEE_light", "DATA_PT_context_light",
    "MATERIAL_PT_preview", "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface",
    "WORLD_PT_context_world", "EEVEE_WORLD_PT_surface", "EEVEE_WORLD_PT_mist",  # the Mist pass's settings
    "VIEWLAYER_PT_layer",
)


class ToyrtPanel:
    """What TOYRT's own panels share: the Properties editor, and shown only while TOYRT renders."""
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    COMPAT_ENGINES = {"TOYRT"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class RENDER_PT_toyrt(ToyrtPanel, bpy.types.Panel):
    bl_label = "TOYRT"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.toyrt
        # A native module that did not load (wrong Python, missing file) is said here, not only in
        # the console, where a user who installed from the UI would never look.
        problem = sys.modules[__package__].load_error
        for i, line in enumerate(textwrap.wrap(problem, 70)):
            layout.label(text=line, icon="ERROR" if i == 0 else "BLANK1")
        row = layout.row(heading="Noise Threshold")
        row.prop(settings, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = settings.use_adaptive_sampling
        sub.prop(settings, "adaptive_threshold", text="")
        layout.prop(settings, "samples", text="Max Samples" if settings.use_adaptive_sampling else "Samples")
        col = layout.column()
        col.active = settings.use_adaptive_sampling
        col.prop(settings, "adaptive_min_samples")
        layout.prop(settings, "time_limit")
        layout.prop(settings, "viewport_samples")
        layout.prop(settings, "area_light_sampling")
        layout.prop(settings, "light_sampling")
        layout.prop(settings, "builder")
        layout.prop(settings, "max_specular_depth")
        layout.prop(settings, "seed")
        layout.prop(settings, "use_denoising")
        layout.label(text=f"Threads: {context.scene.render.threads} (Performance settings)")


class VIEWLAYER_PT_toyrt_passes(ToyrtPanel, bpy.types.Panel):
    """The View Layer's own pass switches that TOYRT fills (passes.py), grouped as Cycles' Passes
    panel groups them; the others (Vector, AO, ...) are registered black when turned on elsewhere."""
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        view_layer = context.view_layer
        col = layout.column(heading="Data", align=True)
        for prop in ("use_pass_combined", "use_pass_z", "use_pass_mist", "use_pass_position", "use_pass_normal"):
            col.prop(view_layer, prop)
        col = layout.column(heading="Indexes", align=True)
        col.prop(view_layer, "use_pass_object_index")
        col.prop(view_layer, "use_pass_material_index")
        col = layout.column(heading="Light", align=True)
        col.prop(view_layer, "use_pass_diffuse_color", text="Diffuse Color")
        col.prop(view_layer, "use_pass_emit", text="Emission")


class VIEWLAYER_PT_toyrt_passes_cryptomatte(ToyrtPanel, bpy.types.Panel):
    """The View Layer's Cryptomatte switches (cryptomatte.py), under Passes as in Cycles, with
    Blender's labels (3.4's Accurate Mode is EEVEE's: not shown)."""
    bl_label = "Cryptomatte"
    bl_context = "view_layer"
    bl_parent_id = "VIEWLAYER_PT_toyrt_passes"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        view_layer = context.view_layer
        col = layout.column()
        col.prop(view_layer, "use_pass_cryptomatte_object", text="Object")
        col.prop(view_layer, "use_pass_cryptomatte_material", text="Material")
        col.prop(view_layer, "use_pass_cryptomatte_asset", text="Asset")
        col = layout.column()
        col.active = bool(cryptomatte.enabled(view_layer))
        col.prop(view_layer, "pass_cryptomatte_depth", text="Levels")


def _panels():
    for name in COMPATIBLE_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            yield panel


def register() -> None:
    bpy.utils.register_class(RENDER_PT_toyrt)
    bpy.utils.register_class(VIEWLAYER_PT_toyrt_passes)
    bpy.utils.register_class(VIEWLAYER_PT_toyrt_passes_cryptomatte)
    for panel in _panels():
        panel.COMPAT_ENGINES.add("TOYRT")


def unregister() -> None:
    for panel in _panels():
        panel.COMPAT_ENGINES.discard("TOYRT")
    bpy.utils.unregister_class(VIEWLAYER_PT_toyrt_passes_cryptomatte)
    bpy.utils.unregister_class(VIEWLAYER_PT_toyrt_passes)
    bpy.utils.unregister_class(RENDER_PT_toyrt)

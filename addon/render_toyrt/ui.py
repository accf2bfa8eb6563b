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


class ToyrtRenderPanel(ToyrtPanel):
    """A panel of the Render tab, laid out as Cycles lays out its own: labels in the left column
    (use_property_split), no animation dots."""
    bl_context = "render"

    def draw(self, context):
        self.layout.use_property_split = True
        self.layout.use_property_decorate = False
        self.draw_settings(self.layout, context.scene.toyrt)


# TOYRT's settings grouped as Cycles groups its own (Sampling > Viewport / Render / Lights / Advanced,
# each Denoise under its sampling panel; Light Paths; Performance), with labels short enough for the
# Properties editor of Blender's default layout: each label is a short name here, the long one is
# its tooltip (tests/blender/test_ui_layout.py measures each label in Blender's real window).
class RENDER_PT_toyrt_sampling(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw_settings(self, layout, settings):
        # A native module that did not load (wrong Python, missing file) is said here, not only in
        # the console, where a user who installed from the UI would never look.
        problem = sys.modules[__package__].load_error
        for i, line in enumerate(textwrap.wrap(problem, 50)):
            layout.label(text=line, icon="ERROR" if i == 0 else "BLANK1")


class RENDER_PT_toyrt_sampling_viewport(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Viewport"
    bl_parent_id = "RENDER_PT_toyrt_sampling"

    def draw_settings(self, layout, settings):
        layout.prop(settings, "viewport_samples", text="Max Samples")


class ToyrtDenoisePanel(ToyrtRenderPanel):
    """A Denoise sub-panel, its switch in the header as Cycles' are: `setting` names the switch,
    `what` says what it denoises."""
    bl_label = "Denoise"
    setting = what = ""

    def draw_header(self, context):
        self.layout.prop(context.scene.toyrt, self.setting, text="")

    def draw_settings(self, layout, settings):
        layout.active = getattr(settings, self.setting)
        layout.label(text=self.what)


class RENDER_PT_toyrt_sampling_viewport_denoise(ToyrtDenoisePanel, bpy.types.Panel):
    bl_parent_id = "RENDER_PT_toyrt_sampling_viewport"
    bl_options = {"DEFAULT_CLOSED"}
    setting, what = "use_preview_denoising", "Open Image Denoise, after each pass"


class RENDER_PT_toyrt_sampling_render(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Render"
    bl_parent_id = "RENDER_PT_toyrt_sampling"

    def draw_settings(self, layout, settings):
        row = layout.row(heading="Noise Threshold")
        row.prop(settings, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = settings.use_adaptive_sampling
        sub.prop(settings, "adaptive_threshold", text="")
        layout.prop(settings, "samples", text="Max Samples" if settings.use_adaptive_sampling else "Samples")
        col = layout.column()
        col.active = settings.use_adaptive_sampling
        col.prop(settings, "adaptive_min_samples", text="Min Samples")
        layout.prop(settings, "time_limit", text="Time Limit")


class RENDER_PT_toyrt_sampling_render_denoise(ToyrtDenoisePanel, bpy.types.Panel):
    bl_parent_id = "RENDER_PT_toyrt_sampling_render"
    setting, what = "use_denoising", "Open Image Denoise, albedo and normal"


class RENDER_PT_toyrt_sampling_lights(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Lights"
    bl_parent_id = "RENDER_PT_toyrt_sampling"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_settings(self, layout, settings):
        layout.prop(settings, "light_sampling", text="Sampling")
        layout.prop(settings, "area_light_sampling", text="Area Lights")


class RENDER_PT_toyrt_sampling_advanced(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "RENDER_PT_toyrt_sampling"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_settings(self, layout, settings):
        layout.prop(settings, "seed", text="Seed")


class RENDER_PT_toyrt_light_paths(ToyrtRenderPanel, bpy.types.Panel):
    """TOYRT's light transport: direct light at every vertex, paths only through glossy and
    specular lobes, so the one bounce limit Cycles splits by kind is the specular one here."""
    bl_label = "Light Paths"

    def draw_settings(self, layout, settings):
        pass


class RENDER_PT_toyrt_light_paths_max_bounces(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Max Bounces"
    bl_parent_id = "RENDER_PT_toyrt_light_paths"

    def draw_settings(self, layout, settings):
        layout.prop(settings, "max_specular_depth", text="Specular")
        layout.prop(settings, "transparent_max_bounces", text="Transparent")


class RENDER_PT_toyrt_performance(ToyrtRenderPanel, bpy.types.Panel):
    bl_label = "Performance"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_settings(self, layout, settings):
        render = bpy.context.scene.render
        col = layout.column()
        col.prop(render, "threads_mode")
        sub = col.column()
        sub.enabled = render.threads_mode == "FIXED"
        sub.prop(render, "threads")
        layout.prop(settings, "builder", text="BVH Builder")


RENDER_PANELS = (
    RENDER_PT_toyrt_sampling, RENDER_PT_toyrt_sampling_viewport, RENDER_PT_toyrt_sampling_viewport_denoise,
    RENDER_PT_toyrt_sampling_render, RENDER_PT_toyrt_sampling_render_denoise, RENDER_PT_toyrt_sampling_lights,
    RENDER_PT_toyrt_sampling_advanced, RENDER_PT_toyrt_light_paths, RENDER_PT_toyrt_light_paths_max_bounces,
    RENDER_PT_toyrt_performance,
)


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
    for cls in RENDER_PANELS:
        bpy.utils.register_class(cls)
    bpy.utils.register_class(VIEWLAYER_PT_toyrt_passes)
    bpy.utils.register_class(VIEWLAYER_PT_toyrt_passes_cryptomatte)
    for panel in _panels():
        panel.COMPAT_ENGINES.add("TOYRT")


def unregister() -> None:
    for panel in _panels():
        panel.COMPAT_ENGINES.discard("TOYRT")
    bpy.utils.unregister_class(VIEWLAYER_PT_toyrt_passes_cryptomatte)
    bpy.utils.unregister_class(VIEWLAYER_PT_toyrt_passes)
    for cls in reversed(RENDER_PANELS):
        bpy.utils.unregister_class(cls)

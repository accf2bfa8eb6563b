// The Python module `toyrt`: the definitions (classes, functions, argument names, defaults and
// docstrings). Converters live in python/convert.*, the scene wrapper in python/py_scene.*, the
// policy in the core. Argument defaults are read from the core's structs, never written here.
#include "core/huge_page_pool.h"
#include "core/params.h"
#include "geometry/offset_ray.h"
#include "python/convert.h"
#include "python/py_scene.h"
#include "render/renderer.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdio>
#include <cstdlib>
#include <limits>

namespace py = pybind11;
using namespace toyrt;
using namespace toyrt::binding;

namespace {

// A float default as the shortest decimal that rounds to it (0.8f shows as 0.8, not
// 0.800000011920929): what the signature and toyrt.defaults print; the same float32 either way.
double tidy(float x) {
  char digits[32];
  std::snprintf(digits, sizeof digits, "%.9g", double(x));  // 9 significant digits identify a float
  for (int precision = 1; precision < 9; ++precision) {
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", precision, double(x));
    if (std::strtof(shorter, nullptr) == x) return std::strtod(shorter, nullptr);
  }
  return std::strtod(digits, nullptr);
}
py::tuple as_tuple(const Vec3& v) { return py::make_tuple(tidy(v.x), tidy(v.y), tidy(v.z)); }

// The core's defaults in one dict (toyrt.defaults), so the add-on's property defaults can be
// tested equal to them.
py::dict core_defaults() {
  const RenderSettings render;
  const CommitOptions commit;
  py::dict d;
  d["samples"] = render.samples;
  d["first_sample"] = render.first_sample;
  d["tile_size"] = render.tile_size;
  d["threads"] = render.threads;
  d["seed"] = render.integrator.seed;
  d["max_specular_depth"] = render.integrator.max_specular_depth;
  d["split_depth"] = render.integrator.split_depth;
  d["transparent_max_bounces"] = render.integrator.transparent_max_bounces;
  d["area_light_sampling"] = area_sampling_name(render.integrator.area_sampling);
  d["light_sampling"] = light_sampling_name(render.integrator.light_sampling);
  d["all_lights_up_to"] = kAllLightsUpTo;
  d["use_adaptive_sampling"] = render.adaptive.use;
  d["adaptive_threshold"] = tidy(render.adaptive.threshold);
  d["adaptive_min_samples"] = render.adaptive.min_samples;
  d["time_limit"] = render.time_limit;
  d["builder"] = builder_name(commit.builder);
  d["material_color"] = as_tuple(Lambert{}.albedo);
  d["ior"] = tidy(PerfectRefraction{}.ior);
  return d;
}

// add_material's and set_material's parameters: the keywords documented since the first
// materials (color, texture, ior), which every kind accepts and ignores where it has no use for
// them (the add-on sends all three whatever the kind), plus any other keyword, which the kind
// must read (a typo is an error). color None: the kind's own default (grey for the diffuse
// kinds, white for glass and refraction).
Params material_params(py::handle color, int64_t texture, float ior, const py::kwargs& extra) {
  Params p = to_params(extra);
  if (!color.is_none()) p.set("color", to_vec3(color, "color"));
  p.set("texture", double(texture)).set("ior", double(ior));
  for (const char* shared : {"color", "texture", "ior"}) p.allow_unread(shared);
  return p;
}

}  // namespace

// The wheels build this module once per CPU level under another name (toyrt._core_v3, ...; see
// native/CMakeLists.txt), which Python finds through the name of its init function.
#ifndef TOYRT_MODULE_NAME
#define TOYRT_MODULE_NAME toyrt
#endif

PYBIND11_MODULE(TOYRT_MODULE_NAME, m) {
#if PYBIND11_VERSION_MAJOR < 2 || (PYBIND11_VERSION_MAJOR == 2 && PYBIND11_VERSION_MINOR < 12)
  // A pybind11 older than 2.12 (Debian 12's 2.10) predates numpy 2's C API and reads numpy 2
  // arrays with the old layout: wrong strides, silently wrong answers (every query point given the
  // first one's). Refuse to load there rather than answer wrongly; the wheels use pybind11 >= 2.13.
  {
    const std::string numpy = py::module_::import("numpy").attr("__version__").cast<std::string>();
    if (numpy.size() > 1 && numpy[0] >= '2' && numpy[1] == '.')
      throw py::import_error("toyrt: this build (pybind11 " + std::to_string(PYBIND11_VERSION_MAJOR) + "." +
                             std::to_string(PYBIND11_VERSION_MINOR) + ") cannot read numpy " + numpy +
                             " arrays: use numpy < 2, or a toyrt wheel (pip install toyrt-*.whl, built with pybind11 "
                             ">= 2.13)");
  }
#endif
  m.doc() = "TOYRT's native core: watertight triangles, SAH BVH, two-level scenes, batch ray queries.";
  m.attr("__version__") = "0.1.0";
  m.attr("defaults") = core_defaults();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::logic_error& e) {
      // std::invalid_argument is bad input; other logic errors are calls in the wrong order.
      if (dynamic_cast<const UnknownArgument*>(&e))
        PyErr_SetString(PyExc_TypeError, e.what());  // as Python's own unexpected-keyword error
      else if (dynamic_cast<const std::invalid_argument*>(&e))
        PyErr_SetString(PyExc_ValueError, e.what());
      else
        PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "toyrt: out of memory");
    } catch (const RenderTooLarge& e) {
      PyErr_SetString(PyExc_MemoryError, e.what());  // refused before allocating
    }
  });

  // The render() docstring names the "auto" light count from the core's constant.
  static const std::string render_doc = std::string(
      "Renders the committed scene; returns (height, width, 4) float32 linear RGBA, rows from the top, of\n"
      "the camera's pixel window (the border region, if set).\n"
      "camera: a dict of Blender's camera and render settings: type ('PERSP', 'ORTHO'), lens, sensor_width,\n"
      "sensor_height, sensor_fit ('AUTO', 'HORIZONTAL', 'VERTICAL'), shift_x, shift_y, clip_start, clip_end,\n"
      "ortho_scale, resolution_x, resolution_y, resolution_percentage, pixel_aspect_x, pixel_aspect_y,\n"
      "use_border, border_min_x/y, border_max_x/y, matrix_world (4, 4); depth of field as Blender's camera.dof:\n"
      "use_dof, focus_distance (m along the view axis), aperture_fstop, aperture_blades (below 3: round),\n"
      "aperture_rotation (radians), aperture_ratio (anamorphic).\n"
      "area_light_sampling: 'solid_angle' (spherical rectangles) or 'area'. light_sampling: 'all' (every\n"
      "light at every hit), 'one' (one light chosen by expected contribution) or 'auto' ('all' up to " +
      std::to_string(kAllLightsUpTo) +
      "\n"
      "lights). on_tile(x, y, width, height, pixels) is called on this thread as tiles finish;\n"
      "should_cancel() is polled every 10 ms and stops the render when true (so does Ctrl-C).\n"
      "Results are the same for any thread count and tile size.\n"
      "first_sample: render samples [first_sample, first_sample + samples) of the same sequence, the\n"
      "mean of that pass: passes weighted by their sample counts average to one render of them all\n"
      "(progressive rendering). A window too large for the memory available raises MemoryError\n"
      "before anything is allocated.\n"
      "split_depth: glass (Fresnel) surfaces among the first split_depth path vertices trace both reflection\n"
      "and refraction, weighted by F and 1 - F; deeper ones choose one. 0: never split.\n"
      "transparent_max_bounces: transparent surfaces a path or shadow ray passes (Cycles' setting of that name):\n"
      "a path past that many shades nothing at its next surface; a shadow ray meeting more is blocked.\n"
      "passes: names of render passes to fill beside the image, read afterwards from last_passes, defined\n"
      "as Cycles' data passes: 'depth' (planar camera z, first sample, 1e10 on a miss), 'mist', 'position'\n"
      "(first sample), 'normal' (world, averaged), 'diffuse_color' (albedo, averaged), 'glossy_color' (the\n"
      "glossy lobes' albedo, averaged), 'emission' (surfaces and lamps seen), 'environment' (the world seen\n"
      "where nothing is hit), 'object_index', 'material_index' (first sample). mist: (start, depth, falloff\n"
      "exponent) in metres, as world.mist_settings (falloff QUADRATIC 2, LINEAR 1, INVERSE_QUADRATIC 0.5).\n"
      "object_index: a value per instance (object pass_index), material_index: per material id (material\n"
      "pass_index).\n"
      "cryptomatte: {'object' | 'asset': an id per instance, 'material': an id per material id} (float32\n"
      "Cryptomatte ids: MurmurHash3_32 of the name as a float; 0 = no id), filling last_passes\n"
      "'cryptomatte_<kind>': (height, width, 2 * cryptomatte_depth), per pixel the (id, coverage) pairs\n"
      "ranked by coverage (the share of samples whose first hit has the id; misses have none), zeros after.\n"
      "cryptomatte_depth: the pairs per pixel, 1 to " +
      std::to_string(kCryptomatteMaxDepth) +
      ".\n"
      "use_adaptive_sampling, adaptive_threshold, adaptive_min_samples: Cycles' adaptive sampling (a pixel\n"
      "stops once its noise estimate is below the threshold; 0 = automatic for both numbers).\n"
      "time_limit: seconds of rendering (0 = none); the image is rendered in passes over the whole window\n"
      "and the last pass is sized to end before the limit. on_progress(samples): called on this thread\n"
      "after each tile with the samples done over the whole image so far (a float).");

  // The types and their parameters, read from the core's tables (each type documents its own).
  static const std::string light_doc =
      "Adds a light of Blender type `type` with its parameters as keywords; returns its id. Types:\n" +
      type_docs<Light>() +
      "visible_camera / visible_glossy / visible_transmission: whether camera rays / reflections / rays\n"
      "through glass see the light itself (glossy and transmission: and whether those lobes are lit by it);\n"
      "visible_diffuse: whether it lights diffuse surfaces; cast_shadow: whether surfaces shadow it.\n"
      "receiver_sets / blocker_sets: light linking, 64-bit masks of the instances' receiver_set / blocker_set\n"
      "it lights / whose instances shadow it (all bits set: no linking; add_instance).\n"
      "An unknown type or keyword raises ValueError naming it; None leaves a parameter at its default.";
  static const std::string material_doc =
      "Adds a material; returns its id. kind and its parameters (other keywords than color, texture and ior\n"
      "must be ones the kind reads):\n" +
      type_docs<Material>() +
      "color, texture and ior are accepted by every kind; kinds without them ignore them (color None: the\n"
      "kind's default, grey for the diffuse kinds, white for glass and refraction). Every kind also\n"
      "emits: emission (linear RGB radiance, Blender's colour x strength, both sides; (0, 0, 0): none) and\n"
      "emission_sampling ('AUTO', 'FRONT_AND_BACK', 'FRONT', 'BACK': sampled as a light towards those sides;\n"
      "'NONE': only seen by rays that hit it); emission_texture (a texture id, -1: none) makes the colour an\n"
      "image read at the UV, emission then the strength. And every kind takes a Normal Map: normal_map (a texture id,\n"
      "-1: none; its RGB is the normal, 2 c - 1), normal_strength (1), normal_space ('TANGENT': needs the\n"
      "mesh's tangents, see add_mesh; 'OBJECT', 'WORLD', 'BLENDER_OBJECT', 'BLENDER_WORLD'), normal_convention\n"
      "('OPENGL'; 'DIRECTX' negates green) and normal_strength_mode ('tangent': Blender 4.x+; 'blend': 3.x).\n"
      "kind 'mix' (Blender's Mix and Add Shaders): first, second (ids of other materials, -1: black), add\n"
      "(False: a Mix, (1 - f) first + f second; True: first + second), fac (0.5, clamped to [0, 1]),\n"
      "fac_source ('constant'; 'alpha' or 'gray' of fac_texture at the hit's UV; 'fresnel' with fac_param the\n"
      "IOR; 'layer_fresnel' or 'layer_facing' with fac_param the blend). Each hit shades one input, drawn by\n"
      "its weight; the mix's own emission, cut-out and normal map apply (its inputs' do not).";

  py::class_<PyScene>(m, "Scene", "A two-level scene: meshes stored once, placed by instances.")
      .def(py::init<>())
      .def("add_mesh", &PyScene::add_mesh, py::arg("vertices"), py::arg("triangles"), py::arg("transform") = py::none(),
           py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("material_ids") = py::none(),
           py::arg("instance") = true, py::arg("tangents") = py::none(),
           "Adds a mesh and one instance of it; returns the mesh id.\n"
           "instance: False stores the mesh without placing it (transform must then be None); place it\n"
           "with add_instance(mesh, transform), as often as needed.\n"
           "vertices: (N, 3) numbers (stored as float32), finite. triangles: (M, 3) integer vertex\n"
           "indices. transform: None (identity) or a (4, 4) row-major affine world matrix.\n"
           "Degenerate (zero-area) triangles are kept but can never be hit.\n"
           "For rendering: normals (M, 3, 3) per corner or (N, 3) per vertex (smooth shading; None: flat),\n"
           "uvs (M, 3, 2) or (N, 2), material_ids: one int or (M,) ints into the scene's materials,\n"
           "tangents (M, 3, 4) or (N, 4): object-space unit tangent xyz and bitangent sign w (+-1) of the UV\n"
           "map a tangent-space normal map reads (MikkTSpace, as Blender's Mesh.calc_tangents gives them).")
      .def(
          "add_material",
          [](PyScene& self, const std::string& kind, py::handle color, int64_t texture, float ior,
             const py::kwargs& params) {
            return self.add_material(kind, material_params(color, texture, ior, params));
          },
          py::arg("kind") = kDefaultMaterialKind, py::arg("color") = py::none(), py::arg("texture") = Lambert{}.texture,
          py::arg("ior") = tidy(PerfectRefraction{}.ior), material_doc.c_str())
      .def("add_texture", &PyScene::add_texture, py::arg("pixels"), py::arg("srgb") = true,
           "Adds an image; returns its id. pixels: (height, width, 3 or 4), float 0..1 or uint8, rows from\n"
           "the bottom (Blender's Image.pixels order); srgb: decode from sRGB to linear, as Blender does.")
      .def(
          "add_light",
          [](PyScene& self, const std::string& type, bool visible_camera, bool visible_glossy,
             bool visible_transmission, bool visible_diffuse, bool cast_shadow, uint64_t receiver_sets,
             uint64_t blocker_sets, const py::kwargs& params) {
            return self.add_light(type, to_params(params),
                                  {visible_camera, visible_glossy, visible_transmission, visible_diffuse, cast_shadow,
                                   receiver_sets, blocker_sets});
          },
          py::arg("type"), py::arg("visible_camera") = LightVisibility{}.camera,
          py::arg("visible_glossy") = LightVisibility{}.glossy,
          py::arg("visible_transmission") = LightVisibility{}.transmission,
          py::arg("visible_diffuse") = LightVisibility{}.diffuse, py::arg("cast_shadow") = LightVisibility{}.shadow,
          py::arg("receiver_sets") = kAllLightSets, py::arg("blocker_sets") = kAllLightSets, light_doc.c_str())
      .def(
          "add_point_light",
          [](PyScene& self, py::handle position, float power, py::handle color, float radius, bool visible_camera,
             bool visible_glossy, bool visible_transmission) {
            Params p;
            p.set("position", to_vec3(position, "position")).set("power", double(power));
            p.set("color", to_vec3(color, "color")).set("radius", double(radius));
            return self.add_light(PointLight::kType, p, {visible_camera, visible_glossy, visible_transmission});
          },
          py::arg("position"), py::arg("power"), py::arg("color") = as_tuple(PointLight::Settings{}.color),
          py::arg("radius") = PointLight::Settings{}.radius, py::arg("visible_camera") = LightVisibility{}.camera,
          py::arg("visible_glossy") = LightVisibility{}.glossy,
          py::arg("visible_transmission") = LightVisibility{}.transmission,
          "Adds a point light in Blender's units: power in watts, linear colour, radius in metres (0: hard shadows).\n"
          "visible_camera / visible_glossy / visible_transmission: whether camera rays / reflections / rays\n"
          "through glass see the sphere itself.\n"
          "The same as add_light('POINT', ...).")
      .def(
          "add_area_light",
          [](PyScene& self, py::handle matrix, const std::string& shape, float size, py::handle size_y, float power,
             py::handle color, float spread, bool visible_camera, bool visible_glossy, bool visible_transmission) {
            Params p;
            p.set("matrix", to_matrix(matrix, "matrix")).set("shape", shape).set("size", double(size));
            if (!size_y.is_none()) p.set("size_y", double(size_y.cast<float>()));
            p.set("power", double(power)).set("color", to_vec3(color, "color")).set("spread", double(spread));
            return self.add_light(AreaLight::kType, p, {visible_camera, visible_glossy, visible_transmission});
          },
          py::arg("matrix"), py::arg("shape") = area_shape_name(AreaLight::Settings{}.shape),
          py::arg("size") = AreaLight::Settings{}.size, py::arg("size_y") = py::none(),
          py::arg("power") = AreaLight::Settings{}.power, py::arg("color") = as_tuple(AreaLight::Settings{}.color),
          py::arg("spread") = AreaLight::Settings{}.spread, py::arg("visible_camera") = LightVisibility{}.camera,
          py::arg("visible_glossy") = LightVisibility{}.glossy,
          py::arg("visible_transmission") = LightVisibility{}.transmission,
          "Adds an area light in Blender's units: the light object's (4, 4) world matrix (it emits along its\n"
          "local -Z, one-sided), shape 'RECTANGLE', 'SQUARE', 'DISK' or 'ELLIPSE', size (and size_y) in metres,\n"
          "power in watts (radiance = power / (4 area), as Cycles), spread in radians (pi: none; the beam of a\n"
          "soft box's slats, as Cycles). visible_camera / visible_glossy / visible_transmission:\n"
          "whether camera rays / reflections / rays through glass see the light's surface (Cycles' defaults: all).\n"
          "The same as add_light('AREA', ...).")
      .def_property("background", &PyScene::background, &PyScene::set_background,
                    "Radiance (linear RGB) of rays that leave the scene: the world colour.")
      .def("set_environment", &PyScene::set_environment, py::arg("texture"), py::arg("strength") = as_tuple(Vec3(1.0f)),
           py::arg("matrix") = py::none(),
           "Lights the world with texture `texture` (an equirectangular image added with add_texture), times\n"
           "strength (linear RGB), as Blender's Environment Texture into a Background node: seen by rays that leave\n"
           "the scene (instead of `background`) and lighting diffuse surfaces (importance-sampled by the image's\n"
           "luminance, combined with cosine sampling). matrix: None, or a (3, 3) (or (4, 4): its rotation and scale)\n"
           "row-major matrix taking world directions into the map's frame (the Mapping node's rotation). The image's\n"
           "centre column looks along -X, its top row up (+Z). texture=-1 removes the environment.")
      .def_property("background_lighting", &PyScene::background_lighting, &PyScene::set_background_lighting,
                    "Whether the background also lights diffuse surfaces, as Cycles' world does (default True).")
      .def_property("background_visible_camera", &PyScene::background_visible_camera,
                    &PyScene::set_background_visible_camera,
                    "Whether camera rays that leave the scene see the background (default True; Blender's\n"
                    "world.cycles_visibility.camera). Off, they see black, still opaque, as in Cycles; rays through\n"
                    "glass or off glossy surfaces, and the lighting, are unchanged.")
      .def_property("background_visible_glossy", &PyScene::background_visible_glossy,
                    &PyScene::set_background_visible_glossy,
                    "Whether rays reflected by glossy and mirror surfaces see the background (default True;\n"
                    "world.cycles_visibility.glossy). Off, reflections of the world are black, as in Cycles.")
      .def_property("background_visible_transmission", &PyScene::background_visible_transmission,
                    &PyScene::set_background_visible_transmission,
                    "Whether rays refracted through glass see the background (default True;\n"
                    "world.cycles_visibility.transmission). Off, the world seen through glass is black.")
      .def("render", &PyScene::render, py::arg("camera"), py::arg("samples") = RenderSettings{}.samples,
           py::arg("seed") = IntegratorSettings{}.seed,
           py::arg("max_specular_depth") = IntegratorSettings{}.max_specular_depth,
           py::arg("area_light_sampling") = area_sampling_name(IntegratorSettings{}.area_sampling),
           py::arg("light_sampling") = light_sampling_name(IntegratorSettings{}.light_sampling),
           py::arg("threads") = RenderSettings{}.threads, py::arg("tile_size") = RenderSettings{}.tile_size,
           py::arg("on_tile") = py::none(), py::arg("should_cancel") = py::none(),
           py::arg("first_sample") = RenderSettings{}.first_sample,
           py::arg("split_depth") = IntegratorSettings{}.split_depth, py::arg("passes") = py::none(),
           py::arg("mist") = py::none(), py::arg("object_index") = py::none(), py::arg("material_index") = py::none(),
           py::arg("cryptomatte") = py::none(), py::arg("cryptomatte_depth") = CryptomatteRequest{}.depth,
           py::arg("use_adaptive_sampling") = AdaptiveSettings{}.use,
           py::arg("adaptive_threshold") = AdaptiveSettings{}.threshold,
           py::arg("adaptive_min_samples") = AdaptiveSettings{}.min_samples,
           py::arg("time_limit") = RenderSettings{}.time_limit, py::arg("on_progress") = py::none(),
           py::arg("transparent_max_bounces") = IntegratorSettings{}.transparent_max_bounces, render_doc.c_str())
      .def_property_readonly(
          "last_render", &PyScene::last_render,
          "What the last render did: cancelled, cancel_latency_ms, tiles_done, tiles_total, render_ms,\n"
          "samples, samples_done (every pixel's: below samples when the time limit stopped it), mean_samples\n"
          "(per pixel: below samples_done where adaptive sampling stopped pixels), time_limit_reached,\n"
          "light_sampling.")
      .def_property_readonly("last_passes", &PyScene::last_passes,
                             "The passes the last render was asked for: name -> (height, width, channels) float32,\n"
                             "rows from the top (see render's `passes`).")
      .def(
          "set_material",
          [](PyScene& self, int64_t material, const std::string& kind, py::handle color, int64_t texture, float ior,
             const py::kwargs& params) {
            self.set_material(material, kind, material_params(color, texture, ior, params));
          },
          py::arg("material"), py::arg("kind") = kDefaultMaterialKind, py::arg("color") = py::none(),
          py::arg("texture") = Lambert{}.texture, py::arg("ior") = tidy(PerfectRefraction{}.ior),
          "Replaces material `material` in place (same arguments as add_material); meshes keep their ids.")
      .def("set_texture", &PyScene::set_texture, py::arg("texture"), py::arg("pixels"), py::arg("srgb") = true,
           "Replaces texture `texture` in place (same arguments as add_texture).")
      .def("clear_lights", &PyScene::clear_lights, "Removes every light (to send them again after an edit).")
      .def("replace_mesh", &PyScene::replace_mesh, py::arg("mesh"), py::arg("vertices"), py::arg("triangles"),
           py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("material_ids") = py::none(),
           py::arg("tangents") = py::none(),
           "Replaces mesh `mesh`'s geometry and shading (arguments as add_mesh, without a transform); its\n"
           "instances stay, the next commit rebuilds its BVH. Empty arrays free a mesh no longer used.")
      .def("set_instance_transform", &PyScene::set_instance_transform, py::arg("instance"), py::arg("transform"),
           "Moves instance `instance` ((4, 4) row-major affine world matrix); the next commit rebuilds only\n"
           "the top level.")
      .def("clear_instances", &PyScene::clear_instances,
           "Removes every instance (meshes stay, with their BVHs), to place them again.")
      .def("add_instance", &PyScene::add_instance, py::arg("mesh"), py::arg("transform"),
           py::arg("visible_shadow") = Instance{}.visible_shadow, py::arg("receiver_set") = 0,
           py::arg("blocker_set") = 0, py::arg("visible_camera") = true, py::arg("visible_diffuse") = true,
           py::arg("visible_glossy") = true, py::arg("visible_transmission") = true,
           py::arg("emitter_receiver_sets") = kAllLightSets,
           "Places mesh `mesh` again with a (4, 4) row-major affine world matrix; returns the instance id.\n"
           "visible_shadow: Blender's Object.visible_shadow; False, the instance casts no shadow in a render\n"
           "(its light-sampled shadow rays pass it), while camera, glossy and glass rays and the ray queries\n"
           "(intersect, occluded, ...) still see it. receiver_set / blocker_set (0-63): its light-linking sets:\n"
           "lamps light it when their receiver_sets has bit receiver_set, and it shadows lamps whose\n"
           "blocker_sets has bit blocker_set (add_light). visible_camera / visible_diffuse / visible_glossy /\n"
           "visible_transmission: Blender's Object ray visibility; False, render rays of that kind pass it (an\n"
           "emitter hidden from diffuse rays lights no diffuse surface); the ray queries see it regardless.\n"
           "emitter_receiver_sets: where its materials emit, the receiver sets it lights (light linking of an\n"
           "emissive object; all bits: every object), as add_light's receiver_sets.")
      .def("commit", &PyScene::commit, py::arg("builder") = builder_name(CommitOptions{}.builder),
           py::arg("threads") = CommitOptions{}.threads, py::arg("expected_rays") = py::none(),
           py::arg("should_cancel") = py::none(),
           "Builds the BVHs of new meshes and the top level; returns True, or False when cancelled.\n"
           "should_cancel(): polled every 10 ms while building; when it returns true the build stops\n"
           "within a few milliseconds and the scene stays uncommitted (meshes already built keep their BVH,\n"
           "so the next commit builds only the rest).\n"
           "builder: 'sah' (binned SAH on the CPU: the faster trees), 'lbvh' (Karras' linear BVH as OpenCL\n"
           "kernels: the faster builds; falls back to 'sah' with a RuntimeWarning when no OpenCL device or\n"
           "kernel build is available), or 'auto' (per mesh, whichever makes build + tracing cheaper for\n"
           "`expected_rays` rays; without that estimate, 'sah'). threads: 0 for all cores.")
      .def_property_readonly(
          "last_commit", &PyScene::last_commit,
          "What the last commit did: build_ms, lbvh_compile_ms (OpenCL compilation, first LBVH build of\n"
          "the process only), meshes_built, sah_meshes, lbvh_meshes, emissive_triangles, emitters_ms,\n"
          "emitter_tree_nodes (0: emissive triangles chosen by power, too few for a tree),\n"
          "light_tree_nodes (0: no light tree, too few lights to pay for one), light_tree_ms, warning.")
      .def("intersect", &PyScene::intersect, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("threads") = 0, py::arg("normals") = false,
           py::arg("mesh_ids") = false,
           "Nearest hits of rays org + t * dir with tnear <= t < tfar (world units of t: the direction's\n"
           "length). origins, directions: (N, 3); tnear, tfar: numbers or (N,) arrays.\n"
           "Returns a dict of (N,) arrays: t (float32, inf on a miss), prim (int32 triangle index in its\n"
           "mesh, -1 on a miss), instance (int32), u, v (float32; p = (1-u-v) p0 + u p1 + v p2).\n"
           "Rays with a zero or non-finite direction, a non-finite origin, or tnear > tfar miss.\n"
           "origins, directions may have any leading shape (..., 3) (an image's (H, W, 3)): the answers\n"
           "come in that shape. Opt-in: normals=True adds normal (..., 3) float32, the unit geometric\n"
           "normal in world space (0 on a miss); mesh_ids=True adds mesh (int32, -1 on a miss).")
      .def("occluded", &PyScene::occluded, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("threads") = 0,
           "Whether anything lies on each ray with tnear <= t < tfar; a (N,) bool array. Stops at the first hit.")
      .def("count_intersections", &PyScene::count_intersections, py::arg("origins"), py::arg("directions"),
           py::arg("tnear") = 0.0f, py::arg("tfar") = std::numeric_limits<float>::infinity(), py::arg("threads") = 0,
           "Number of surface crossings of each ray on tnear <= t < tfar: (N,) uint32. Exact: a ray through a\n"
           "shared edge or vertex of a mesh crosses it once, a ray grazing a silhouette 0 or 2 times, a ray in\n"
           "a triangle's plane never crosses that triangle (one tie-break for all: docs/queries.md), so a\n"
           "line through a closed mesh counts an even number. Per mesh under one transform: a closed\n"
           "surface split over meshes or instances may leak or double-count at the seam.")
      .def("list_intersections", &PyScene::list_intersections, py::arg("origins"), py::arg("directions"),
           py::arg("tnear") = 0.0f, py::arg("tfar") = std::numeric_limits<float>::infinity(),
           py::arg("max_hits") = size_t(1) << 24, py::arg("threads") = 0,
           "Every crossing counted by count_intersections, in ray order then t order (ties by instance,\n"
           "prim). Returns a dict: ray_splits (N+1,) int64 (ray i owns entries ray_splits[i]:ray_splits[i+1]),\n"
           "ray (uint32), t, u, v (float32), mesh, instance, prim (int32). More than max_hits crossings in\n"
           "all raise ValueError before anything of that size is allocated (28 bytes per crossing).")
      .def("compute_occupancy", &PyScene::compute_occupancy, py::arg("points"), py::arg("threads") = 0,
           "Whether each point (N, 3) is inside a closed mesh: (N,) bool. Exact, by the parity of the ray\n"
           "along +x (the count_intersections rule); a point exactly on a triangle is inside; an open mesh\n"
           "gets the parity of that one ray; only instances whose box holds the point count; the union of\n"
           "the instances' solids. Non-finite points raise ValueError.")
      .def("compute_closest_points", &PyScene::compute_closest_points, py::arg("points"), py::arg("threads") = 0,
           "The nearest surface point to each point (N, 3), in double precision, rounded once: a dict of\n"
           "points (N, 3), distance (N,), mesh, instance, prim (int32), u, v (closest = (1-u-v) p0 + u p1 +\n"
           "v p2) and normal (N, 3; unit geometric normal in world space). No geometry: distance inf, ids -1.")
      .def("compute_distance", &PyScene::compute_distance, py::arg("points"), py::arg("signed") = false,
           py::arg("threads") = 0, "Distance from each point (N, 3) to the nearest surface: (N,) float32.")
      .def(
          "compute_signed_distance",
          [](PyScene& s, py::handle points, int threads) { return s.compute_distance(points, true, threads); },
          py::arg("points"), py::arg("threads") = 0,
          "compute_distance, negative where compute_occupancy says inside (0 exactly on the surface).")
      .def("bvh_stats", &PyScene::bvh_stats, py::arg("mesh") = -1,
           "The shape of a tree, as a dict. mesh >= 0: the mesh's traced 8-wide tree: nodes (wide nodes),\n"
           "leaves (child slots holding triangles, or 1 for a tree that is a single leaf), triangles (in its\n"
           "leaves: the mesh's triangles but degenerate ones), depth (levels of wide nodes; 0 for a single\n"
           "leaf), children_per_node (mean used slots of a node) and sah_cost (node visits and block tests,\n"
           "weighted as the collapse weighs them: not on the top level's scale). mesh=-1: the binary top\n"
           "level over instances: nodes (leaves included), leaves, depth (1 for a single leaf),\n"
           "children_per_node (2; 0 for a single leaf) and sah_cost (traversal and intersection cost 1).")
      .def_property_readonly("mesh_count", &PyScene::mesh_count)
      .def_property_readonly("instance_count", &PyScene::instance_count)
      .def_property_readonly("triangle_count", &PyScene::triangle_count, "Triangles stored, each mesh counted once.")
      .def_property_readonly(
          "memory_bytes", &PyScene::memory_bytes,
          "Bytes the scene holds: meshes and their BVHs, the top level, shading arrays, textures,\n"
          "the environment's sampling grid, emissive triangles, materials, lamps and the light tree.")
      .def_property_readonly("committed", &PyScene::committed)
      .def_property_readonly("build_ms", &PyScene::build_ms, "Wall time of the last commit in milliseconds.");

  m.def(
      "camera_window",
      [](const py::dict& camera) {
        const Camera c = Camera::make(to_camera(camera));
        py::dict d;
        d["width"] = c.width;
        d["height"] = c.height;
        d["x0"] = c.window.x0;
        d["y0"] = c.window.y0;
        d["x1"] = c.window.x1;
        d["y1"] = c.window.y1;
        return d;
      },
      py::arg("camera"),
      "The image size (resolution times percentage) and the pixel window render() fills (the border,\n"
      "or the whole image), rows counted from the top: dict of width, height, x0, y0, x1, y1.");

  m.def("cached_memory_bytes", &huge_page_pool::kept_bytes,
        "Bytes of freed BVH and commit arrays the module keeps mapped for the next commit (in huge\n"
        "pages, already faulted in): at most a 32nd of the machine's memory, 256 MB to 1 GB.");
  m.def("release_cached_memory", &huge_page_pool::release,
        "Gives the memory cached_memory_bytes() counts back to the system; returns how many bytes.\n"
        "The next commit then maps its arrays afresh (the kernel zeroes each page on first touch: about\n"
        "a sixth of a 1M-triangle LBVH commit). The Blender add-on calls it after every final render.");
  m.def(
      "offset_ray_origin",
      [](py::handle points, py::handle normals) {
        FloatArray p = as_points(points, "points"), n = as_points(normals, "normals");
        if (p.shape(0) != n.shape(0)) throw py::value_error("points and normals must have the same length");
        const size_t count = size_t(p.shape(0));
        py::array_t<float> out({py::ssize_t(count), py::ssize_t(3)});
        const Vec3* pp = reinterpret_cast<const Vec3*>(p.data());
        const Vec3* nn = reinterpret_cast<const Vec3*>(n.data());
        Vec3* o = reinterpret_cast<Vec3*>(out.mutable_data());
        for (size_t i = 0; i < count; ++i) o[i] = offset_ray_origin(pp[i], nn[i]);
        return out;
      },
      py::arg("points"), py::arg("normals"),
      "Ray origins moved off the surface along the normals (Waechter and Binder 2019), so rays\n"
      "leaving the surface do not hit it again: (N, 3) float32.");
}

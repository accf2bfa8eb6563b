// PyScene::render: the renderer's binding. Its keyword arguments become the core's settings and
// pass request, tiles and progress go back to Python's callbacks as they finish (the GIL taken
// for each), and the image, passes and the render's record are kept for Python to read.
#include "python/convert.h"
#include "python/py_scene.h"
#include "render/renderer.h"

#include <cstring>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

namespace toyrt::binding {

namespace {
// render()'s pass arguments as the core's request: names, the mist settings (start, depth,
// falloff exponent), the pass-index tables (per instance, per material id) and the Cryptomatte
// id tables (kind name -> ids per instance or material id) with their depth.
AovRequest aov_request(py::handle passes, py::handle mist, py::handle object_index, py::handle material_index,
                       py::handle cryptomatte, int cryptomatte_depth) {
  AovRequest r;
  if (!passes.is_none())
    for (py::handle name : passes) r.mask |= 1u << uint32_t(parse_aov(py::cast<std::string>(name)));
  if (!mist.is_none()) {
    const auto m = py::cast<std::tuple<float, float, float>>(mist);
    r.mist = MistSettings{std::get<0>(m), std::get<1>(m), std::get<2>(m)};
  }
  auto table = [](py::handle obj) {
    if (obj.is_none()) return std::vector<float>();
    const FloatArray a = contiguous<float>(obj, "render: a pass-index table");
    if (a.ndim() != 1) throw py::value_error("render: a pass-index table must be a 1-D array of numbers");
    return std::vector<float>(a.data(), a.data() + a.size());
  };
  r.object_index = table(object_index);
  r.material_index = table(material_index);
  r.cryptomatte.depth = cryptomatte_depth;
  if (!cryptomatte.is_none())
    for (auto [kind, ids] : py::cast<py::dict>(cryptomatte))
      r.cryptomatte.ids[size_t(parse_crypto_kind(py::cast<std::string>(kind)))] = table(ids);
  return r;
}
}  // namespace

py::array_t<float> PyScene::render(const py::dict& camera_settings, int samples, uint32_t seed, int max_specular_depth,
                                   const std::string& area_light_sampling, const std::string& light_sampling,
                                   int threads, int tile_size, py::object on_tile, py::object should_cancel,
                                   int first_sample, int split_depth, py::handle passes, py::handle mist,
                                   py::handle object_index, py::handle material_index, py::handle cryptomatte,
                                   int cryptomatte_depth, bool use_adaptive_sampling, float adaptive_threshold,
                                   int adaptive_min_samples, double time_limit, py::object on_progress,
                                   int transparent_max_bounces) {
  const AovRequest request = aov_request(passes, mist, object_index, material_index, cryptomatte, cryptomatte_depth);
  const Camera camera = Camera::make(to_camera(camera_settings));
  RenderSettings settings;
  settings.samples = samples;
  settings.first_sample = first_sample;
  settings.tile_size = tile_size;
  settings.threads = threads;
  settings.integrator.seed = seed;
  settings.integrator.max_specular_depth = max_specular_depth;
  settings.integrator.split_depth = split_depth;
  settings.integrator.transparent_max_bounces = transparent_max_bounces;
  settings.integrator.area_sampling = parse_area_sampling(area_light_sampling);
  settings.integrator.light_sampling = parse_light_sampling(light_sampling);
  settings.adaptive.use = use_adaptive_sampling;
  settings.adaptive.threshold = adaptive_threshold;
  settings.adaptive.min_samples = adaptive_min_samples;
  settings.time_limit = time_limit;

  // Tiles and cancel polls arrive on this thread with the GIL released: take it for Python.
  TileSink sink;
  if (!on_tile.is_none() || !on_progress.is_none()) {
    sink = [&](const Tile& t, const RenderResult& r) {
      py::gil_scoped_acquire gil;
      if (!on_tile.is_none()) {
        py::array_t<float> pixels({py::ssize_t(t.height), py::ssize_t(t.width), py::ssize_t(4)});
        float* out = pixels.mutable_data();
        for (int j = 0; j < t.height; ++j)
          std::memcpy(out + size_t(j) * t.width * 4, &r.rgba[(size_t(t.y + j) * r.width + t.x) * 4],
                      size_t(t.width) * 4 * sizeof(float));
        on_tile(t.x, t.y, t.width, t.height, pixels);
      }
      if (!on_progress.is_none()) on_progress(r.progress_samples);
    };
  }
  CancelPoll poll = [&]() {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C cancels too
    return !should_cancel.is_none() && py::bool_(should_cancel());
  };
  RenderResult result;
  {
    // The scene is read in place under the shared lock: edits wait for the render to end.
    py::gil_scoped_release release;
    std::shared_lock lock(mutex_);
    result = toyrt::render(scene_, camera, settings, sink, poll, request);
  }
  last_passes_ = py::dict();
  for (size_t k = 0; k < kAovCount; ++k) {
    const std::vector<float>& d = result.passes.data[k];
    if (d.empty()) continue;
    py::array_t<float> pass({py::ssize_t(result.height), py::ssize_t(result.width), py::ssize_t(aov_channels(Aov(k)))});
    std::memcpy(pass.mutable_data(), d.data(), d.size() * sizeof(float));
    last_passes_[aov_name(Aov(k))] = pass;
  }
  for (size_t k = 0; k < kCryptoKindCount; ++k) {
    const std::vector<float>& d = result.passes.cryptomatte[k];
    if (d.empty()) continue;
    py::array_t<float> pass(
        {py::ssize_t(result.height), py::ssize_t(result.width), py::ssize_t(request.cryptomatte.channels())});
    std::memcpy(pass.mutable_data(), d.data(), d.size() * sizeof(float));
    last_passes_[py::str(std::string("cryptomatte_") + crypto_kind_name(CryptoKind(k)))] = pass;
  }
  last_render_ = py::dict();
  last_render_["cancelled"] = result.cancelled;
  last_render_["tiles_done"] = result.tiles_done;
  last_render_["tiles_total"] = result.tiles_total;
  last_render_["render_ms"] = result.render_ms;
  last_render_["cancel_latency_ms"] = result.cancel_latency_ms;
  last_render_["samples"] = samples;
  last_render_["samples_done"] = result.samples_done;
  last_render_["mean_samples"] = result.mean_samples;
  last_render_["time_limit_reached"] = result.time_limit_reached;
  last_render_["first_sample"] = first_sample;
  last_render_["light_sampling"] = light_sampling_name(result.light_sampling);
  py::array_t<float> image({py::ssize_t(result.height), py::ssize_t(result.width), py::ssize_t(4)});
  std::memcpy(image.mutable_data(), result.rgba.data(), result.rgba.size() * sizeof(float));
  return image;
}

}  // namespace toyrt::binding

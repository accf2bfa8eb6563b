#include "render/renderer.h"

#include "core/parallel.h"
#include "render/glossy_color.h"
#include "render/pass_accumulation.h"
#include "sampling/sobol_owen.h"

#include <tbb/parallel_for.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace toyrt {

namespace {
// The thin lens's 2D sample dimension. Dimensions are hashed into the scramble (sobol_owen.h), so
// any number is as good as another; this one is past every path vertex's block of 64 up to a
// depth of 2^26.
constexpr uint32_t kLensDimension = 0xFFFFFFFFu;

// A pixel's sums over every sample it has taken, kept between the passes of a time-limited
// render when adaptive sampling is on (its test needs them all).
struct PixelProgress {
  Vec3 sum{0.0f}, half{0.0f};
  uint32_t n = 0;
  bool converged = false;
};

std::string format_bytes(size_t bytes) {
  char buf[32];
  const double b = double(bytes);
  if (b >= 1e12)
    std::snprintf(buf, sizeof buf, "%.1f TB", b / 1e12);
  else if (b >= 1e9)
    std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", b / 1e6);
  return buf;
}
}  // namespace

size_t render_memory_estimate(const Camera& camera, const RenderSettings& settings, const AovRequest& passes) {
  // Sizes in double: a window of 1e6 x 1e6 pixels must not wrap around before it is refused.
  const double w = std::max(0, camera.window.width()), h = std::max(0, camera.window.height());
  const double pixels = w * h;
  const double tile = std::max(1, settings.tile_size);
  const double tiles = std::ceil(w / tile) * std::ceil(h / tile);
  const double threads = settings.threads > 0 ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  // Framebuffer and the caller's copy (RGBA float each); a Tile and a queue slot per tile; a
  // worker's stack and TBB's bookkeeping (1 MB is generous: the integrator keeps its state on the stack).
  double channels = 4;
  for (size_t k = 0; k < kAovCount; ++k)
    if (passes.has(Aov(k))) channels += aov_channels(Aov(k));
  for (size_t k = 0; k < kCryptoKindCount; ++k)
    if (passes.cryptomatte.has(CryptoKind(k))) channels += passes.cryptomatte.channels();
  // A time limit renders into a pass buffer beside the image, with each pixel's sample count (and,
  // adaptive, its sums: PixelProgress) for adding passes up.
  const bool in_passes = settings.time_limit > 0.0;
  const double copies = in_passes ? 3 : 2;
  const double per_pixel = in_passes ? 2 * sizeof(uint32_t) + (settings.adaptive.use ? sizeof(PixelProgress) : 0)
                                     : (settings.adaptive.use ? sizeof(uint32_t) : 0);
  const double bytes = pixels * (channels * sizeof(float) * copies + per_pixel) +
                       tiles * (sizeof(Tile) + sizeof(size_t)) + threads * 1e6;
  return bytes >= 1.8e19 ? SIZE_MAX : size_t(bytes);
}

size_t available_memory_bytes() {
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    unsigned long long kb = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof line, f)) found = std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1;
    std::fclose(f);
    if (found) return size_t(kb) * 1024;
  }
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? size_t(pages) * size_t(page) : SIZE_MAX;
}

namespace {

// What one pass needs beside the render's own arguments.
struct PassPlan {
  AdaptiveRule rule;
  std::vector<PixelProgress>* progress = nullptr;  // adaptive: the pixels' sums so far (else null)
  std::vector<uint32_t>* counts = nullptr;         // samples each pixel took in this pass (or null)
  // Called on the calling thread for each finished tile (never on a worker).
  std::function<void(size_t tile)> on_finished;
};

// One pass over the window: samples [first_sample, first_sample + samples) of every pixel (fewer
// where adaptive sampling stops a pixel), tiles on a TBB pool, cancel polled on this thread.
void render_pass(const Scene& scene, const Camera& camera, const RenderSettings& settings, const AovRequest& passes,
                 const std::vector<Tile>& tiles, const PassPlan& plan, const CancelPoll& should_cancel,
                 RenderResult& result) {
  const PixelWindow win = camera.window;
  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable wake;
  std::deque<size_t> finished;
  bool done = false;
  std::exception_ptr failure;

  // The camera ray of one sample: dimension 0 jitters it in the pixel; a thin lens draws its
  // aperture point from a dimension of its own, far past the path vertices' blocks
  // (integrator.cpp) so it never shares one. A pinhole draws nothing more: its rays, and so its
  // image, are those it had before depth of field existed.
  const bool pinhole = camera.lens.pinhole();
  auto primary_ray = [&](int px, int py, uint32_t pixel, uint32_t s) {
    const Vec2 jitter = sobol_owen_2d(pixel, s, 0, settings.integrator.seed);
    if (pinhole) return camera.generate(float(px) + jitter.x, float(py) + jitter.y);
    return camera.generate(float(px) + jitter.x, float(py) + jitter.y,
                           sobol_owen_2d(pixel, s, kLensDimension, settings.integrator.seed));
  };

  // The samples of one pixel: `trace_one(s)` returns sample s's radiance. Returns the count
  // taken, or -1 when cancelled. Without adaptive sampling the loop is the plain one.
  auto sample_pixel = [&](auto adaptive, size_t index, Vec3& sum, auto&& trace_one) -> int {
    const int first = settings.first_sample, last = settings.first_sample + settings.samples;
    // Adaptive: the pixel's sums so far (kept between passes under a time limit, else its own).
    PixelProgress local;
    PixelProgress* state = &local;
    if constexpr (adaptive) {
      if (plan.progress) state = &(*plan.progress)[index];
      if (state->converged) return 0;
    }
    for (int s = first; s < last; ++s) {
      // A relaxed load every few samples costs nothing next to a path, and bounds the cancel
      // latency by a few samples whatever the sample count.
      if ((s - first) % kCancelCheckSamples == kCancelCheckSamples - 1 && cancel.load(std::memory_order_relaxed))
        return -1;
      const Vec3 L = trace_one(s);
      sum += L;
      if constexpr (adaptive) {
        state->sum += L;
        if (AdaptiveRule::in_half(uint32_t(s))) state->half += L;
        ++state->n;
        if (plan.rule.tests_after(s) && plan.rule.converged(state->sum, state->half, int(state->n))) {
          state->converged = true;
          return s - first + 1;
        }
      }
    }
    return last - first;
  };

  auto render_tile = [&](const Tile& t, auto adaptive) {
    const int first = settings.first_sample;
    const bool with_passes = passes.any();  // read once: the plain loop below must stay as it was
    const bool with_cryptomatte = passes.cryptomatte.any();
    const bool with_glossy = passes.has(Aov::GlossyColor);
    std::vector<CryptomattePixel::Entry> crypto_scratch;  // grows once per tile, only if asked for
    for (int j = t.y; j < t.y + t.height; ++j) {
      if (cancel.load(std::memory_order_relaxed)) return false;
      for (int i = t.x; i < t.x + t.width; ++i) {
        // The pixel's index in the full image keys its random numbers: the same whatever the
        // window, tile size or thread that renders it.
        const int px = win.x0 + i, py = win.y0 + j;
        const uint32_t pixel = uint32_t(py) * uint32_t(camera.width) + uint32_t(px);
        Vec3 sum(0.0f);
        const size_t index = size_t(j) * size_t(result.width) + size_t(i);
        int taken;
        if (with_passes) {
          // Passes asked for: the same samples, each reporting its first surface (aovs.h).
          AovPixel aov(passes, camera);
          CryptomattePixel crypto(passes.cryptomatte, crypto_scratch);
          taken = sample_pixel(adaptive, index, sum, [&](int s) {
            FirstHit hit;
            const Vec3 L = trace_path(scene, primary_ray(px, py, pixel, uint32_t(s)), pixel, uint32_t(s),
                                      settings.integrator, &hit);
            if (with_glossy) add_layered_pass_color(scene.materials(), scene.textures(), hit);
            aov.add(hit, s == first);
            if (with_cryptomatte) crypto.add(hit.found ? hit.instance : -1, hit.material);
            return L;
          });
          if (taken < 0) return false;
          if (taken > 0) {
            aov.store(result.passes, index, 1.0f / float(taken));
            if (with_cryptomatte) crypto.store(result.passes.cryptomatte, index, 1.0f / float(taken));
          }
        } else {
          taken = sample_pixel(adaptive, index, sum, [&](int s) {
            return trace_path(scene, primary_ray(px, py, pixel, uint32_t(s)), pixel, uint32_t(s), settings.integrator);
          });
          if (taken < 0) return false;
        }
        if (plan.counts) (*plan.counts)[index] = uint32_t(taken);
        if (taken == 0) continue;  // converged in an earlier pass
        const float inv = 1.0f / float(taken);
        float* out = &result.rgba[index * 4];
        out[0] = sum.x * inv;
        out[1] = sum.y * inv;
        out[2] = sum.z * inv;
        out[3] = 1.0f;
      }
    }
    return true;
  };

  // Workers render on their own thread, so this one stays free to hand tiles to the caller and
  // to poll for a cancel.
  std::thread driver([&] {
    try {
      run_with_threads(settings.threads, [&] {
        tbb::parallel_for(size_t(0), tiles.size(), [&](size_t k) {
          const bool complete =
              plan.rule.use ? render_tile(tiles[k], std::true_type{}) : render_tile(tiles[k], std::false_type{});
          if (!complete) return;
          std::lock_guard lock(mutex);
          finished.push_back(k);
          wake.notify_one();
        });
      });
    } catch (...) {
      std::lock_guard lock(mutex);
      failure = std::current_exception();
    }
    std::lock_guard lock(mutex);
    done = true;
    wake.notify_one();
  });

  std::exception_ptr caller_failure;
  std::chrono::steady_clock::time_point cancelled_at;
  auto request_cancel = [&] {
    if (!cancel.exchange(true)) cancelled_at = std::chrono::steady_clock::now();
  };
  for (;;) {
    std::deque<size_t> ready;
    bool all_done;
    {
      std::unique_lock lock(mutex);
      wake.wait_for(lock, std::chrono::milliseconds(10), [&] { return done || !finished.empty(); });
      ready.swap(finished);
      all_done = done;
    }
    try {
      for (size_t k : ready) {
        ++result.tiles_done;
        if (plan.on_finished && !cancel) plan.on_finished(k);
      }
      if (!cancel && should_cancel && should_cancel()) request_cancel();
    } catch (...) {
      // A failing callback cancels the render; the error is raised once every worker is joined.
      caller_failure = std::current_exception();
      request_cancel();
    }
    if (all_done) break;
  }
  driver.join();
  if (caller_failure) std::rethrow_exception(caller_failure);
  if (failure) std::rethrow_exception(failure);
  result.cancelled = cancel;
  if (result.cancelled)
    result.cancel_latency_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cancelled_at).count();
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

RenderResult render(const Scene& scene, const Camera& camera, const RenderSettings& requested, const TileSink& on_tile,
                    const CancelPoll& should_cancel, const AovRequest& passes) {
  requested.check();
  passes.cryptomatte.check();
  scene.check_renderable();
  // The settings with "auto" light sampling resolved for this scene: a copy of a few ints, the
  // scene itself is read in place.
  RenderSettings settings = requested;
  settings.integrator.light_sampling =
      resolve_light_sampling(requested.integrator.light_sampling, scene.world().lights.size());
  const CameraCone camera_cone = CameraCone::of(camera);
  settings.integrator.camera_cone = &camera_cone;
  const auto start = std::chrono::steady_clock::now();
  const PixelWindow win = camera.window;
  const size_t needed = render_memory_estimate(camera, settings, passes), available = available_memory_bytes();
  if (needed > available)
    throw RenderTooLarge("render: a " + std::to_string(win.width()) + " x " + std::to_string(win.height()) +
                         " image needs " + format_bytes(needed) + " but only " + format_bytes(available) +
                         " of memory is available; lower the resolution or the resolution percentage");
  RenderResult result;
  result.light_sampling = settings.integrator.light_sampling;
  result.width = win.width();
  result.height = win.height();
  result.rgba.assign(size_t(result.width) * size_t(result.height) * 4, 0.0f);
  result.passes.allocate(passes, result.width, result.height);
  std::vector<Tile> tiles;
  for (int y = 0; y < result.height; y += settings.tile_size)
    for (int x = 0; x < result.width; x += settings.tile_size)
      tiles.push_back(
          {x, y, std::min(settings.tile_size, result.width - x), std::min(settings.tile_size, result.height - y)});
  result.tiles_total = tiles.size();
  const size_t pixels = size_t(result.width) * size_t(result.height);

  PassPlan plan;
  plan.rule = AdaptiveRule::resolve(settings.adaptive, settings.samples);
  std::vector<uint32_t> counts;  // samples per pixel (adaptive sampling or passes)
  auto mean_samples = [&] {
    double total = 0.0;
    for (uint32_t c : counts) total += c;
    return pixels ? total / double(pixels) : 0.0;
  };

  if (settings.time_limit <= 0.0) {
    // One pass: tiles go to the caller as they finish, as they are final.
    if (plan.rule.use) {
      counts.assign(pixels, 0);
      plan.counts = &counts;
    }
    plan.on_finished = [&](size_t k) {
      result.progress_samples = double(settings.samples) * double(result.tiles_done) / double(tiles.size());
      if (on_tile) on_tile(tiles[k], result);
    };
    render_pass(scene, camera, settings, passes, tiles, plan, should_cancel, result);
    result.samples_done = settings.samples;
    result.mean_samples = plan.rule.use ? mean_samples() : double(settings.samples);
    result.render_ms = seconds_since(start) * 1e3;
    return result;
  }

  // A time limit: passes of 1, 1, 2, 4... samples over the whole window, each added into `result`
  // tile by tile as it finishes (the caller sees the image refine), the next one sized so that
  // it ends before the limit at the time per sample measured so far.
  std::vector<PixelProgress> progress;
  if (plan.rule.use) {
    progress.assign(pixels, PixelProgress{});
    plan.progress = &progress;
  }
  counts.assign(pixels, 0);
  std::vector<uint32_t> pass_counts(pixels, 0);
  plan.counts = &pass_counts;
  RenderResult pass;
  pass.width = result.width;
  pass.height = result.height;
  pass.rgba.assign(pixels * 4, 0.0f);
  pass.passes.allocate(passes, result.width, result.height);
  const auto render_start = std::chrono::steady_clock::now();
  int taken = 0, next = 1;
  while (taken < settings.samples) {
    RenderSettings step = settings;
    step.first_sample = settings.first_sample + taken;
    step.samples = next;
    pass.tiles_done = 0;
    plan.on_finished = [&](size_t k) {
      accumulate_tile(result, counts, pass, pass_counts, tiles[k], passes.cryptomatte.depth);
      result.progress_samples = double(taken) + double(next) * double(pass.tiles_done) / double(tiles.size());
      if (on_tile) on_tile(tiles[k], result);
    };
    render_pass(scene, camera, step, passes, tiles, plan, should_cancel, pass);
    if (pass.cancelled) {
      result.cancelled = true;
      result.cancel_latency_ms = pass.cancel_latency_ms;
      break;
    }
    taken += next;
    const double elapsed = seconds_since(render_start), per_sample = elapsed / double(taken);
    const double room = settings.time_limit - elapsed;
    // At most double what is done (the estimate stays fresh), and only what fits in the time left.
    const double fits = per_sample > 0.0 ? std::floor(room / per_sample) : double(settings.samples);
    next = int(std::min({double(settings.samples - taken), double(std::max(taken, 1)), fits}));
    if (taken < settings.samples && next < 1) {
      result.time_limit_reached = true;
      break;
    }
  }
  // Every tile holds the passes before the last one; a cancelled last pass finished only some.
  result.tiles_done = taken > 0 ? result.tiles_total : pass.tiles_done;
  result.samples_done = taken;
  result.mean_samples = mean_samples();
  result.progress_samples = taken;
  result.render_ms = seconds_since(start) * 1e3;
  return result;
}

}  // namespace toyrt
